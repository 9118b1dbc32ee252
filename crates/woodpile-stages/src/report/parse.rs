//! A `[[quote]]` table and its sources, read key by key from the stage file, and the rule for
//! where a report's Markdown may go.

use std::path::Path;

use woodpile_pipeline::error::Result;
use woodpile_pipeline::fields::{Ends, Fields};

use super::{Convention, Paper, Quote, Read, Source};

/// A report's Markdown must stay inside the tree that holds `results/` (a relative path of
/// plain names, no `..`; `.` and repeated slashes are dropped) and be Markdown: any other extension could overwrite another stage's
/// table or figure.
pub(super) fn check_markdown_path(markdown: &str) -> std::result::Result<(), String> {
    let path = Path::new(markdown);
    if !woodpile_files::layout::is_plain_relative(markdown) {
        return Err(format!(
            "`{markdown}` must be a relative path inside the project (no `..`, not absolute)"
        ));
    }
    if path.extension().is_none_or(|e| e != "md") {
        return Err(format!(
            "`{markdown}` must end in `.md`: a report writes Markdown, and another name could replace a stage's table or figure"
        ));
    }
    Ok(())
}

pub(super) fn parse_quote(mut f: Fields<'_>) -> Result<Quote> {
    let figure: String = f.required("figure")?;
    let quantity: String = f.required("quantity")?;
    let paper = match (
        f.optional::<f64>("paper")?,
        f.optional::<String>("paper_text")?,
    ) {
        (Some(value), None) => Paper::Value {
            value,
            agree: f.required::<f64>("agree")?.abs(),
        },
        (None, Some(text)) => Paper::Text {
            text,
            range: f.interval("range", Ends::MayMeet)?,
        },
        _ => {
            return Err(f.error(
                "paper",
                "give exactly one of `paper` (a number) and `paper_text`",
            ))
        }
    };
    let as_run: String = f.required("as_run")?;
    let note: String = f.optional("note")?.unwrap_or_default();
    let ours_table: toml::Table = f.required("ours")?;
    let ours = parse_source(f.nested("ours", ours_table))?;
    let mut conventions = Vec::new();
    if let Some(value) = f.take("convention") {
        let toml::Value::Array(entries) = value else {
            return Err(f.error("convention", "expected [[quote.convention]] tables"));
        };
        for (j, entry) in entries.into_iter().enumerate() {
            let key = format!("convention[{j}]");
            let toml::Value::Table(table) = entry else {
                return Err(f.error(&key, "expected a table"));
            };
            let mut c = f.nested(&key, table);
            let name: String = c.required("name")?;
            let source_table: toml::Table = c.required("source")?;
            let source = parse_source(c.nested("source", source_table))?;
            c.finish()?;
            conventions.push(Convention { name, source });
        }
    }
    f.finish()?;
    Ok(Quote {
        figure,
        quantity,
        paper,
        ours,
        as_run,
        note,
        conventions,
    })
}

pub(super) fn parse_source(mut f: Fields<'_>) -> Result<Source> {
    let stage: String = f.required("stage")?;
    let read = match (
        f.optional::<String>("column")?,
        f.optional::<String>("manifest")?,
    ) {
        (Some(c), None) => Read::Column(c),
        (None, Some(p)) if !p.trim_matches(['/', '.']).is_empty() => Read::Manifest(p),
        (None, Some(_)) => {
            return Err(f.error(
                "manifest",
                "expected a path into the manifest such as \"summary.rms_error\"",
            ))
        }
        _ => return Err(f.error("column", "give exactly one of `column` and `manifest`")),
    };
    let filter = f.equality_filter("where")?;
    let max = f.optional::<String>("max")?;
    let locate = f.optional::<Vec<String>>("locate")?.unwrap_or_default();
    let scan = f.optional::<String>("scan")?;
    let scan_range = f.interval("scan_range", Ends::MayMeet)?;
    if scan_range.is_some() && scan.is_none() {
        return Err(f.error("scan_range", "needs `scan`"));
    }
    if matches!(read, Read::Manifest(_))
        && (!filter.is_empty() || max.is_some() || scan.is_some() || !locate.is_empty())
    {
        return Err(f.error(
            "manifest",
            "a manifest entry takes no `where`, `max`, `locate` or `scan`",
        ));
    }
    f.finish()?;
    Ok(Source {
        stage,
        read,
        filter,
        max,
        locate,
        scan,
        scan_range,
    })
}
