//! Colour maps. Viridis for magnitudes (perceptually uniform, readable in grey and by
//! colour-blind readers), a blue-white-red diverging map for signed values (white is zero),
//! and distinct named colours for categories.

use plotters::style::RGBColor;

/// Viridis at nine evenly spaced anchors, from dark purple to yellow.
#[rustfmt::skip]
const ANCHORS: [(u8, u8, u8); 9] = [
    (68, 1, 84), (71, 44, 122), (59, 81, 139),
    (44, 113, 142), (33, 144, 141), (39, 173, 129),
    (92, 200, 99), (170, 220, 50), (253, 231, 37),
];

/// Matplotlib's RdBu reversed: dark blue (most negative) through white (zero) to dark red.
#[rustfmt::skip]
const DIVERGING: [(u8, u8, u8); 7] = [
    (5, 48, 97), (67, 147, 195), (209, 229, 240), (247, 247, 247),
    (253, 219, 199), (214, 96, 77), (103, 0, 31),
];

/// Okabe and Ito's colours, told apart by red-green colour-blind readers.
const BLUE: RGBColor = RGBColor(0, 114, 178);
const VERMILLION: RGBColor = RGBColor(213, 94, 0);
const GREEN: RGBColor = RGBColor(0, 158, 115);
const ORANGE: RGBColor = RGBColor(230, 159, 0);
const PURPLE: RGBColor = RGBColor(204, 121, 167);
const SKY: RGBColor = RGBColor(86, 180, 233);
const YELLOW: RGBColor = RGBColor(240, 228, 66);

/// Line colours, in an order that starts with the pairs that differ most in grey. Yellow, too
/// light on white, is left out.
pub const PALETTE: [RGBColor; 7] = [
    BLUE,
    VERMILLION,
    GREEN,
    ORANGE,
    PURPLE,
    SKY,
    RGBColor(0, 0, 0),
];

/// Colours for categories: three classes such as "meets", "misses", "unstable" read as go,
/// caution, stop.
pub const CATEGORIES: [RGBColor; 6] = [GREEN, YELLOW, VERMILLION, BLUE, PURPLE, SKY];

/// How a curve is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dash {
    /// Unbroken.
    Solid,
    /// Long dashes.
    Dashed,
    /// Dots.
    Dotted,
    /// Dashes and dots.
    DashDot,
}

impl Dash {
    /// Every dash under its stage-file name: the one table names are read from.
    #[rustfmt::skip]
    pub const OPTIONS: [(&'static str, Dash); 4] = [
        ("solid", Dash::Solid), ("dashed", Dash::Dashed),
        ("dotted", Dash::Dotted), ("dashdot", Dash::DashDot),
    ];

    /// The on-off lengths in points (empty: solid).
    pub(crate) fn pattern(self) -> &'static [f64] {
        match self {
            Dash::Solid => &[],
            Dash::Dashed => &[4.0, 2.5],
            Dash::Dotted => &[1.0, 1.6],
            Dash::DashDot => &[4.0, 1.6, 1.0, 1.6],
        }
    }

    /// The dash called `name` in [`Dash::OPTIONS`].
    pub fn named(name: &str) -> Option<Dash> {
        named_in(&Dash::OPTIONS, name)
    }
}

/// The symbol drawn on a curve's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// No symbol.
    None,
    /// A filled circle.
    Circle,
    /// A filled square.
    Square,
    /// A filled triangle.
    Triangle,
    /// A filled diamond.
    Diamond,
    /// A cross.
    Cross,
}

impl Marker {
    /// Every marker under its stage-file name: the one table names are read from.
    #[rustfmt::skip]
    pub const OPTIONS: [(&'static str, Marker); 6] = [
        ("none", Marker::None), ("circle", Marker::Circle), ("square", Marker::Square),
        ("triangle", Marker::Triangle), ("diamond", Marker::Diamond), ("cross", Marker::Cross),
    ];

    /// The marker called `name` in [`Marker::OPTIONS`].
    pub fn named(name: &str) -> Option<Marker> {
        named_in(&Marker::OPTIONS, name)
    }
}

/// A curve's look; what is `None` follows the curve's place in its panel, so that every curve
/// differs from the others in colour, dash and marker and reads in greyscale.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SeriesStyle {
    /// Line colour.
    pub colour: Option<RGBColor>,
    /// Stroke pattern.
    pub dash: Option<Dash>,
    /// Point symbol.
    pub marker: Option<Marker>,
}

impl SeriesStyle {
    /// The look of the `k`-th curve of a panel: this style's choices, the defaults elsewhere.
    pub(crate) fn resolve(&self, k: usize) -> (RGBColor, Dash, Marker) {
        const DASHES: [Dash; 4] = [Dash::Solid, Dash::Dashed, Dash::Dotted, Dash::DashDot];
        const MARKERS: [Marker; 5] = [
            Marker::Circle,
            Marker::Square,
            Marker::Triangle,
            Marker::Diamond,
            Marker::Cross,
        ];
        (
            self.colour.unwrap_or(PALETTE[k % PALETTE.len()]),
            self.dash.unwrap_or(DASHES[k % DASHES.len()]),
            self.marker.unwrap_or(MARKERS[k % MARKERS.len()]),
        )
    }
}

/// The colour written `#rrggbb`.
pub fn hex_colour(text: &str) -> Option<RGBColor> {
    let hex = text.strip_prefix('#').filter(|h| h.len() == 6)?;
    let byte = |k: usize| u8::from_str_radix(hex.get(k..k + 2)?, 16).ok();
    Some(RGBColor(byte(0)?, byte(2)?, byte(4)?))
}

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

/// The value called `name` in a table of (name, value) options.
pub(crate) fn named_in<T: Copy>(options: &[(&str, T)], name: &str) -> Option<T> {
    options.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
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
        assert_eq!(hex_colour("#0072b2"), Some(RGBColor(0, 114, 178)));
        assert_eq!(hex_colour("0072b2"), None);
        assert_eq!(hex_colour("#00zz00"), None);
    }

    #[test]
    fn curves_differ_in_colour_dash_and_marker_by_default() {
        let looks: Vec<_> = (0..3).map(|k| SeriesStyle::default().resolve(k)).collect();
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            assert_ne!(looks[a].0, looks[b].0);
            assert_ne!(looks[a].1, looks[b].1);
            assert_ne!(looks[a].2, looks[b].2);
        }
        let chosen = SeriesStyle {
            dash: Some(Dash::Dotted),
            ..SeriesStyle::default()
        };
        assert_eq!(chosen.resolve(0).1, Dash::Dotted);
    }
}
