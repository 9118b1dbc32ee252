"""The figure pipeline of a woodpile project, from Python: ``Pipeline``.

Running stages needs the whole engine (polars included), which the Python module does not
compile: ``status`` and ``run`` call the ``woodpile`` command, and ``read`` and ``manifest``
open the parquet tables with pyarrow, after checking each table's seal as the engine does.
The command is ``$WOODPILE_BIN``, else the one installed with the package, else ``woodpile`` on
the PATH. Nothing is ever built at run time, and no build folder is searched: a path baked in at
install time, or named by ``CARGO_TARGET_DIR``, could be anyone's.
"""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import pandas as pd

from . import _core

PathLike = Union[str, "os.PathLike[str]"]

# The largest table read, as the engine bounds it.
_MAX_TABLE_BYTES = 1 << 30


def _packaged_binary() -> Path:
    """Where a wheel puts the ``woodpile`` command: inside the package."""
    return Path(__file__).resolve().parent / "bin" / "woodpile"


def find_woodpile() -> str:
    """The path of the ``woodpile`` command this package drives: ``$WOODPILE_BIN``, else the
    one installed with the package (a wheel carries it), else ``woodpile`` on the PATH (the
    package's own ``woodpile`` script, which only forwards here, is passed over)."""
    explicit = os.environ.get("WOODPILE_BIN")
    if explicit:
        return explicit
    packaged = _packaged_binary()
    if packaged.is_file() and os.access(packaged, os.X_OK):
        return str(packaged)
    for folder in os.environ.get("PATH", "").split(os.pathsep):
        candidate = Path(folder or ".") / "woodpile"
        if candidate.is_file() and os.access(candidate, os.X_OK) and not _forwards(candidate):
            return str(candidate)
    raise FileNotFoundError(
        "the woodpile command was not found: install the woodpile wheel (`make wheel` builds "
        "it; it carries the command), set WOODPILE_BIN to its path, or run `make install` in "
        "a clone to put it on the PATH"
    )


def _forwards(path: Path) -> bool:
    """Whether ``path`` is this package's ``woodpile`` script (a few lines of Python that
    forward to the real command), not the command itself."""
    try:
        with open(path, "rb") as f:
            head = f.read(1024)
    except OSError:
        return False
    return head.startswith(b"#!") and b"woodpile._cli" in head


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
        # Absolute once, here: the command runs in ``root``, where a relative folder would be
        # taken twice (``proj/proj/results``).
        self.root = Path(root).absolute()
        self.pipeline_dir = self.root / pipeline
        self.results_dir = self.root / results
        self.figures_dir = self.root / figures
        self._woodpile = str(woodpile) if woodpile is not None else None

    def __repr__(self) -> str:
        return f"Pipeline({str(self.root)!r})"

    def _command(
        self, args: Sequence[str], names: Sequence[str] = (), echo: bool = False
    ) -> str:
        """Runs the ``woodpile`` command on this project and returns its stdout; with
        ``echo``, its progress lines (stderr) reach ``sys.stderr`` as they come, which a
        notebook shows in the cell."""
        binary = self._woodpile or find_woodpile()
        self._woodpile = binary
        where = [
            "--pipeline", str(self.pipeline_dir),
            "--results", str(self.results_dir),
            "--figures", str(self.figures_dir),
        ]
        tail = ["--", *names] if names else []
        process = subprocess.Popen(
            [binary, *args, *where, *tail],
            cwd=self.root,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        stderr: List[str] = []

        def read_stderr() -> None:
            assert process.stderr is not None
            for line in process.stderr:
                stderr.append(line)
                if echo and sys.stderr is not None:
                    sys.stderr.write(line)
                    sys.stderr.flush()

        reader = threading.Thread(target=read_stderr, daemon=True)
        reader.start()
        assert process.stdout is not None
        stdout = process.stdout.read()
        code = process.wait()
        reader.join()
        if code == 2:
            raise _core.SceneError(_message("".join(stderr)))
        if code != 0:
            raise _core.SimulationError(_message("".join(stderr)))
        return stdout

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
        set: Optional[Mapping[str, Any]] = None,
        progress: Optional[bool] = None,
    ) -> Dict[str, Any]:
        """Bring ``stage`` (a name, several, or all when None) up to date, upstream first.

        ``set={"f4_fractions.at": 120.0}`` runs a variant of a stage with keys of its file
        set, without editing it (``woodpile run --set``): its table is
        ``results/<stage>--<key>-<value>.parquet``, named in the summary's ``stages``.

        ``progress`` streams the command's per-stage progress lines into ``sys.stderr`` (a
        notebook shows them in the cell) as they come; by default it does in an interactive
        session (a notebook, or a terminal), and ``False`` silences it.

        Returns the run's summary: ``stages`` (each ``stage``, ``runs``, ``why``,
        ``points``, ``cached``), ``ran``, ``fresh``, ``scenes_simulated``, ``seconds``.
        Raises ``SceneError`` for a bad stage definition or ``set`` key and
        ``SimulationError`` when a stage fails (the message names every failure)."""
        names: List[str] = [] if stage is None else [stage] if isinstance(stage, str) else list(stage)
        args = ["run", "--json"]
        if force:
            args.append("--force")
        if dry_run:
            args.append("--dry-run")
        for key, value in (set or {}).items():
            args += ["--set", f"{key}={_toml_value(value)}"]
        echo = _interactive() if progress is None else progress
        # After `--`, a name is a name: "--force" cannot pass for the flag.
        return json.loads(self._command(args, names, echo=echo))

    def table_path(self, stage: str) -> Path:
        """Where ``stage``'s table is (``results/<stage>.parquet``)."""
        return self.results_dir / f"{stage}.parquet"

    def _sealed(self, stage: str) -> "tuple[Path, bytes]":
        """The bytes of ``stage``'s table, checked against their seal before anything decodes
        them (the engine's check: a damaged table raises, as ``status`` calls it damaged)."""
        path = self.table_path(stage)
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no table for stage `{stage}` (run it first)")
        if path.stat().st_size > _MAX_TABLE_BYTES:
            raise ValueError(f"{path}: larger than the {_MAX_TABLE_BYTES} bytes a table may have")
        data = path.read_bytes()
        state = _core.table_integrity(data)
        if state == "damaged":
            raise ValueError(
                f"{path}: damaged: its bytes no longer match the seal in its manifest (run the stage again)"
            )
        if state != "intact":
            raise ValueError(f"{path}: not a woodpile table (it has no seal)")
        return path, data

    def read(self, stage: str) -> pd.DataFrame:
        """``stage``'s table as a pandas DataFrame (run the stage first if it is missing).
        Raises ``ValueError`` if the file no longer matches its seal."""
        _, data = self._sealed(stage)
        return pd.read_parquet(io.BytesIO(data), engine="pyarrow")

    def manifest(self, stage: str) -> Dict[str, Any]:
        """``stage``'s manifest: ``stage``, ``kind``, ``key``, ``code_version``, ``params``,
        ``inputs`` (upstream stage -> key), ``summary`` and ``checksum`` (the seal of the
        whole file). Raises ``ValueError`` if the file no longer matches its seal."""
        import pyarrow.parquet as pq

        path, data = self._sealed(stage)
        metadata = pq.read_metadata(io.BytesIO(data)).metadata or {}
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


def _interactive() -> bool:
    """Whether someone is watching: a notebook kernel, or stderr on a terminal."""
    return "ipykernel" in sys.modules or sys.stderr.isatty()


def new_study(path: PathLike, *, woodpile: Optional[PathLike] = None) -> Pipeline:
    """Make a new study folder at ``path`` that runs as written (``woodpile new study``):
    a sweep, its reduction and a figure, with a README of what to change. Returns its
    ``Pipeline``. Raises ``SceneError`` when ``path`` exists."""
    target = Path(path).absolute()
    binary = str(woodpile) if woodpile is not None else find_woodpile()
    done = subprocess.run(
        [binary, "new", "study", str(target)], cwd=target.parent, capture_output=True, text=True
    )
    if done.returncode == 2:
        raise _core.SceneError(_message(done.stderr))
    if done.returncode != 0:
        raise _core.SimulationError(_message(done.stderr))
    return Pipeline(target, woodpile=binary)


def _toml_value(value: Any) -> str:
    """``value`` as a TOML value for ``woodpile run --set`` (numbers, booleans, strings,
    lists and tables of them; NumPy scalars included)."""
    if hasattr(value, "item") and not isinstance(value, (list, tuple, dict)):
        value = value.item()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise _core.SceneError(f"set: {value} is not a number a stage file can hold")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {_toml_value(v)}" for k, v in value.items()) + "}"
    raise _core.SceneError(f"set: a {type(value).__name__} is not a TOML value")


def _message(stderr: str) -> str:
    lines = [line for line in stderr.strip().splitlines() if line.startswith("error")]
    text = "\n".join(lines) if lines else stderr.strip()
    return text.removeprefix("error: ") if hasattr(text, "removeprefix") else text
