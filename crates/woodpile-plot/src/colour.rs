//! Colour maps. Viridis for magnitudes (perceptually uniform, readable in grey and by
//! colour-blind readers), a blue-white-red diverging map for signed values (white is zero),
//! and distinct named colours for categories.

use plotters::style::RGBColor;

const ANCHORS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Matplotlib's RdBu reversed: dark blue (most negative) through white (zero) to dark red.
const DIVERGING: [(u8, u8, u8); 7] = [
    (5, 48, 97),
    (67, 147, 195),
    (209, 229, 240),
    (247, 247, 247),
    (253, 219, 199),
    (214, 96, 77),
    (103, 0, 31),
];

/// Line colours (matplotlib's tab10, which prints and projects well). Its grey is left out:
/// it is too close to the grey of missing values.
pub const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colours for categories, the palette's in the order green, orange, red, blue, purple, brown:
/// three classes such as "meets", "misses", "unstable" read as go, caution, stop.
pub const CATEGORIES: [RGBColor; 6] = [
    PALETTE[2], PALETTE[3], PALETTE[1], PALETTE[0], PALETTE[4], PALETTE[5],
];

/// The viridis colour at `t` in [0, 1] (clamped).
pub fn viridis(t: f64) -> RGBColor {
    interpolate(&ANCHORS, t)
}

/// The diverging colour at `t` in [0, 1] (clamped); 0.5 is white.
pub fn diverging(t: f64) -> RGBColor {
    interpolate(&DIVERGING, t)
}

fn interpolate(anchors: &[(u8, u8, u8)], t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (anchors.len() - 1) as f64;
    let i = (x.floor() as usize).min(anchors.len() - 2);
    let f = x - i as f64;
    let (a, b) = (anchors[i], anchors[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + (q as f64 - p as f64) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_clamping() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        assert_eq!(diverging(0.5), RGBColor(247, 247, 247));
        assert_eq!(diverging(0.0), RGBColor(5, 48, 97));
    }
}
