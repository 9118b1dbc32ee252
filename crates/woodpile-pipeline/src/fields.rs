//! Reading a stage file's TOML table key by key, so that every error names the exact key: a
//! value of the wrong type, a missing required key, or a key nobody asked for (a typo must
//! never be silently ignored).

use std::path::Path;

use crate::error::PipelineError;
use crate::table::Match;

/// The keys of one TOML table not yet consumed.
pub struct Fields<'a> {
    file: &'a Path,
    prefix: String,
    table: toml::Table,
}

impl<'a> Fields<'a> {
    /// `table`, found at dotted path `prefix` ("" for the file's top level) of `file`.
    pub fn new(file: &'a Path, prefix: &str, table: toml::Table) -> Self {
        Self {
            file,
            prefix: prefix.to_string(),
            table,
        }
    }

    /// The dotted path of `key` in this table.
    pub fn path(&self, key: &str) -> String {
        if self.prefix.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.prefix)
        }
    }

    /// An error about `key` of this table.
    pub fn error(&self, key: &str, reason: impl Into<String>) -> PipelineError {
        PipelineError::Definition {
            file: self.file.to_path_buf(),
            key: self.path(key),
            reason: reason.into(),
            source: None,
        }
    }

    /// An error about this table as a whole.
    pub fn error_here(&self, reason: impl Into<String>) -> PipelineError {
        PipelineError::Definition {
            file: self.file.to_path_buf(),
            key: self.prefix.clone(),
            reason: reason.into(),
            source: None,
        }
    }

    /// `table`, found at `key` of this table, as its own [`Fields`].
    pub fn nested(&self, key: &str, table: toml::Table) -> Fields<'a> {
        Fields::new(self.file, &self.path(key), table)
    }

    /// The keys not yet consumed, sorted.
    pub fn keys(&self) -> Vec<String> {
        self.table.keys().cloned().collect()
    }

    /// The file these fields come from.
    pub fn file(&self) -> &'a Path {
        self.file
    }

    /// Removes and returns `key`'s raw value.
    pub fn take(&mut self, key: &str) -> Option<toml::Value> {
        self.table.remove(key)
    }

    /// A required value of type `T`.
    pub fn required<T: FromToml>(&mut self, key: &str) -> Result<T, PipelineError> {
        self.optional(key)?
            .ok_or_else(|| self.error(key, format!("missing (expected {})", T::EXPECTED)))
    }

    /// An optional value of type `T`.
    pub fn optional<T: FromToml>(&mut self, key: &str) -> Result<Option<T>, PipelineError> {
        match self.table.remove(key) {
            None => Ok(None),
            Some(value) => T::from_toml(value)
                .map(Some)
                .ok_or_else(|| self.error(key, format!("expected {}", T::EXPECTED))),
        }
    }

    /// A key whose value is one of `options` (the names a stage file writes, each with the
    /// value it stands for), or `default` when absent (`None`: the key is required). The one
    /// parser of every "one of these words" key, so each refusal reads alike ([`pick`]).
    pub fn choice<T: Copy>(
        &mut self,
        key: &str,
        options: &[(&str, T)],
        default: Option<T>,
    ) -> Result<T, PipelineError> {
        match (self.optional_choice(key, options)?, default) {
            (Some(value), _) | (None, Some(value)) => Ok(value),
            (None, None) => Err(self.error(
                key,
                format!("missing (expected {})", <String as FromToml>::EXPECTED),
            )),
        }
    }

    /// [`Fields::choice`] of a key that may be absent, with no default: `None` then.
    pub fn optional_choice<T: Copy>(
        &mut self,
        key: &str,
        options: &[(&str, T)],
    ) -> Result<Option<T>, PipelineError> {
        match self.optional::<String>(key)? {
            None => Ok(None),
            Some(given) => pick(options, &given)
                .map(Some)
                .map_err(|e| self.error(key, e)),
        }
    }

    /// An optional `key = [lo, hi]` of finite numbers, the one parser of every range key:
    /// `lo <= hi` for a closed range ([`Ends::MayMeet`]), `lo < hi` for an interval of
    /// positive width ([`Ends::Apart`]).
    pub fn interval(&mut self, key: &str, ends: Ends) -> Result<Option<[f64; 2]>, PipelineError> {
        let Some(value) = self.table.remove(key) else {
            return Ok(None);
        };
        match (Vec::<f64>::from_toml(value).as_deref(), ends) {
            (Some(&[lo, hi]), Ends::MayMeet) if lo <= hi => Ok(Some([lo, hi])),
            (Some(&[lo, hi]), Ends::Apart) if lo < hi => Ok(Some([lo, hi])),
            (_, Ends::MayMeet) => Err(self.error(key, "expected [lo, hi] with lo <= hi")),
            (_, Ends::Apart) => Err(self.error(key, "expected [lo, hi] with lo < hi")),
        }
    }

    /// An optional `key = { column = value, ... }` row filter, the one `where` of every kind:
    /// each value a number or a string, matched by equality ([`crate::table::matching_rows`]).
    pub fn equality_filter(&mut self, key: &str) -> Result<Vec<(String, Match)>, PipelineError> {
        let Some(table) = self.optional::<toml::Table>(key)? else {
            return Ok(Vec::new());
        };
        let f = self.nested(key, table);
        let mut filter = Vec::with_capacity(f.table.len());
        for (column, value) in &f.table {
            let m = match value {
                toml::Value::Float(x) => Match::Number(*x),
                toml::Value::Integer(i) => Match::Number(*i as f64),
                toml::Value::String(s) => Match::Text(s.clone()),
                _ => return Err(f.error(column, "expected a number or a string")),
            };
            filter.push((column.clone(), m));
        }
        Ok(filter)
    }

    /// `key = [{ ... }, ...]`: each table as its own [`Fields`] (keys `key[i].…`), none when
    /// the key is absent; anything else is an error saying what was `expected`.
    pub fn table_array(
        &mut self,
        key: &str,
        expected: &str,
    ) -> Result<Vec<Fields<'a>>, PipelineError> {
        let Some(value) = self.take(key) else {
            return Ok(Vec::new());
        };
        let toml::Value::Array(items) = value else {
            return Err(self.error(key, format!("expected an array of {expected} tables")));
        };
        items
            .into_iter()
            .enumerate()
            .map(|(i, item)| {
                let at = format!("{key}[{i}]");
                match item {
                    toml::Value::Table(table) => Ok(self.nested(&at, table)),
                    _ => Err(self.error(&at, format!("expected a table {expected}"))),
                }
            })
            .collect()
    }

    /// Rejects every key left unconsumed.
    pub fn finish(self) -> Result<(), PipelineError> {
        match self.table.keys().next() {
            None => Ok(()),
            Some(key) => Err(self.error(key, "unknown key")),
        }
    }
}

/// How the ends of a `[lo, hi]` range may compare ([`Fields::interval`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ends {
    /// `lo <= hi`: a closed range, possibly one point.
    MayMeet,
    /// `lo < hi`: a range of positive width (an axis, a search box).
    Apart,
}

/// A Rust type a TOML value converts to.
pub trait FromToml: Sized {
    /// What the error says was expected.
    const EXPECTED: &'static str;
    /// The conversion, or `None` for a value of the wrong type.
    fn from_toml(value: toml::Value) -> Option<Self>;
}

/// `FromToml` for the types that are one TOML variant as it is.
macro_rules! from_toml_variant {
    ($($t:ty => $variant:ident, $expected:literal;)*) => {$(
        impl FromToml for $t {
            const EXPECTED: &'static str = $expected;
            fn from_toml(value: toml::Value) -> Option<Self> {
                match value {
                    toml::Value::$variant(x) => Some(x),
                    _ => None,
                }
            }
        }
    )*};
}

from_toml_variant! {
    String => String, "a string";
    i64 => Integer, "an integer";
    toml::Table => Table, "a table";
}

/// `FromToml` for arrays whose every item reads as the element type.
macro_rules! from_toml_array {
    ($($t:ty, $expected:literal;)*) => {$(
        impl FromToml for Vec<$t> {
            const EXPECTED: &'static str = $expected;
            fn from_toml(value: toml::Value) -> Option<Self> {
                match value {
                    toml::Value::Array(items) => items.into_iter().map(<$t>::from_toml).collect(),
                    _ => None,
                }
            }
        }
    )*};
}

from_toml_array! {
    String, "an array of strings";
    f64, "an array of numbers";
}

impl FromToml for f64 {
    const EXPECTED: &'static str = "a number";
    fn from_toml(value: toml::Value) -> Option<Self> {
        match value {
            toml::Value::Float(x) if x.is_finite() => Some(x),
            toml::Value::Integer(i) => Some(i as f64),
            _ => None,
        }
    }
}

impl FromToml for toml::Value {
    const EXPECTED: &'static str = "a value";
    fn from_toml(value: toml::Value) -> Option<Self> {
        Some(value)
    }
}

/// The value of `options` named `given`, or the reason it is none of them:
/// `expected "a", "b" or "c", got "x"`. Every "one of these words" value of a stage file is
/// read by it (through [`Fields::choice`], or directly for the words of a list).
pub fn pick<T: Copy>(options: &[(&str, T)], given: &str) -> Result<T, String> {
    if let Some(&(_, value)) = options.iter().find(|(name, _)| *name == given) {
        return Ok(value);
    }
    let names: Vec<String> = options
        .iter()
        .map(|(name, _)| format!("\"{name}\""))
        .collect();
    let listed = match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    };
    Err(format!("expected {listed}, got \"{given}\""))
}
