"""Benchmarks of the Python package against the Rust core (not tests; numbers go to
docs/performance.md). Run from the repository root after `pip install ./python`:

    python python/benches/bench.py [--repeat 5] [--skip-sweep]

1. `woodpile.simulate` on the standard scene (one defect, eps = 10, auto at 1e-7), with its
   series returned, against the same call's own Rust time (the report's `wall_s`, measured
   inside the core around the simulation): the Python overhead, as the median call's ratio.
2. `woodpile.sweep` of the F7 coarse grid (pipeline/f7/f7_coarse_sweep.toml, series kept)
   against `woodpile run f7_coarse_sweep` into an empty results folder.
3. `woodpile.simulate_many` of a grid's points as a list of scenes against `woodpile.sweep`
   of the same grid (final values, no series kept): the list's own cost, in one process.
The simulate rows are the median of `--repeat` calls, each against its own Rust time; the
sweep rows the best of two runs each.
"""

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import woodpile
from woodpile._pipeline import find_woodpile

REPO = Path(__file__).resolve().parents[2]


def best(repeat, work):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return min(times), result


def bench_simulate(repeat):
    scene = tomllib.loads((REPO / "scenes" / "single_eps10.toml").read_text())
    scene.setdefault("run", {})["tolerance"] = 1e-7
    woodpile.simulate(scene)  # warm up
    rows = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = woodpile.simulate(scene)
        returned = time.perf_counter()
        assert len(result.series) == 151
        rows.append((result.wall_s, returned - start, time.perf_counter() - start))
    # Each call against its own Rust time, so the machine's drift between calls cancels.
    median = lambda i: sorted(r[i] / r[0] for r in rows)[len(rows) // 2]
    rust = sorted(r[0] for r in rows)[len(rows) // 2]
    return rust, median(1), median(2)


def bench_sweep(repeat):
    stage = tomllib.loads((REPO / "pipeline" / "f7" / "f7_coarse_sweep.toml").read_text())
    binary = find_woodpile()

    def cli():
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run(
                [binary, "run", "f7_coarse_sweep", "--results", tmp, "--figures", tmp],
                cwd=REPO, check=True, capture_output=True,
            )

    rust, _ = best(repeat, cli)
    python, table = best(repeat, lambda: woodpile.sweep(stage["scene"], stage["axes"], series=True))
    assert table.failure.isna().all()
    return rust, python


def bench_many(repeat):
    """`simulate_many` of the F6 grid's scenes, listed, against `sweep` of the grid."""
    stage = tomllib.loads((REPO / "pipeline" / "f6" / "f6_sweep.toml").read_text())
    grid = woodpile.sweep(stage["scene"], stage["axes"], progress=False)
    names = sorted(stage["axes"])
    scenes = [
        woodpile.scene_toml(_filled(stage["scene"], {n: row[n] for n in names}))
        for _, row in grid.iterrows()
    ]
    swept, _ = best(repeat, lambda: woodpile.sweep(stage["scene"], stage["axes"], progress=False))
    listed, many = best(repeat, lambda: woodpile.simulate_many(scenes, progress=False))
    assert many.E_tr.tolist() == grid.E_tr.tolist()
    return len(scenes), swept, listed


def _filled(template, values):
    """`template` with each "$name" string replaced by its value."""
    if isinstance(template, dict):
        return {k: _filled(v, values) for k, v in template.items()}
    if isinstance(template, list):
        return [_filled(v, values) for v in template]
    if isinstance(template, str) and template.startswith("$"):
        value = values[template[1:]]
        return int(value) if float(value).is_integer() and "." not in str(value) else float(value)
    return template


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=21)
    parser.add_argument("--skip-sweep", action="store_true")
    args = parser.parse_args()
    print("| call | Rust | Python | Python / Rust |")
    print("|---|---|---|---|")
    rust, call, with_frame = bench_simulate(args.repeat)
    print(f"| `simulate`, standard scene, auto at 1e-7 (series arrays returned) | {rust * 1e3:.2f} ms | {rust * call * 1e3:.2f} ms | {call:.3f} |")
    print(f"| the same, then `.series` made a DataFrame | {rust * 1e3:.2f} ms | {rust * with_frame * 1e3:.2f} ms | {with_frame:.3f} |")
    if not args.skip_sweep:
        rust, python = bench_sweep(2)
        print(f"| `sweep` of F7 coarse (10,000 scenes, series) vs `woodpile run` | {rust:.2f} s | {python:.2f} s | {python / rust:.3f} |")
        count, swept, listed = bench_many(3)
        print(f"| `simulate_many` of F6's {count} scenes, listed, vs `sweep` of its grid | {swept:.2f} s (`sweep`) | {listed:.2f} s | {listed / swept:.3f} |")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
