//! Numbers as the report writes them, in its tables and in its measurements' messages.

/// Four significant digits, without exponent for the magnitudes a report shows.
pub(super) fn fmt(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if !(-4..=7).contains(&magnitude) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - magnitude).clamp(0, 8) as usize;
    format!("{x:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::fmt;

    #[test]
    fn four_significant_digits() {
        assert_eq!(fmt(0.21116587), "0.2112");
        assert_eq!(fmt(3961000.0), "3961000");
        assert_eq!(fmt(-0.0110), "-0.01100");
        assert_eq!(fmt(124.0), "124.0");
        assert_eq!(fmt(1.5e-9), "1.500e-9");
    }
}
