//! Linear and logarithmic axes. Data are drawn in "plot space" (the value, or its log10), so
//! one chart type serves both; the ticks are chosen here and labelled with the data's values.

/// How an axis maps values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Equal distances for equal differences.
    #[default]
    Linear,
    /// Equal distances for equal ratios; values at or below zero are not drawn.
    Log,
}

impl Scale {
    /// `v` in plot space: itself, or its log10 (NaN, a gap, for v <= 0).
    pub fn to_plot(self, v: f64) -> f64 {
        match self {
            Scale::Linear => v,
            Scale::Log if v > 0.0 => v.log10(),
            Scale::Log => f64::NAN,
        }
    }

    /// The value at plot-space position `u`.
    pub fn from_plot(self, u: f64) -> f64 {
        match self {
            Scale::Linear => u,
            Scale::Log => 10f64.powf(u),
        }
    }

    /// The label of the tick at plot-space position `u`.
    pub(crate) fn label(self, u: f64) -> String {
        match self {
            Scale::Linear => tick(&u),
            Scale::Log => {
                let v = 10f64.powf(u);
                let decade = u.round();
                if (u - decade).abs() < 1e-9 && !(-3.0..=4.0).contains(&decade) {
                    format!("10{}", superscript_integer(decade as i64))
                } else {
                    tick(&v)
                }
            }
        }
    }

    /// Major and minor tick positions in plot space over [lo, hi] (plot space), about
    /// `target` major ones.
    pub(crate) fn ticks(self, lo: f64, hi: f64, target: usize) -> (Vec<f64>, Vec<f64>) {
        match self {
            Scale::Linear => linear_ticks(lo, hi, target),
            Scale::Log => log_ticks(lo, hi, target),
        }
    }
}

fn superscript_integer(k: i64) -> String {
    k.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => "⁰¹²³⁴⁵⁶⁷⁸⁹"
                .chars()
                .nth(d.to_digit(10).unwrap_or(0) as usize)
                .unwrap_or('⁰'),
        })
        .collect()
}

/// Steps of 1, 2, 2.5 or 5 times a power of ten, about `target` of them; minor ticks at a
/// fifth (or a quarter, between steps of 2) of a step.
fn linear_ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, Vec<f64>) {
    if hi <= lo || !lo.is_finite() || !hi.is_finite() {
        return (vec![lo], Vec::new());
    }
    let rough = (hi - lo) / target.max(1) as f64;
    let power = 10f64.powf(rough.log10().floor());
    let (step, minor) = [(1.0, 5.0), (2.0, 4.0), (2.5, 5.0), (5.0, 5.0), (10.0, 5.0)]
        .into_iter()
        .find(|(m, _)| m * power >= rough)
        .map_or((10.0 * power, 5.0), |(m, minor)| (m * power, minor));
    let at = |step: f64| -> Vec<f64> {
        let first = (lo / step - 1e-9).ceil() as i64;
        let last = (hi / step + 1e-9).floor() as i64;
        (first..=last).map(|k| k as f64 * step).collect()
    };
    let major = at(step);
    let minor = at(step / minor)
        .into_iter()
        .filter(|m| !major.iter().any(|t| (t - m).abs() < 1e-9 * step))
        .collect();
    (major, minor)
}

/// Decades, with 2 and 5 between them when the axis spans fewer than two; minor ticks at 2..9
/// times each decade. An axis inside one decade falls back to linear steps of the values.
fn log_ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, Vec<f64>) {
    if hi <= lo || !lo.is_finite() || !hi.is_finite() {
        return (vec![lo], Vec::new());
    }
    let inside = |u: f64| u >= lo - 1e-9 && u <= hi + 1e-9;
    let decades: Vec<i64> = ((lo.floor() as i64)..=(hi.ceil() as i64)).collect();
    let with = |ms: &[f64]| -> Vec<f64> {
        decades
            .iter()
            .flat_map(|&k| ms.iter().map(move |m| m.log10() + k as f64))
            .filter(|&u| inside(u))
            .collect()
    };
    let stride = ((hi - lo) / target.max(1) as f64).ceil().max(1.0) as i64;
    let mut major: Vec<f64> = decades
        .iter()
        .filter(|&&k| k.rem_euclid(stride) == 0)
        .map(|&k| k as f64)
        .filter(|&u| inside(u))
        .collect();
    if hi - lo < 2.0 {
        major = with(&[1.0, 2.0, 5.0]);
    }
    if major.len() < 2 {
        let (lin, _) = linear_ticks(10f64.powf(lo), 10f64.powf(hi), target);
        major = lin
            .into_iter()
            .filter(|&v| v > 0.0)
            .map(f64::log10)
            .collect();
    }
    let minor = with(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
        .into_iter()
        .filter(|m| !major.iter().any(|t| (t - m).abs() < 1e-9))
        .collect();
    (major, minor)
}

/// A tick label: integers without a decimal point (`10`, not `10.0`), other values with at
/// most four significant decimals, and never `-0`.
pub fn tick(v: &f64) -> String {
    let v = if v.abs() < 1e-12 { 0.0 } else { *v };
    if (v - v.round()).abs() <= 1e-9 * v.abs().max(1.0) && v.abs() < 1e15 {
        return format!("{}", v.round() as i64);
    }
    let magnitude = v.abs().log10().floor();
    if !(-4.0..6.0).contains(&magnitude) {
        return format!("{v:.2e}");
    }
    let decimals = (3.0 - magnitude).clamp(0.0, 8.0) as usize;
    let text = format!("{v:.decimals$}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_round_numbers_inside_the_range() {
        let (major, _) = Scale::Linear.ticks(0.0, 0.5, 6);
        assert_eq!(major, vec![0.0, 0.1, 0.2, 0.30000000000000004, 0.4, 0.5]);
        let (major, minor) = Scale::Linear.ticks(3.0, 19.0, 6);
        assert_eq!(major, vec![5.0, 10.0, 15.0]);
        assert_eq!(minor.first(), Some(&3.0));
    }

    #[test]
    fn log_ticks_label_values_and_skip_what_is_not_positive() {
        let (lo, hi) = (Scale::Log.to_plot(0.1), Scale::Log.to_plot(5.0));
        let (major, minor) = Scale::Log.ticks(lo, hi, 6);
        let labels: Vec<String> = major.iter().map(|&u| Scale::Log.label(u)).collect();
        assert_eq!(labels, ["0.1", "0.2", "0.5", "1", "2", "5"]);
        assert!(minor.iter().all(|&u| u > lo && u < hi));
        assert!(Scale::Log.to_plot(0.0).is_nan());
        assert_eq!(Scale::Log.label(-6.0), "10⁻⁶");
        let (major, _) = Scale::Log.ticks(-8.0, 0.0, 6);
        assert_eq!(major, vec![-8.0, -6.0, -4.0, -2.0, 0.0]);
    }

    #[test]
    fn ticks_print_integers_as_integers_and_never_minus_zero() {
        assert_eq!(tick(&10.0), "10");
        assert_eq!(tick(&-0.0), "0");
        assert_eq!(tick(&-1e-17), "0");
        assert_eq!(tick(&0.25), "0.25");
        assert_eq!(tick(&(0.1 + 0.2)), "0.3");
        assert_eq!(tick(&-2.5), "-2.5");
        assert_eq!(tick(&1.5e-7), "1.50e-7");
    }
}
