//! Results trees: diff, shards merged into the single-machine result, damaged tables, and a
//! report that writes only its own Markdown.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;
use std::sync::atomic::Ordering;

use common::{load_error, Counter, Project, BEST, REDUCE, REPORT, SWEEP};
use woodpile_pipeline::diff::{diff, DiffOptions, Tolerance};
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::table;

#[test]
fn diff_agrees_on_identical_trees_and_catches_a_perturbed_value() {
    let a = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
    let b = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
    a.counted(&[]);
    b.counted(&[]);
    let exact = DiffOptions::default();
    let report = diff(&a.results(), &b.results(), &exact).unwrap();
    assert!(report.agrees(), "{report:?}");
    assert_eq!(report.files, 2);

    perturb(&b.output("best"), "E_tr", 1e-6);
    let report = diff(&a.results(), &b.results(), &exact).unwrap();
    assert!(!report.agrees());
    assert_eq!(report.worst[0].column, "E_tr");
    let loose = DiffOptions {
        default: Tolerance {
            abs: 1e-5,
            rel: 0.0,
        },
        ..Default::default()
    };
    assert!(diff(&a.results(), &b.results(), &loose).unwrap().agrees());

    std::fs::remove_file(b.output("sweep")).unwrap();
    let report = diff(&a.results(), &b.results(), &loose).unwrap();
    assert!(report.problems.iter().any(|p| p.contains("sweep.parquet")));
}

/// Adds `delta` to the first value of `column` in the table at `path`, keeping its manifest.
fn perturb(path: &Path, column: &str, delta: f64) {
    let manifest = table::read_manifest(path).unwrap().unwrap();
    let mut frame = table::read(path).unwrap();
    let mut values = table::f64_column(&frame, column).unwrap();
    values[0] = values[0].map(|v| v + delta);
    frame
        .with_column(polars::prelude::Column::new(column.into(), values))
        .unwrap();
    table::write(path, frame, &manifest).unwrap();
}

#[test]
fn sharded_runs_merge_into_the_single_machine_result() {
    use woodpile_pipeline::shard::merge;
    let single = Project::new(&[("sweep", SWEEP)]);
    single.counted(&[]);
    let sharded = Project::new(&[("sweep", SWEEP)]);
    let pipeline = sharded.load();
    let events = Counter::default();
    let shard = |i: usize, n: usize| {
        sharded.shard(&pipeline, "sweep", (i, n), &events).unwrap();
    };
    let merge_error = || {
        merge(&pipeline, "sweep", &sharded.results(), &Counter::default())
            .unwrap_err()
            .to_string()
    };
    shard(0, 4);
    shard(2, 4);
    // Incomplete: the error names the missing shards, and nothing is written.
    let err = merge_error();
    assert!(err.contains("2 of 4 shard(s) missing (1, 3;"), "{err}");
    assert!(!sharded.output("sweep").exists());
    // A part made with another N is a mismatch, not a silent mix.
    shard(0, 3);
    let err = merge_error();
    assert!(err.contains("different shard counts"), "{err}");
    std::fs::remove_dir_all(sharded.results().join("parts")).unwrap();

    for i in 0..4 {
        shard(i, 4);
    }
    // A shard re-run finds its part done and simulates nothing.
    let again = Counter::default();
    let rerun = sharded.shard(&pipeline, "sweep", (1, 4), &again).unwrap();
    assert!(rerun.already_done);
    assert_eq!(again.points.load(Ordering::SeqCst), 0);
    assert_eq!(
        merge(&pipeline, "sweep", &sharded.results(), &Counter::default()).unwrap(),
        4
    );
    let report = diff(
        &single.results(),
        &sharded.results(),
        &DiffOptions::default(),
    )
    .unwrap();
    assert!(report.agrees(), "{report:?}");
    let (a, b) = (
        table::read_manifest(&single.output("sweep"))
            .unwrap()
            .unwrap(),
        table::read_manifest(&sharded.output("sweep"))
            .unwrap()
            .unwrap(),
    );
    assert_eq!(a, b, "the merged manifest is the single run's");
    assert_eq!(
        state(
            &pipeline,
            &sharded.results(),
            &sharded.results(),
            pipeline.stage("sweep").unwrap()
        ),
        State::Fresh
    );
}

/// Replaces `path`'s first `column` value, keeping the manifest (and so its checksum) as it
/// was: a damaged data page that still decodes.
fn corrupt_keeping_manifest(path: &Path, column: &str) {
    use polars::prelude::*;
    let manifest = table::read_manifest(path).unwrap().unwrap();
    let mut frame = table::read(path).unwrap();
    let mut values = table::f64_column(&frame, column).unwrap();
    values[0] = values[0].map(|v| v + 0.25);
    frame
        .with_column(Column::new(column.into(), values))
        .unwrap();
    let metadata =
        KeyValueMetadata::from_static(vec![("woodpile".to_string(), manifest.to_json_text())]);
    let file = std::fs::File::create(path).unwrap();
    ParquetWriter::new(file)
        .with_key_value_metadata(Some(metadata))
        .finish(&mut frame)
        .unwrap();
}

#[test]
fn a_damaged_table_is_never_fresh_and_is_recomputed_before_it_is_read() {
    let p = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
    p.counted(&[]);
    let (sweep, best) = (
        std::fs::read(p.output("sweep")).unwrap(),
        std::fs::read(p.output("best")).unwrap(),
    );
    corrupt_keeping_manifest(&p.output("sweep"), "E_tr");
    assert!(
        matches!(p.state("sweep"), State::Damaged(ref why) if why.contains("seal")),
        "{:?}",
        p.state("sweep")
    );
    assert!(table::read(&p.output("sweep"))
        .unwrap_err()
        .to_string()
        .contains("seal"));
    // Forcing the downstream stage recomputes the damaged input first, with a warning.
    let events = p.counted_with(&["best"], true);
    assert!(events
        .warnings
        .lock()
        .unwrap()
        .iter()
        .any(|w| w.contains("`sweep`") && w.contains("again")));
    assert_eq!(std::fs::read(p.output("sweep")).unwrap(), sweep);
    assert_eq!(std::fs::read(p.output("best")).unwrap(), best);

    // One flipped bit in any page (data, header or statistics) or in the manifest is never
    // fresh either; every such byte is tried.
    let footer = u32::from_le_bytes(sweep[sweep.len() - 8..sweep.len() - 4].try_into().unwrap());
    let pages = sweep.len() - 8 - footer as usize;
    let manifest_text = table::read_manifest(&p.output("sweep"))
        .unwrap()
        .unwrap()
        .to_json_text();
    let manifest_at = sweep
        .windows(manifest_text.len())
        .position(|w| w == manifest_text.as_bytes())
        .unwrap();
    let offsets = (0..pages).chain(manifest_at..manifest_at + manifest_text.len());
    for offset in offsets {
        let mut bytes = sweep.clone();
        bytes[offset] ^= 0x04;
        std::fs::write(p.output("sweep"), &bytes).unwrap();
        assert!(
            !matches!(p.state("sweep"), State::Fresh),
            "a flip at byte {offset} of {} went unnoticed",
            sweep.len()
        );
    }
}

#[test]
fn a_report_writes_only_markdown_inside_the_tree_and_never_over_a_file_it_did_not_write() {
    let report = REPORT.replace("PAPER", "0.1");
    for (markdown, expected) in [
        ("../../x.md", "inside the project"),
        ("/tmp/x.md", "inside the project"),
        ("results/sweep.parquet", "must end in `.md`"),
        ("figures/f.png", "must end in `.md`"),
    ] {
        let e = load_error(&[
            ("sweep", SWEEP),
            ("at_end", REDUCE),
            (
                "report",
                &report.replace("\"REPORT.md\"", &format!("\"{markdown}\"")),
            ),
        ]);
        assert!(
            e.contains("report.toml") && e.contains("`markdown`") && e.contains(expected),
            "{markdown}: {e}"
        );
    }
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("report", &report),
        ("report2", &report),
    ]);
    assert!(
        e.contains("report2.toml") && e.contains("written by stage `report`"),
        "{e}"
    );

    // A hand-written file of that name is not overwritten; the report's own file is.
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("report", &report)]);
    let markdown = p.results().parent().unwrap().join("REPORT.md");
    std::fs::write(&markdown, "mine").unwrap();
    let options = RunOptions {
        targets: vec![],
        force: false,
        dry_run: false,
        results: p.results().clone(),
        figures: p.figures(),
    };
    let e = run(&p.load(), &options, &Counter::default()).unwrap_err();
    assert!(e.to_string().contains("did not write"), "{e}");
    assert_eq!(std::fs::read_to_string(&markdown).unwrap(), "mine");
    std::fs::remove_file(&markdown).unwrap();
    p.counted(&[]);
    p.counted_with(&["report"], true);
    assert!(std::fs::read_to_string(&markdown)
        .unwrap()
        .starts_with("# Tiny report"));
}

#[test]
fn diff_reports_changed_types_and_missing_manifests_and_refuses_unknown_columns() {
    use polars::prelude::*;
    let a = Project::new(&[("sweep", SWEEP)]);
    let b = Project::new(&[("sweep", SWEEP)]);
    a.counted(&[]);
    b.counted(&[]);
    // `steps` (integers) rewritten as floats, without a manifest.
    let mut frame = table::read(&b.output("sweep")).unwrap();
    let steps = frame
        .column("steps")
        .unwrap()
        .cast(&DataType::Float64)
        .unwrap();
    frame.with_column(steps).unwrap();
    let file = std::fs::File::create(b.output("sweep")).unwrap();
    ParquetWriter::new(file).finish(&mut frame).unwrap();
    let report = diff(&a.results(), &b.results(), &DiffOptions::default()).unwrap();
    assert!(!report.agrees());
    assert!(
        report
            .problems
            .iter()
            .any(|p| p.contains("`steps`") && p.contains("f64")),
        "{:?}",
        report.problems
    );
    assert!(
        report
            .problems
            .iter()
            .any(|p| p.contains("no `woodpile` manifest")),
        "{:?}",
        report.problems
    );
    let mut options = DiffOptions::default();
    options.columns.insert("nope".into(), Tolerance::default());
    let e = diff(&a.results(), &a.results(), &options).unwrap_err();
    assert!(e.to_string().contains("`nope`"), "{e}");
}
