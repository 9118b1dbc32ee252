"""Shared fixtures: the repository's scene files, the `woodpile` command, a small pipeline."""

import json
import os
import subprocess
from pathlib import Path

import pytest

from woodpile._pipeline import find_woodpile

REPO = Path(__file__).resolve().parents[2]
SCENES = sorted((REPO / "scenes").glob("*.toml"))

# The package never searches build folders; its tests use this clone's release build when no
# command is named (`make python-test` names it), except when they test an installed wheel
# (`make wheel-test`), whose own command they must find.
_BUILT = REPO / "target" / "release" / "woodpile"
if _BUILT.is_file() and not os.environ.get("WOODPILE_TEST_INSTALLED"):
    os.environ.setdefault("WOODPILE_BIN", str(_BUILT))


@pytest.fixture(scope="session")
def woodpile_bin() -> str:
    return find_woodpile()


@pytest.fixture(scope="session")
def cli(woodpile_bin):
    """`woodpile simulate PATH [ARGS]` as its JSON object."""

    def run(path, *args):
        out = subprocess.run(
            [woodpile_bin, "simulate", str(path), *args], capture_output=True, text=True, check=True
        )
        return json.loads(out.stdout)

    return run


SWEEP_STAGE = """\
kind = "sweep"
description = "two single defects"
[axes]
eps = [0.5, 4.0]
[scene]
chain = { n = 40, boundary = "fixed" }
impulse = { site = -10, velocity = 1.0 }
run = { t_end = 40.0, method = "auto", tolerance = 1e-6, sample_every = 2.0 }
[[scene.defect]]
site = 0
eps = "$eps"
"""

REDUCE_STAGE = """\
kind = "reduce"
description = "fractions at t = 30"
inputs = ["small_sweep"]
at = 30.0
"""


@pytest.fixture()
def small_pipeline(tmp_path):
    """A project folder with a two-point sweep and a reduce of it."""
    stages = tmp_path / "pipeline"
    stages.mkdir()
    (stages / "small_sweep.toml").write_text(SWEEP_STAGE)
    (stages / "small_fractions.toml").write_text(REDUCE_STAGE)
    return tmp_path
