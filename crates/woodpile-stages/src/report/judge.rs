//! Whether a measured number reproduces the paper's, and by how much it differs: what the
//! report judges, apart from how [`super::markdown`](mod@super::markdown) writes it.

use super::measure::Measured;
use super::Paper;

/// Whether `m` reproduces the paper's number (None for a statement without a range).
pub(super) fn reproduces(paper: &Paper, m: &Measured) -> Option<bool> {
    if m.failure.is_some() {
        return None;
    }
    match paper {
        Paper::Value { value, agree } => Some((m.value - value).abs() <= *agree),
        Paper::Text {
            range: Some([lo, hi]),
            ..
        } => Some((*lo..=*hi).contains(&m.value)),
        Paper::Text { range: None, .. } => None,
    }
}

/// Our number minus the paper's, absolute and relative (None where the paper gives no number
/// or ours failed).
pub(super) fn difference(p: &Paper, m: &Measured) -> (Option<f64>, Option<f64>) {
    if m.failure.is_some() {
        return (None, None);
    }
    match p {
        Paper::Value { value, .. } => (
            Some(m.value - value),
            (*value != 0.0).then(|| (m.value - value) / value.abs()),
        ),
        Paper::Text { .. } => (None, None),
    }
}

/// The verdict column: yes, no, or – where the paper gives no range.
pub(super) fn verdict(p: &Paper, m: &Measured) -> &'static str {
    match reproduces(p, m) {
        Some(true) => "yes",
        Some(false) => "no",
        None => "–",
    }
}
