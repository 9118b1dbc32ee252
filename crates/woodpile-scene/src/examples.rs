//! The example scenes of the repository's `scenes/` folder, compiled in, so that the binary and
//! the Python wheel carry them: a user without a clone can start from `woodpile example
//! single_eps10` or `woodpile.example("single_eps10")`.

/// Every example: its name (the file's stem) and its TOML text.
pub const EXAMPLES: [(&str, &str); 4] = [
    (
        "single_eps10",
        include_str!("../../../scenes/single_eps10.toml"),
    ),
    ("ramp_trap", include_str!("../../../scenes/ramp_trap.toml")),
    (
        "woodpile_experiment",
        include_str!("../../../scenes/woodpile_experiment.toml"),
    ),
    (
        "woodpile_striker",
        include_str!("../../../scenes/woodpile_striker.toml"),
    ),
];

/// The TOML text of the example `name`, or why there is none (naming the ones there are).
pub fn example(name: &str) -> Result<&'static str, String> {
    EXAMPLES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .ok_or_else(|| {
            format!(
                "no example `{name}`; the examples are {}",
                names().join(", ")
            )
        })
}

/// The examples' names, in order.
pub fn names() -> Vec<&'static str> {
    EXAMPLES.iter().map(|(name, _)| *name).collect()
}

/// What an example is: its opening comment up to the first colon, or full stop that ends a
/// sentence (a "Fig. 10" goes on).
pub fn summary(text: &str) -> String {
    let comment: Vec<&str> = text
        .lines()
        .map_while(|line| line.strip_prefix('#'))
        .map(str::trim)
        .collect();
    let joined = comment.join(" ");
    let bytes = joined.as_bytes();
    let ends_clause = |i: usize| {
        let spaced = bytes.get(i + 1).is_none_or(|&c| c == b' ');
        match bytes[i] {
            b':' => spaced,
            b'.' => spaced && !bytes.get(i + 2).is_some_and(u8::is_ascii_digit),
            _ => false,
        }
    };
    let end = (0..bytes.len())
        .find(|&i| ends_clause(i))
        .unwrap_or(joined.len());
    joined[..end].trim().to_string()
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    /// Every example is a valid scene, says what it is, and is the repository's file.
    #[test]
    fn every_example_loads_and_is_its_file() {
        for (name, text) in EXAMPLES {
            crate::parse(text, Path::new(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!summary(text).is_empty(), "{name}");
            let file = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../scenes")
                .join(format!("{name}.toml"));
            assert_eq!(std::fs::read_to_string(file).ok().as_deref(), Some(text));
        }
        let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let files = std::fs::read_dir(folder).map_or(0, |d| d.count());
        assert_eq!(
            files,
            EXAMPLES.len(),
            "every scene of scenes/ is an example"
        );
        assert!(example("nope").unwrap_err().contains("single_eps10"));
    }
}
