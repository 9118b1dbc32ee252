//! A stage's parameters ([`Params`]): what its key hashes and its manifest records, kept as
//! the stage's own keys over the one shared copy of its kind's defaults.

use std::sync::Arc;

use serde_json::Value;
use woodpile_files::key::toml_to_json;

/// `table` as JSON, without `description` (free text, not part of the key).
pub(crate) fn own_params(table: &toml::Table) -> Value {
    let mut params = toml_to_json(&toml::Value::Table(table.clone()));
    if let Value::Object(map) = &mut params {
        map.remove("description");
    }
    params
}

/// A stage's parameters: its file's content without `description`, laid over its kind's
/// defaults. The defaults are held once for every stage of the kind, not copied into each: a
/// large defaults file under thousands of stages would otherwise fill the memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    pub(crate) own: Value,
    pub(crate) defaults: Option<Arc<Value>>,
}

impl Params {
    /// The parameters whole, as canonical JSON: what the stage's key hashes and its manifest
    /// records. Made afresh on each call, for the few places that need it whole.
    pub fn value(&self) -> Value {
        let Some(defaults) = &self.defaults else {
            return self.own.clone();
        };
        let mut merged = Value::clone(defaults);
        merge_json(&mut merged, &self.own);
        merged
    }
}

/// `over` laid over `base` as [`crate::stage::merge`] lays tables: objects merge key by key, any other
/// value replaces.
fn merge_json(base: &mut Value, over: &Value) {
    match (base, over) {
        (Value::Object(base), Value::Object(over)) => {
            for (key, value) in over {
                match base.get_mut(key) {
                    Some(inner @ Value::Object(_)) if value.is_object() => merge_json(inner, value),
                    _ => {
                        base.insert(key.clone(), value.clone());
                    }
                }
            }
        }
        (base, over) => *base = over.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stage::merge;

    /// The parameters a stage keeps (its own keys over the shared defaults) are the ones the
    /// merged table gives, so no stage's key changed when the defaults stopped being copied.
    #[test]
    fn shared_defaults_give_the_merged_tables_parameters() {
        let defaults: toml::Table =
            toml::from_str("[style]\ndpi = 300\nfont_pt = 8\n[labels]\nE_tr = \"E_{tr}\"\n")
                .unwrap();
        let own: toml::Table = toml::from_str(
            "kind = \"render\"\ndescription = \"d\"\ny = [1, 2]\n[style]\ndpi = 150\n[labels]\nR = \"r\"\n",
        )
        .unwrap();
        let mut merged = defaults.clone();
        merge(&mut merged, own.clone());
        let params = Params {
            own: own_params(&own),
            defaults: Some(Arc::new(toml_to_json(&toml::Value::Table(defaults)))),
        };
        assert_eq!(params.value(), own_params(&merged));
        assert_eq!(params.value()["style"]["dpi"], 150);
        assert_eq!(params.value()["style"]["font_pt"], 8);
    }
}
