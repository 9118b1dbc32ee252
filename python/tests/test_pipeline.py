"""`woodpile.Pipeline` on a small project in a temporary folder."""

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
