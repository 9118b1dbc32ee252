//! The `table` kind, the worked example of docs/adding-a-kind.md: an input's rows and columns
//! as a CSV beside the stage's parquet, read back to the same numbers, and sealed like every
//! file a stage writes.
#![allow(clippy::unwrap_used)]

mod common;

use common::{Project, SWEEP};
use woodpile_pipeline::status::State;
use woodpile_pipeline::table;

const REDUCE: &str = r#"
kind = "reduce"
inputs = ["sweep"]
"#;

const TABLE: &str = r#"
kind = "table"
inputs = ["fractions"]
columns = ["eps", "R", "E_tr"]
where = { L = 1 }
"#;

#[test]
fn a_table_stage_writes_the_chosen_rows_and_columns_as_csv_that_reads_back_exactly() {
    let p = Project::new(&[("sweep", SWEEP), ("fractions", REDUCE), ("export", TABLE)]);
    p.run(&[]).unwrap();
    let text = std::fs::read_to_string(p.results().join("export.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("eps,R,E_tr"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    // The rows of L = 1, in the input's order, to the last bit.
    let input = table::read(&p.output("fractions")).unwrap();
    let l = table::f64_column(&input, "L").unwrap();
    let keep: Vec<usize> = (0..input.height()).filter(|&r| l[r] == Some(1.0)).collect();
    assert_eq!(rows.len(), keep.len());
    for (k, column) in ["eps", "R", "E_tr"].iter().enumerate() {
        let values = table::f64_column(&input, column).unwrap();
        for (row, &r) in rows.iter().zip(&keep) {
            assert_eq!(Some(row[k]), values[r], "{column}");
        }
    }
    // The stage's own table is what the CSV holds.
    let own = table::read(&p.output("export")).unwrap();
    assert_eq!(own.height(), rows.len());
    assert_eq!(p.state("export"), State::Fresh);
    // A CSV edited by hand is not this run's: the stage is stale until it is written again.
    std::fs::write(p.results().join("export.csv"), text.replace(',', ";")).unwrap();
    assert_ne!(p.state("export"), State::Fresh);
    p.run(&[]).unwrap();
    assert_eq!(
        std::fs::read_to_string(p.results().join("export.csv")).unwrap(),
        text
    );
}

#[test]
fn a_table_stage_names_what_it_cannot_write() {
    let list_column = r#"
kind = "table"
inputs = ["fractions"]
columns = ["nope"]
"#;
    let p = Project::new(&[
        ("sweep", SWEEP),
        ("fractions", REDUCE),
        ("export", list_column),
    ]);
    let e = p.run(&[]).unwrap_err().to_string();
    assert!(e.contains("nope"), "{e}");
    let twice = TABLE.replace(r#"["eps", "R", "E_tr"]"#, r#"["eps", "eps"]"#);
    let p = Project::new(&[("sweep", SWEEP), ("fractions", REDUCE), ("export", &twice)]);
    let e = p.run(&[]).unwrap_err().to_string();
    assert!(
        e.contains("listed twice") && e.contains("export.toml"),
        "{e}"
    );
}
