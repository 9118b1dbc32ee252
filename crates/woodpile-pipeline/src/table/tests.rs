//! The table builder, the seal over the whole file, and every flipped bit refused.

use super::*;

fn manifest() -> Manifest {
    Manifest {
        stage: "s".into(),
        kind: "sweep".into(),
        key: "k".into(),
        code_version: "v".into(),
        params: serde_json::json!({"a": 1e-6, "b": [1, 2.5], "c": "x"}),
        inputs: Default::default(),
        summary: serde_json::json!({"points": 3}),
        files: Default::default(),
        checksum: None,
    }
}

struct Pair(i64, Option<f64>, bool);

impl Row for Pair {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let second = match self.2 {
            true => Cell::from("text"),
            false => Cell::from(self.1),
        };
        vec![("n", Cell::from(self.0)), ("x", second)]
    }
}

#[test]
fn rows_make_typed_columns_and_mixed_kinds_are_an_error() {
    let frame = rows_frame(&[Pair(1, Some(0.5), false), Pair(2, None, false)]).unwrap();
    assert_eq!(frame.height(), 2);
    assert_eq!(f64_column(&frame, "x").unwrap(), vec![Some(0.5), None]);
    assert_eq!(frame.column("n").unwrap().dtype(), &DataType::Int64);
    let e = rows_frame(&[Pair(1, Some(0.5), false), Pair(2, None, true)]).unwrap_err();
    assert!(e.to_string().contains("`x` mixes"), "{e}");
}

/// Text read as numbers is refused, not cast to nulls (a figure of it drew nothing, silently).
#[test]
fn a_text_column_is_not_read_as_numbers() {
    let frame = rows_frame(&[Pair(1, None, true)]).unwrap();
    let e = f64_column(&frame, "x").unwrap_err();
    assert!(
        e.to_string().contains("column `x` holds str, not numbers"),
        "{e}"
    );
}

/// `columns` written as a sealed table in a fresh temporary folder (kept alive by the returned
/// guard): the folder, the table's path and the frame written.
fn written(columns: &mut Columns) -> (tempfile::TempDir, std::path::PathBuf, DataFrame) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.parquet");
    let frame = std::mem::take(columns).into_frame().unwrap();
    write(&path, frame.clone(), &manifest()).unwrap();
    (dir, path, frame)
}

#[test]
fn a_written_table_reads_back_intact() {
    let (_dir, path, frame) = written(
        Columns::new()
            .f64("x", vec![Some(1.0), None, Some(f64::NAN)])
            .i64("n", vec![Some(1), Some(2), None])
            .str("s", vec![Some("a".into()), None, Some("c".into())]),
    );
    let checked = read_checked(&path).unwrap();
    assert!(checked.frame.equals_missing(&frame), "content");
    let mut m = checked.manifest.clone().unwrap();
    m.checksum = None;
    assert_eq!(m.to_json_text(), manifest().to_json_text(), "manifest");
    assert_eq!(checked.integrity, Integrity::Intact);
}

/// Every single-bit flip of a sealed table reads as damaged (and is never decoded), or
/// leaves a table that is still intact: never an abort, a panic or a different table.
#[test]
fn every_flipped_bit_is_caught_before_decoding() {
    let (dir, path, _) = written(
        Columns::new()
            .f64("R", (0..40).map(|i| Some(f64::from(i) * 0.25)).collect())
            .i64("point", (0..40).map(Some).collect())
            .str(
                "failure",
                (0..40)
                    .map(|i| (i % 7 == 0).then(|| format!("f{i}")))
                    .collect(),
            ),
    );
    let bytes = std::fs::read(&path).unwrap();
    let flipped = dir.path().join("flipped.parquet");
    for byte in 0..bytes.len() {
        for bit in 0..8 {
            let mut copy = bytes.clone();
            copy[byte] ^= 1 << bit;
            std::fs::write(&flipped, &copy).unwrap();
            let checked = read_checked(&flipped).unwrap();
            assert_eq!(
                checked.integrity,
                Integrity::Damaged,
                "byte {byte} bit {bit}"
            );
            assert!(read(&flipped).is_err());
            assert!(read_manifest(&flipped).is_err());
        }
    }
}
