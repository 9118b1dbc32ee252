//! Titles that quote input manifests: `{stage.params.at}` replaced by that value, checked at
//! parse time against the stage's inputs and expanded in one bounded pass when drawing.

use std::collections::HashMap;

use polars::prelude::DataFrame;
use serde_json::Value;

use woodpile_pipeline::manifest::Manifest;

/// The `{stage.path}` quotes of `text`, each naming one of `inputs`.
pub(super) fn check_quotes(text: &str, inputs: &[String]) -> std::result::Result<(), String> {
    for quote in quotes(text) {
        let stage = quote.split('.').next().unwrap_or_default();
        if !inputs.iter().any(|i| i == stage) {
            return Err(format!(
                "`{{{quote}}}` quotes `{stage}`, which is not one of the inputs {inputs:?}"
            ));
        }
    }
    Ok(())
}

/// The quotes of `text`: each `{...}` that is not a markup group (`E_{tr}`, `10^{-3}`).
fn quotes(text: &str) -> impl Iterator<Item = &str> {
    text.match_indices('{')
        .filter(|&(i, _)| !is_markup_group(text, i))
        .filter_map(|(i, _)| text[i + 1..].split_once('}').map(|(q, _)| q))
        .filter(|q| !q.contains('{'))
}

/// Whether the `{` at byte `open` of `text` opens a sub- or superscript group.
fn is_markup_group(text: &str, open: usize) -> bool {
    text[..open].ends_with(['_', '^'])
}

/// Longest text a title or label may expand to: far more than any figure shows.
const MAX_EXPANDED_CHARS: usize = 100_000;

/// `text` with every `{stage.path}` replaced by that value of the stage's manifest, in one
/// pass over `text`: inserted values are never expanded again (a quoted value cannot inject
/// quotes, and the order of the quotes does not matter), each distinct quote is looked up
/// once, and the result is at most [`MAX_EXPANDED_CHARS`] long.
pub(super) fn quoted(
    text: &str,
    inputs: &HashMap<String, (DataFrame, Manifest)>,
) -> std::result::Result<String, String> {
    let mut manifests: HashMap<&str, Value> = HashMap::new();
    let mut values: HashMap<&str, String> = HashMap::new();
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        if is_markup_group(rest, open) {
            out.push('{');
            rest = after;
            continue;
        }
        // A quote runs to the next `}` with no `{` before it; anything else is literal.
        let Some(close) = after
            .find(['{', '}'])
            .filter(|&i| after.as_bytes()[i] == b'}')
        else {
            out.push('{');
            rest = after;
            continue;
        };
        let quote = &after[..close];
        if !values.contains_key(quote) {
            let shown = quote_value(quote, inputs, &mut manifests)?;
            values.insert(quote, shown);
        }
        out.push_str(&values[quote]);
        if out.len() > MAX_EXPANDED_CHARS {
            return Err(format!(
                "the text expands to more than {MAX_EXPANDED_CHARS} characters; quote less"
            ));
        }
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The shown value of one quote `stage.path`.
fn quote_value<'a>(
    quote: &'a str,
    inputs: &HashMap<String, (DataFrame, Manifest)>,
    manifests: &mut HashMap<&'a str, Value>,
) -> std::result::Result<String, String> {
    let (stage, path) = quote.split_once('.').unwrap_or((quote, ""));
    if !manifests.contains_key(stage) {
        let manifest = inputs
            .get(stage)
            .map(|(_, m)| serde_json::to_value(m).unwrap_or(Value::Null))
            .ok_or_else(|| format!("`{{{quote}}}`: no input `{stage}`"))?;
        manifests.insert(stage, manifest);
    }
    let value = woodpile_pipeline::manifest::lookup(&manifests[stage], path)
        .ok_or_else(|| format!("`{{{quote}}}`: the manifest of `{stage}` has no `{path}`"))?;
    Ok(match value {
        Value::Number(n) => n
            .as_f64()
            .map_or(n.to_string(), |x| woodpile_plot::tick(&x)),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_groups_are_not_quotes() {
        let inputs = ["f4".to_string()];
        assert!(check_quotes("best E_{tr} at {f4.params.at}, 10^{-3}", &inputs).is_ok());
        assert!(check_quotes("{tr}", &inputs).is_err());
        let expanded = quoted("E_{tr} and 10^{-3}", &HashMap::new()).unwrap();
        assert_eq!(expanded, "E_{tr} and 10^{-3}");
    }
}
