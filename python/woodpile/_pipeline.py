"""The figure pipeline of a woodpile project, from Python: ``Pipeline``.

Running stages needs the whole engine (polars included), which the Python module does not
compile: ``status`` and ``run`` call the ``woodpile`` command, and ``read`` and ``manifest``
open the parquet tables with pyarrow. The command is found as ``$WOODPILE_BIN``, else the
release build of the clone this package was built from, else ``woodpile`` on the PATH; if
none exists, it is built once from that clone with cargo.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Union

import pandas as pd

from . import _core

PathLike = Union[str, "os.PathLike[str]"]


def _clone() -> Path:
    return Path(_core.SOURCE_DIR).resolve()


def _clone_binary() -> Path:
    target = os.environ.get("CARGO_TARGET_DIR") or str(_clone() / "target")
    return Path(target) / "release" / "woodpile"


def find_woodpile() -> str:
    """The path of the ``woodpile`` command this package drives (building it if needed)."""
    explicit = os.environ.get("WOODPILE_BIN")
    if explicit:
        return explicit
    built = _clone_binary()
    if built.is_file():
        return str(built)
    on_path = shutil.which("woodpile")
    if on_path:
        return on_path
    if (_clone() / "Cargo.toml").is_file() and shutil.which("cargo"):
        print(
            f"woodpile: building the woodpile command once (cargo build --release -p woodpile-cli in {_clone()})",
            file=sys.stderr,
        )
        subprocess.run(
            ["cargo", "build", "--release", "-p", "woodpile-cli"], cwd=_clone(), check=True
        )
        if built.is_file():
            return str(built)
    raise FileNotFoundError(
        "the woodpile command was not found: set WOODPILE_BIN, or run `make install` in a clone"
    )


class Pipeline:
    """A woodpile project: stage files in ``pipeline/``, tables in ``results/``, figures in
    ``figures/`` (each relative to ``root`` unless given as absolute paths).

    >>> p = woodpile.Pipeline("path/to/woodpile")
    >>> p.status()                    # DataFrame: stage, kind, state, why
    >>> p.run("f4_fractions")         # bring it (and what it reads) up to date
    >>> p.read("f4_fractions")        # its table as a DataFrame
    >>> p.manifest("f4_fractions")    # parameters, inputs' keys, summary, seal
    >>> p.figure("f4_figure")         # Path of figures/f4_figure.png
    """

    def __init__(
        self,
        root: PathLike = ".",
        *,
        pipeline: PathLike = "pipeline",
        results: PathLike = "results",
        figures: PathLike = "figures",
        woodpile: Optional[PathLike] = None,
    ) -> None:
        self.root = Path(root)
        self.pipeline_dir = self.root / pipeline
        self.results_dir = self.root / results
        self.figures_dir = self.root / figures
        self._woodpile = str(woodpile) if woodpile is not None else None

    def __repr__(self) -> str:
        return f"Pipeline({str(self.root)!r})"

    def _command(self, args: Sequence[str]) -> str:
        binary = self._woodpile or find_woodpile()
        self._woodpile = binary
        where = [
            "--pipeline", str(self.pipeline_dir),
            "--results", str(self.results_dir),
            "--figures", str(self.figures_dir),
        ]
        done = subprocess.run(
            [binary, *args, *where], cwd=self.root, capture_output=True, text=True
        )
        if done.returncode == 2:
            raise _core.SceneError(_message(done.stderr))
        if done.returncode != 0:
            raise _core.SimulationError(_message(done.stderr))
        return done.stdout

    def status(self) -> pd.DataFrame:
        """Every stage with its kind, its state (``fresh``, ``stale``, ``missing`` or
        ``damaged``) and why, in pipeline order."""
        rows = json.loads(self._command(["status", "--json"]))
        return pd.DataFrame(rows, columns=["stage", "kind", "state", "why"])

    def run(
        self,
        stage: Union[str, Sequence[str], None] = None,
        *,
        force: bool = False,
        dry_run: bool = False,
    ) -> Dict[str, Any]:
        """Bring ``stage`` (a name, several, or all when None) up to date, upstream first.

        Returns the run's summary: ``stages`` (each ``stage``, ``runs``, ``why``,
        ``points``, ``cached``), ``ran``, ``fresh``, ``scenes_simulated``, ``seconds``.
        Raises ``SceneError`` for a bad stage definition and ``SimulationError`` when a
        stage fails (the message names every failure)."""
        names: List[str] = [] if stage is None else [stage] if isinstance(stage, str) else list(stage)
        args = ["run", *names, "--json"]
        if force:
            args.append("--force")
        if dry_run:
            args.append("--dry-run")
        return json.loads(self._command(args))

    def table_path(self, stage: str) -> Path:
        """Where ``stage``'s table is (``results/<stage>.parquet``)."""
        return self.results_dir / f"{stage}.parquet"

    def read(self, stage: str) -> pd.DataFrame:
        """``stage``'s table as a DataFrame (run the stage first if it is missing)."""
        path = self.table_path(stage)
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no table for stage `{stage}` (run it first)")
        return pd.read_parquet(path, engine="pyarrow")

    def manifest(self, stage: str) -> Dict[str, Any]:
        """``stage``'s manifest: ``stage``, ``kind``, ``key``, ``code_version``, ``params``,
        ``inputs`` (upstream stage -> key), ``summary`` and ``checksum`` (its seal)."""
        import pyarrow.parquet as pq

        path = self.table_path(stage)
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no table for stage `{stage}` (run it first)")
        metadata = pq.read_metadata(path).metadata or {}
        text = metadata.get(b"woodpile")
        if text is None:
            raise ValueError(f"{path}: not a woodpile table (no manifest in its metadata)")
        return json.loads(text)

    def figure(self, stage: str, format: str = "png") -> Path:
        """The path of a render stage's figure (``png`` or ``svg``)."""
        path = self.figures_dir / f"{stage}.{format}"
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no figure for stage `{stage}` (run it first)")
        return path


def _message(stderr: str) -> str:
    lines = [line for line in stderr.strip().splitlines() if line.startswith("error")]
    text = "\n".join(lines) if lines else stderr.strip()
    return text.removeprefix("error: ") if hasattr(text, "removeprefix") else text
