//! A figure's printed size and typography, and where its legends go. Every length the drawing
//! uses is derived from these, so a figure set at 178 mm and 8 pt prints with 8-pt text at
//! whatever DPI its PNG is rendered.

/// The printed size, resolution and type size of a figure, and its panel conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct Style {
    /// Printed width in millimetres (a journal's full page: about 178; one column: about 86).
    pub width_mm: f64,
    /// Printed height in millimetres.
    pub height_mm: f64,
    /// Pixels per inch of the PNG (the SVG is vector; its size is stated in mm).
    pub dpi: f64,
    /// Size of tick labels, axis labels and legends in points; titles are a little larger.
    pub font_pt: f64,
    /// Where each panel's legend goes.
    pub legend: Legend,
    /// Letter the panels (a), (b), (c) in their top-left corner.
    pub panel_letters: bool,
    /// Draw a light minor grid between the ticks.
    pub minor_grid: bool,
    /// One x range for every panel of a kind (lines, or heat maps).
    pub share_x: bool,
    /// One y range for every panel of a kind.
    pub share_y: bool,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            width_mm: 178.0,
            height_mm: 120.0,
            dpi: 300.0,
            font_pt: 8.0,
            legend: Legend::Best,
            panel_letters: false,
            minor_grid: false,
            share_x: false,
            share_y: false,
        }
    }
}

impl Style {
    /// The figure's size in pixels at its DPI.
    pub fn pixels(&self) -> (u32, u32) {
        let px = |mm: f64| self.mm(mm).round().max(1.0) as u32;
        (px(self.width_mm), px(self.height_mm))
    }

    /// Pixels in `mm` millimetres.
    pub(crate) fn mm(&self, mm: f64) -> f64 {
        mm * self.dpi / 25.4
    }

    /// Pixels in `pt` points.
    pub(crate) fn pt(&self, pt: f64) -> f64 {
        pt * self.dpi / 72.0
    }

    /// The font size in pixels of text `scale` times the base size.
    pub(crate) fn font(&self, scale: f64) -> f64 {
        self.pt(self.font_pt * scale)
    }

    /// A line width of `pt` points in whole pixels (at least one).
    pub(crate) fn stroke(&self, pt: f64) -> u32 {
        self.pt(pt).round().max(1.0) as u32
    }
}

/// Where a panel's legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Legend {
    /// The inside corner that covers no plotted point; outside on the right when none is free.
    Best,
    /// Inside the axes, at this place.
    Inside(Corner),
    /// To the right of the axes.
    OutsideRight,
    /// Under the axes.
    Below,
    /// No legend.
    None,
}

/// A place inside the axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    /// Top left.
    UpperLeft,
    /// Top, centred.
    UpperCenter,
    /// Top right.
    UpperRight,
    /// Bottom left.
    LowerLeft,
    /// Bottom, centred.
    LowerCenter,
    /// Bottom right.
    LowerRight,
    /// Middle of the left side.
    CenterLeft,
    /// Middle of the right side.
    CenterRight,
}

impl Corner {
    /// The places `Legend::Best` tries, in order of preference.
    pub(crate) const TRIED: [Corner; 8] = [
        Corner::UpperRight,
        Corner::UpperLeft,
        Corner::LowerRight,
        Corner::LowerLeft,
        Corner::UpperCenter,
        Corner::LowerCenter,
        Corner::CenterRight,
        Corner::CenterLeft,
    ];
}

impl Legend {
    /// Every placement under its stage-file name: the one table names are read from.
    pub const OPTIONS: [(&'static str, Legend); 12] = [
        ("best", Legend::Best),
        ("upper left", Legend::Inside(Corner::UpperLeft)),
        ("upper center", Legend::Inside(Corner::UpperCenter)),
        ("upper right", Legend::Inside(Corner::UpperRight)),
        ("lower left", Legend::Inside(Corner::LowerLeft)),
        ("lower center", Legend::Inside(Corner::LowerCenter)),
        ("lower right", Legend::Inside(Corner::LowerRight)),
        ("center left", Legend::Inside(Corner::CenterLeft)),
        ("center right", Legend::Inside(Corner::CenterRight)),
        ("outside right", Legend::OutsideRight),
        ("below", Legend::Below),
        ("none", Legend::None),
    ];

    /// The placement called `name` in [`Legend::OPTIONS`].
    pub fn named(name: &str) -> Option<Legend> {
        crate::colour::named_in(&Legend::OPTIONS, name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_follow_from_millimetres_points_and_dpi() {
        let style = Style::default();
        assert_eq!(style.pixels(), (2102, 1417));
        assert!((style.pt(72.0) - 300.0).abs() < 1e-12);
        assert_eq!(Legend::named("below"), Some(Legend::Below));
        assert_eq!(
            Legend::named("lower right"),
            Some(Legend::Inside(Corner::LowerRight))
        );
        assert_eq!(Legend::named("top"), None);
    }
}
