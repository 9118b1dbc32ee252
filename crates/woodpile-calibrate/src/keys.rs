//! Scene keys addressed by their dotted names, as docs/scene.md writes them
//! (`damping.contact`, `defect[0].quality_factor`, `chain.boundary.right.spring`).

/// One fitted key and its box.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Its dotted name.
    pub key: String,
    /// Least value.
    pub min: f64,
    /// Greatest value.
    pub max: f64,
    /// Where the fit starts; `None`: the scene's value, or the middle of the box.
    pub start: Option<f64>,
}

impl Parameter {
    /// Checks the box: finite, min < max, and a start inside it.
    pub fn check(&self) -> Result<(), String> {
        if !(self.min.is_finite() && self.max.is_finite() && self.min < self.max) {
            return Err(format!(
                "parameter `{}`: bounds [{}, {}] must be finite with min < max",
                self.key, self.min, self.max
            ));
        }
        match self.start {
            Some(s) if !(self.min..=self.max).contains(&s) => Err(format!(
                "parameter `{}`: start {s} lies outside [{}, {}]",
                self.key, self.min, self.max
            )),
            _ => Ok(()),
        }
    }
}

/// One step of a dotted name: a table key, and an array index after it if any.
fn steps(key: &str) -> Result<Vec<(&str, Option<usize>)>, String> {
    key.split('.')
        .map(|part| match part.split_once('[') {
            Some((name, rest)) => rest
                .strip_suffix(']')
                .and_then(|i| i.parse().ok())
                .map(|i| (name, Some(i)))
                .ok_or_else(|| format!("`{key}`: `{part}` is not name[index]")),
            None => Ok((part, None)),
        })
        .collect()
}

/// The numeric value at `key` in `scene`, if it has one there.
pub fn get(scene: &toml::Table, key: &str) -> Option<f64> {
    let mut value: Option<&toml::Value> = None;
    let mut table = scene;
    for (name, index) in steps(key).ok()? {
        let mut v = table.get(name)?;
        if let Some(i) = index {
            v = v.as_array()?.get(i)?;
        }
        if let Some(t) = v.as_table() {
            table = t;
        }
        value = Some(v);
    }
    value.and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
}

/// Sets `key` in `scene` to `value`, making the tables on its way (but not array elements:
/// `defect[2]` must exist).
pub fn set(scene: &mut toml::Table, key: &str, value: f64) -> Result<(), String> {
    let steps = steps(key)?;
    let last = steps.len() - 1;
    let mut table = scene;
    for (n, (name, index)) in steps.into_iter().enumerate() {
        if n == last && index.is_none() {
            table.insert(name.to_string(), toml::Value::Float(value));
            return Ok(());
        }
        let entry = table
            .entry(name.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let entry = match index {
            Some(i) => entry
                .as_array_mut()
                .and_then(|a| a.get_mut(i))
                .ok_or_else(|| format!("`{key}`: the scene has no `{name}[{i}]`"))?,
            None => entry,
        };
        table = entry
            .as_table_mut()
            .ok_or_else(|| format!("`{key}`: `{name}` is not a table"))?;
    }
    Err(format!("`{key}`: names a table, not a number"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_read_and_written_through_tables_and_arrays() {
        let mut scene: toml::Table =
            toml::from_str("[[defect]]\nsite = 0\nquality_factor = 40\n").unwrap();
        assert_eq!(get(&scene, "defect[0].quality_factor"), Some(40.0));
        set(&mut scene, "defect[0].quality_factor", 55.0).unwrap();
        set(&mut scene, "damping.contact", 0.5).unwrap();
        assert_eq!(get(&scene, "defect[0].quality_factor"), Some(55.0));
        assert_eq!(get(&scene, "damping.contact"), Some(0.5));
        assert!(set(&mut scene, "defect[3].eps", 1.0).is_err());
        assert!(set(&mut scene, "defect[x].eps", 1.0).is_err());
    }
}
