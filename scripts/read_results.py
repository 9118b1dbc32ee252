#!/usr/bin/env python3
"""Opens every result table with pyarrow, pandas and polars (issue 3's interoperability check).

Usage: python3 scripts/read_results.py [RESULTS_DIR]   (default: results)
Exits non-zero, naming the file and the library, if any reader fails or disagrees on the shape,
or if a file lacks its `woodpile` manifest.
"""
import json
import pathlib
import sys

import pandas as pd
import polars as pl
import pyarrow.parquet as pq


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "results")
    files = sorted(p for p in root.rglob("*.parquet") if "points" not in p.parts)
    if not files:
        print(f"no parquet files under {root}", file=sys.stderr)
        return 1
    for path in files:
        table = pq.read_table(path)
        manifest = json.loads(pq.read_metadata(path).metadata[b"woodpile"])
        frame = pd.read_parquet(path)
        lazy = pl.read_parquet(path)
        shapes = {(table.num_rows, table.num_columns), frame.shape, lazy.shape}
        if len(shapes) != 1:
            print(f"{path}: readers disagree on the shape: {shapes}", file=sys.stderr)
            return 1
        print(f"{path}: {table.num_rows} rows x {table.num_columns} columns, "
              f"stage {manifest['stage']} ({manifest['kind']}), key {manifest['key'][:12]}")
    print(f"{len(files)} files read by pyarrow, pandas and polars")
    return 0


if __name__ == "__main__":
    sys.exit(main())
