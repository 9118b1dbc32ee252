//! What `woodpile run --json` and `woodpile status --json` print: the contract Python's
//! `Pipeline.run` and `.status` read (docs/python.md), as types, so that a field cannot be
//! renamed or dropped in one place and not the other.

use serde::Serialize;

/// `run --json`: what ran (or would run, with `--dry-run`) and what it cost.
#[derive(Debug, Serialize)]
pub(crate) struct RunReport {
    /// Whether nothing was run, only decided.
    pub dry_run: bool,
    /// Every stage of the selection, upstream first.
    pub stages: Vec<StageRun>,
    /// How many stages ran (or would run).
    pub ran: usize,
    /// How many were fresh.
    pub fresh: usize,
    /// Scenes simulated by this run (0 for a dry run).
    pub scenes_simulated: u64,
    /// Wall time of the run.
    pub seconds: f64,
}

/// One stage of a run.
#[derive(Debug, Serialize)]
pub(crate) struct StageRun {
    /// Its name.
    pub stage: String,
    /// Whether it ran (or would run).
    pub runs: bool,
    /// Why it ran, or why it is fresh.
    pub why: String,
    /// For a grid of scenes: how many points, and how many the cache held.
    pub points: Option<usize>,
    pub cached: Option<usize>,
}

impl StageRun {
    /// A stage of a run as it is told.
    pub fn of(step: &woodpile_pipeline::run::Step) -> StageRun {
        StageRun {
            stage: step.stage.clone(),
            runs: step.runs,
            why: step.why.clone(),
            points: step.points.map(|(n, _)| n),
            cached: step.points.map(|(_, c)| c),
        }
    }
}

/// One row of `status --json`.
#[derive(Debug, Serialize)]
pub(crate) struct StageStatus {
    /// Its name.
    pub stage: String,
    /// Its kind's name.
    pub kind: &'static str,
    /// `fresh`, `stale`, `missing` or `damaged`.
    pub state: &'static str,
    /// Why it is not fresh (empty when it is).
    pub why: String,
}

/// `value` as one line of JSON (or indented, with `pretty`) holding no raw control character:
/// serde_json escapes those below U+0020 but leaves DEL and U+0080–U+009F, which a terminal
/// obeys; they are written as `\u007f`-style escapes, still valid JSON.
pub(crate) fn json_text<T: Serialize>(value: &T, pretty: bool) -> serde_json::Result<String> {
    let text = match pretty {
        true => serde_json::to_string_pretty(value)?,
        false => serde_json::to_string(value)?,
    };
    Ok(text
        .chars()
        .map(|c| match c.is_control() && c > '\u{1f}' {
            true => format!("\\u{:04x}", c as u32),
            false => c.to_string(),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// DEL and the C1 controls (which serde_json leaves raw) come out escaped, and the text
    /// is still JSON that reads back to the same value.
    #[test]
    fn json_text_has_no_raw_control_and_stays_json() {
        let value = serde_json::json!({"why": "a\u{7f}b\u{85}c\u{9b}2J\u{1b}"});
        for pretty in [false, true] {
            let text = json_text(&value, pretty).unwrap();
            assert!(
                !text.chars().any(|c| c.is_control() && c != '\n'),
                "{text:?}"
            );
            let back: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!(back, value);
        }
    }
}
