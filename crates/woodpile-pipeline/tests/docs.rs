//! `docs/stage-kinds.md` is generated from the module documentation of every stage kind
//! (`src/kinds/<kind>.rs`, the one place each kind's keys are described), so the reference a user
//! reads cannot drift from the code. This test fails when it is out of date;
//! `UPDATE_DOCS=1 cargo test -p woodpile-pipeline --test docs` (or `make docs`) rewrites it.
#![allow(clippy::unwrap_used)]

use std::path::Path;

use woodpile_pipeline::kind;

fn module_doc(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .take_while(|l| l.starts_with("//!"))
        .map(|l| {
            l.strip_prefix("//! ")
                .unwrap_or(l.strip_prefix("//!").unwrap_or(l))
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn generated() -> String {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = String::from(
        "# Stage kinds\n\n<!-- Generated from the module documentation of each kind \
         (crates/woodpile-pipeline/src/kinds/<kind>.rs) by `make docs`; do not edit by hand. -->\n\n\
         Every stage file takes the common keys below; the rest belong to its kind. Unknown keys \
         are errors that name the file and the key.\n\n",
    );
    out.push_str(&module_doc(&src.join("stage.rs")));
    out.push('\n');
    for kind in kind::names() {
        out.push_str(&format!("\n## `{kind}`\n\n"));
        out.push_str(&module_doc(&src.join(format!("kinds/{kind}.rs"))));
        out.push('\n');
    }
    out
}

#[test]
fn the_stage_kind_reference_is_generated_from_the_code() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/stage-kinds.md");
    let expected = generated();
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(&path, &expected).unwrap();
    }
    let current = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        current == expected,
        "docs/stage-kinds.md is out of date: run `make docs`"
    );
}
