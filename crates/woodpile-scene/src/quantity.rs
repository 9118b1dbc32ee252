//! Quantities written with a unit, `"1.5 ms"`, `"2 kHz"`, `"1 m/s"`: the one table of the units a
//! scene, a stage or a figure label may name, what each measures and its size in SI, and the
//! one reader of such text. Scene times, restitution velocities, spectrum frequencies and the
//! units of figure axes all go through it.

/// A unit: its name, what it measures, and its size in the SI unit of that quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// As written (`"µs"`).
    pub name: &'static str,
    /// The quantity (`"time"`).
    pub measures: &'static str,
    /// Its size in SI (1e-6 for µs).
    pub size: f64,
}

const fn unit(name: &'static str, measures: &'static str, size: f64) -> Unit {
    Unit {
        name,
        measures,
        size,
    }
}

/// Every unit woodpile reads.
pub const UNITS: [Unit; 18] = [
    unit("s", "time", 1.0),
    unit("ms", "time", 1e-3),
    unit("us", "time", 1e-6),
    unit("µs", "time", 1e-6),
    unit("ns", "time", 1e-9),
    unit("m", "length", 1.0),
    unit("mm", "length", 1e-3),
    unit("µm", "length", 1e-6),
    unit("m/s", "velocity", 1.0),
    unit("cm/s", "velocity", 1e-2),
    unit("mm/s", "velocity", 1e-3),
    unit("J", "energy", 1.0),
    unit("mJ", "energy", 1e-3),
    unit("µJ", "energy", 1e-6),
    unit("nJ", "energy", 1e-9),
    unit("Hz", "frequency", 1.0),
    unit("kHz", "frequency", 1e3),
    unit("MHz", "frequency", 1e6),
];

/// The unit named `name`, if woodpile knows it.
pub fn named(name: &str) -> Option<Unit> {
    UNITS.into_iter().find(|u| u.name == name)
}

/// The value of `text`, a number and a unit of `measures` (`"1.5 ms"`, `"2us"`), in SI.
pub fn parse(text: &str, measures: &str) -> Result<f64, String> {
    let text = text.trim();
    let split = text
        .char_indices()
        .find(|&(_, c)| c.is_alphabetic() && c != 'e' && c != 'E')
        .map_or(text.len(), |(i, _)| i);
    let (number, name) = (text[..split].trim(), text[split..].trim());
    let names: Vec<&str> = UNITS
        .iter()
        .filter(|u| u.measures == measures)
        .map(|u| u.name)
        .collect();
    let Some(unit) = named(name).filter(|u| u.measures == measures) else {
        return Err(match name {
            "" => format!(
                "`{text}` has no unit: write a {measures} with one of {}",
                names.join(", ")
            ),
            _ => format!(
                "`{name}` is not a unit of {measures} ({})",
                names.join(", ")
            ),
        });
    };
    let value: f64 = number
        .parse()
        .map_err(|_| format!("`{text}`: `{number}` is not a number"))?;
    Ok(value * unit.size)
}

#[cfg(test)]
mod tests {
    use super::parse;

    #[test]
    fn quantities_are_read_in_every_unit() {
        let close = |text: &str, measures: &str, si: f64| {
            (parse(text, measures).unwrap() - si).abs() <= 1e-15 * si
        };
        assert!(close("1.5 ms", "time", 1.5e-3));
        assert!(close("2us", "time", 2e-6));
        assert!(close("40 µs", "time", 40e-6));
        assert!(close("3e2 ns", "time", 3e-7));
        assert!(close("0.25 s", "time", 0.25));
        assert!(close("20 mm/s", "velocity", 0.02));
        assert!(close("1e3 Hz", "frequency", 1e3));
        assert!(close("12.5 kHz", "frequency", 12.5e3));
        assert!(parse("1.5 kg", "time")
            .unwrap_err()
            .contains("not a unit of time"));
        assert!(parse("1.5 kHz", "time")
            .unwrap_err()
            .contains("not a unit of time"));
        assert!(parse("1.5", "time").unwrap_err().contains("no unit"));
        assert!(parse("1.2.3 ms", "time")
            .unwrap_err()
            .contains("not a number"));
    }
}
