"""`woodpile.Pipeline` on a small project in a temporary folder."""

import os

import pytest

import woodpile


def test_status_run_read_and_manifest(small_pipeline):
    p = woodpile.Pipeline(small_pipeline)
    status = p.status()
    assert list(status.columns) == ["stage", "kind", "state", "why"]
    assert set(status.stage) == {"small_sweep", "small_fractions"}
    assert (status.state == "missing").all()

    summary = p.run()
    assert summary["ran"] == 2 and summary["scenes_simulated"] == 2
    assert {s["stage"] for s in summary["stages"] if s["runs"]} == {"small_sweep", "small_fractions"}
    assert (p.status().state == "fresh").all()
    assert p.run()["ran"] == 0

    table = p.read("small_fractions")
    assert sorted(table.eps) == [0.5, 4.0] and (table.t == 30.0).all()
    manifest = p.manifest("small_fractions")
    assert manifest["kind"] == "reduce" and manifest["params"]["at"] == 30.0
    assert manifest["inputs"] == {"small_sweep": p.manifest("small_sweep")["key"]}

    forced = p.run("small_fractions", force=True)
    assert [s["stage"] for s in forced["stages"] if s["runs"]] == ["small_fractions"]


def test_an_edited_stage_is_stale_with_its_reason(small_pipeline):
    p = woodpile.Pipeline(small_pipeline)
    p.run()
    stage = small_pipeline / "pipeline" / "small_fractions.toml"
    stage.write_text(stage.read_text().replace("at = 30.0", "at = 20.0"))
    status = p.status().set_index("stage")
    assert status.loc["small_fractions", "state"] == "stale"
    assert "at" in status.loc["small_fractions", "why"]
    assert p.run(dry_run=True)["scenes_simulated"] == 0


def test_errors(small_pipeline):
    p = woodpile.Pipeline(small_pipeline)
    with pytest.raises(FileNotFoundError):
        p.read("small_sweep")
    with pytest.raises(FileNotFoundError):
        p.figure("small_sweep")
    (small_pipeline / "pipeline" / "broken.toml").write_text('kind = "sweep"\n')
    with pytest.raises(woodpile.SceneError, match="broken.toml"):
        p.status()


def test_read_and_manifest_check_the_seal(small_pipeline):
    """A table whose bytes no longer match its seal raises, as `status` calls it damaged,
    instead of handing back a silently different DataFrame."""
    p = woodpile.Pipeline(small_pipeline)
    p.run()
    path = p.table_path("small_fractions")
    data = bytearray(path.read_bytes())
    data[len(data) // 3] ^= 0x01
    path.write_bytes(bytes(data))
    assert p.status().set_index("stage").loc["small_fractions", "state"] == "damaged"
    with pytest.raises(ValueError, match="damaged"):
        p.read("small_fractions")
    with pytest.raises(ValueError, match="damaged"):
        p.manifest("small_fractions")


def test_a_relative_root_is_the_project_and_names_are_never_flags(small_pipeline, monkeypatch):
    """`Pipeline("proj")` from the folder above works (the command runs inside the project,
    where a relative path would be taken twice), and a stage named "--force" is a name."""
    monkeypatch.chdir(small_pipeline.parent)
    p = woodpile.Pipeline(small_pipeline.name)
    assert (p.status().state == "missing").all()
    p.run("small_sweep")
    assert (small_pipeline / "results" / "small_sweep.parquet").is_file()
    assert not (small_pipeline / small_pipeline.name).exists()
    with pytest.raises(woodpile.SceneError, match="--force"):
        p.run("--force")
    assert p.status().set_index("stage").loc["small_fractions", "state"] == "missing"


def test_the_command_is_never_taken_from_a_build_folder(monkeypatch, tmp_path):
    """`$WOODPILE_BIN`, then the package's own, then PATH: never `CARGO_TARGET_DIR`, never built."""
    from woodpile import _pipeline

    planted = tmp_path / "release" / "woodpile"
    planted.parent.mkdir()
    planted.write_text("#!/bin/sh\necho planted\n")
    planted.chmod(0o755)
    monkeypatch.setenv("CARGO_TARGET_DIR", str(tmp_path))
    monkeypatch.delenv("WOODPILE_BIN", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    if _pipeline._packaged_binary().is_file():
        assert _pipeline.find_woodpile() == str(_pipeline._packaged_binary())
    else:
        with pytest.raises(FileNotFoundError, match="WOODPILE_BIN"):
            _pipeline.find_woodpile()
    monkeypatch.setenv("WOODPILE_BIN", "/opt/woodpile")
    assert _pipeline.find_woodpile() == "/opt/woodpile"


def test_the_woodpile_script_forwards_to_the_command_and_is_never_taken_for_it(
    monkeypatch, tmp_path, woodpile_bin
):
    """The package's `woodpile` script runs the real command; looking the command up on the
    PATH passes the script over."""
    import subprocess
    import sys

    from woodpile import _pipeline

    script, real = tmp_path / "venv-bin", tmp_path / "cargo-bin"
    script.mkdir()
    real.mkdir()
    (script / "woodpile").write_text(
        "#!/usr/bin/env python3\nfrom woodpile._cli import main\nmain()\n"
    )
    (real / "woodpile").write_text("#!/bin/sh\necho real \"$@\"\n")
    for f in (script / "woodpile", real / "woodpile"):
        f.chmod(0o755)
    monkeypatch.delenv("WOODPILE_BIN", raising=False)
    monkeypatch.setattr(_pipeline, "_packaged_binary", lambda: tmp_path / "absent")
    monkeypatch.setenv("PATH", f"{script}:{real}")
    assert _pipeline.find_woodpile() == str(real / "woodpile")
    monkeypatch.setenv("PATH", str(script))
    with pytest.raises(FileNotFoundError, match="make wheel"):
        _pipeline.find_woodpile()
    # The script itself: `woodpile --version` through it is the command's.
    out = subprocess.run(
        [sys.executable, "-m", "woodpile._cli", "--version"],
        capture_output=True,
        text=True,
        env={**os.environ, "WOODPILE_BIN": woodpile_bin},
        check=True,
    )
    assert out.stdout.startswith("woodpile ")


@pytest.mark.skipif(
    not os.environ.get("WOODPILE_TEST_INSTALLED"), reason="tests an installed wheel (make wheel-test)"
)
def test_an_installed_wheel_drives_the_command_it_carries():
    from woodpile import _pipeline

    packaged = _pipeline._packaged_binary()
    assert packaged.is_file() and os.access(packaged, os.X_OK)
    assert _pipeline.find_woodpile() == str(packaged)


def test_read_refuses_a_table_without_a_seal(small_pipeline):
    """A parquet file woodpile did not write (no seal) is not read as a stage's table."""
    import pandas as pd

    p = woodpile.Pipeline(small_pipeline)
    p.results_dir.mkdir(parents=True, exist_ok=True)
    pd.DataFrame({"x": [1.0]}).to_parquet(p.table_path("small_sweep"))
    with pytest.raises(ValueError, match="not a woodpile table"):
        p.read("small_sweep")


def test_run_a_variant_with_set(small_pipeline):
    p = woodpile.Pipeline(small_pipeline)
    summary = p.run("small_fractions", set={"small_fractions.at": 20.0})
    variants = [s["stage"] for s in summary["stages"] if s["stage"].startswith("small_fractions--")]
    assert len(variants) == 1
    table = p.read(variants[0])
    assert (table.t == 20.0).all()
    with pytest.raises(woodpile.SceneError, match="no_such_key"):
        p.run(set={"small_fractions.no_such_key": 1})


def test_new_study_runs_as_written(tmp_path):
    p = woodpile.new_study(tmp_path / "study")
    assert (p.status().state == "missing").all()
    assert p.run()["ran"] > 0
    assert (p.status().state == "fresh").all()
    with pytest.raises(woodpile.SceneError):
        woodpile.new_study(tmp_path / "study")


def test_run_streams_the_commands_progress_when_asked(small_pipeline, capfd):
    p = woodpile.Pipeline(small_pipeline)
    p.run(progress=True)
    err = capfd.readouterr().err
    assert "small_sweep" in err and "done" in err
    p.run(force=True, progress=False)
    assert capfd.readouterr().err == ""
