//! Headless figures: panels of line plots and heat maps with colour bars, drawn by plotters to
//! PNG and SVG with an embedded DejaVu Sans (registered once), so text renders identically on
//! every machine without system font libraries. A figure comes out as bytes: whoever stores it
//! decides where, and how to make the write atomic.
//!
//! This crate knows nothing about simulations or parquet: it draws the numbers it is given.
#![warn(missing_docs)]

mod axis;
mod chart;
mod colour;
mod draw;
mod grid;
mod heat;
mod legend;
mod markup;
mod panel;
mod style;

use std::sync::OnceLock;

use plotters::prelude::*;

pub use axis::tick;
pub use axis::Scale;
pub use colour::{diverging, hex_colour, viridis, Dash, Marker, SeriesStyle};
pub use grid::Grid;
pub use heat::cell_edges;
pub use markup::markup;
pub use style::{Corner, Legend, Style};

/// Drawing failed.
#[derive(Debug, thiserror::Error)]
#[error("drawing the {format}: {reason}")]
pub struct PlotError {
    /// `png` or `svg`.
    pub format: &'static str,
    /// What went wrong.
    pub reason: String,
}

/// One curve of a line panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// Legend label.
    pub label: String,
    /// Points in drawing order; a non-finite y breaks the line.
    pub points: Vec<(f64, f64)>,
    /// Colour, dash and marker; unset ones follow the curve's place in its panel.
    pub style: SeriesStyle,
}

/// One line-plot panel.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePanel {
    /// Panel title (e.g. `L = 2`).
    pub title: String,
    /// x-axis label, with units.
    pub x_label: String,
    /// y-axis label, with units.
    pub y_label: String,
    /// The curves.
    pub series: Vec<Trace>,
    /// Straight lines marking a position.
    pub marks: Vec<Mark>,
    /// The visible ranges.
    pub view: View,
}

/// One heat-map panel on a rectangular grid.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatPanel {
    /// Panel title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Colour-bar label.
    pub z_label: String,
    /// Cell centres along x, increasing.
    pub xs: Vec<f64>,
    /// Cell centres along y, increasing.
    pub ys: Vec<f64>,
    /// Values, row-major by y: `z[j * xs.len() + i]` at `(xs[i], ys[j])`; `None` is drawn grey.
    pub z: Vec<Option<f64>>,
    /// A marked point (e.g. the maximum) and its label.
    pub marker: Option<(f64, f64, String)>,
    /// Lines drawn over the map (e.g. a stability bound), each with a legend entry.
    pub overlays: Vec<Trace>,
    /// How values become colours.
    pub colours: Colours,
    /// The value range the colours span; `None`: the data's own (symmetric about zero for
    /// [`Colours::Diverging`]). Two panels given one range share one colour scale.
    pub z_range: Option<(f64, f64)>,
    /// Straight lines marking a position (a defect's site, a switch-on time).
    pub marks: Vec<Mark>,
    /// The visible x and y ranges (a zoom); `None`: the whole grid.
    pub view: View,
}

impl HeatPanel {
    /// The smallest and largest finite value, or (inf, -inf) when there is none.
    pub fn value_range(&self) -> (f64, f64) {
        self.z
            .iter()
            .flatten()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), &v| {
                (l.min(v), u.max(v))
            })
    }
}

/// How a heat map colours its values.
#[derive(Debug, Clone, PartialEq)]
pub enum Colours {
    /// Viridis from the smallest to the largest value.
    Sequential,
    /// Blue through white (zero) to red, symmetric about zero: for signed values.
    Diverging,
    /// Value k (an integer) is category k, named by the k-th label, in a legend.
    Categories(Vec<String>),
}

/// A straight line across a panel at a fixed x or y, with a legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// Vertical (at an x) or horizontal (at a y).
    pub at: MarkAt,
    /// Legend label; marks with the same label share one entry.
    pub label: String,
}

/// Where a [`Mark`] is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MarkAt {
    /// A vertical line at this x.
    X(f64),
    /// A horizontal line at this y.
    Y(f64),
}

/// The visible ranges of a panel (`None` keeps the data's own) and how its axes scale.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct View {
    /// x from, to.
    pub x: Option<(f64, f64)>,
    /// y from, to.
    pub y: Option<(f64, f64)>,
    /// Linear or log x axis.
    pub x_scale: Scale,
    /// Linear or log y axis.
    pub y_scale: Scale,
}

/// A panel of either kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// Line plot.
    Lines(LinePanel),
    /// Heat map.
    Heat(HeatPanel),
}

impl Panel {
    /// The heat map, if this is one.
    pub fn as_heat(&self) -> Option<&HeatPanel> {
        match self {
            Panel::Heat(h) => Some(h),
            Panel::Lines(_) => None,
        }
    }

    /// The panel's title.
    pub fn title(&self) -> &str {
        match self {
            Panel::Lines(p) => &p.title,
            Panel::Heat(h) => &h.title,
        }
    }
}

/// A drawn figure: its PNG and SVG, and per panel how many plotted points its legend covers
/// (zero unless a stage forced the legend onto the data).
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// The PNG file's bytes.
    pub png: Vec<u8>,
    /// The SVG text, sized in millimetres.
    pub svg: String,
    /// Curve samples under each panel's legend box.
    pub legend_covers: Vec<usize>,
}

/// A figure: a title over a grid of panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Overall title.
    pub title: String,
    /// Panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row (at most the number of panels: a single panel fills the figure).
    pub columns: usize,
    /// Printed size, type and conventions.
    pub style: Style,
    /// One colour bar for the figure (its heat maps share one scale) instead of one per map.
    pub shared_colour_bar: bool,
}

fn register_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
            plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
                .map_err(|_| "the embedded font is invalid".to_string())
        })
        .clone()
}

impl Figure {
    /// Total size in pixels, from the style's millimetres and DPI.
    pub fn size(&self) -> (u32, u32) {
        self.style.pixels()
    }

    /// The figure as a PNG file's bytes. The caller writes them (atomically, under the name
    /// it chooses): this crate draws, it does not manage files.
    pub fn png(&self) -> Result<Vec<u8>, PlotError> {
        Ok(self.png_and_covers()?.0)
    }

    fn png_and_covers(&self) -> Result<(Vec<u8>, Vec<usize>), PlotError> {
        register_font().map_err(fail("png"))?;
        let (width, height) = self.size();
        let mut rgb = vec![0u8; width as usize * height as usize * 3];
        let covers;
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
            covers = draw::figure(&root, self).map_err(fail("png"))?;
            root.present().map_err(|e| fail("png")(e.to_string()))?;
        }
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        // The PNG states its resolution, so a layout program places it at its printed size.
        let per_metre = (self.style.dpi / 0.0254).round() as u32;
        encoder.set_pixel_dims(Some(png::PixelDimensions {
            xppu: per_metre,
            yppu: per_metre,
            unit: png::Unit::Meter,
        }));
        encoder
            .write_header()
            .and_then(|mut writer| writer.write_image_data(&rgb))
            .map_err(|e| fail("png")(e.to_string()))?;
        Ok((bytes, covers))
    }

    /// The figure as SVG text whose width and height are stated in millimetres, so LaTeX and
    /// Inkscape place it at its printed size.
    pub fn svg(&self) -> Result<String, PlotError> {
        register_font().map_err(fail("svg"))?;
        let mut text = String::new();
        let (width, height) = self.size();
        {
            let root = SVGBackend::with_string(&mut text, (width, height)).into_drawing_area();
            draw::figure(&root, self).map_err(fail("svg"))?;
            root.present().map_err(|e| fail("svg")(e.to_string()))?;
        }
        let pixels = format!("width=\"{width}\" height=\"{height}\"");
        let printed = format!(
            "width=\"{:.1}mm\" height=\"{:.1}mm\"",
            self.style.width_mm, self.style.height_mm
        );
        if !text.contains(&pixels) {
            return Err(fail("svg")(
                "the SVG header has no pixel size to restate".into(),
            ));
        }
        Ok(text.replacen(&pixels, &printed, 1))
    }

    /// PNG, SVG, and how much each legend covers.
    pub fn draw(&self) -> Result<Drawn, PlotError> {
        let (png, legend_covers) = self.png_and_covers()?;
        Ok(Drawn {
            png,
            svg: self.svg()?,
            legend_covers,
        })
    }
}

fn fail(format: &'static str) -> impl Fn(String) -> PlotError {
    move |reason| PlotError { format, reason }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_png_and_svg_with_text() {
        let figure = Figure {
            title: "test".into(),
            columns: 2,
            style: Style {
                width_mm: 120.0,
                height_mm: 80.0,
                dpi: 100.0,
                ..Style::default()
            },
            shared_colour_bar: false,
            panels: vec![
                Panel::Lines(LinePanel {
                    title: "L = 0".into(),
                    x_label: "ε".into(),
                    y_label: "fraction".into(),
                    series: vec![Trace {
                        label: "E_tr".into(),
                        points: vec![(0.0, 0.1), (1.0, 0.3), (2.0, f64::NAN), (3.0, 0.2)],
                        style: SeriesStyle::default(),
                    }],
                    marks: vec![Mark {
                        at: MarkAt::X(1.5),
                        label: "switch-on".into(),
                    }],
                    view: View::default(),
                }),
                Panel::Heat(HeatPanel {
                    title: "map".into(),
                    x_label: "ε₁".into(),
                    y_label: "ε₂".into(),
                    z_label: "E_tr".into(),
                    xs: vec![1.0, 2.0],
                    ys: vec![1.0, 2.0, 3.0],
                    z: vec![Some(0.1), Some(0.2), None, Some(0.4), Some(0.5), Some(0.6)],
                    marker: Some((2.0, 3.0, "max".into())),
                    overlays: vec![Trace {
                        label: "bound".into(),
                        points: vec![(1.5, 0.5), (1.5, 3.5)],
                        style: SeriesStyle::default(),
                    }],
                    colours: Colours::Diverging,
                    z_range: None,
                    marks: vec![Mark {
                        at: MarkAt::Y(2.0),
                        label: "defect".into(),
                    }],
                    view: View::default(),
                }),
                Panel::Heat(HeatPanel {
                    title: "classes".into(),
                    x_label: "dt".into(),
                    y_label: "p".into(),
                    z_label: "class".into(),
                    xs: vec![1.0, 2.0],
                    ys: vec![3.0, 5.0],
                    z: vec![Some(0.0), Some(1.0), Some(2.0), None],
                    marker: None,
                    overlays: vec![],
                    colours: Colours::Categories(vec![
                        "meets".into(),
                        "misses".into(),
                        "unstable".into(),
                    ]),
                    z_range: None,
                    marks: vec![],
                    view: View::default(),
                }),
            ],
        };
        let bytes = figure.png().unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        let text = figure.svg().unwrap();
        assert!(text.contains("<svg") && text.contains("E_tr") && text.contains("test"));
        assert!(
            text.contains(r#"width="120.0mm" height="80.0mm""#),
            "the SVG states its printed size"
        );
        assert!(text.contains("bound"), "the overlay has a legend entry");
        assert!(
            text.contains("switch-on") && text.contains("defect"),
            "marks have legends"
        );
        assert!(
            text.contains("unstable"),
            "categories are named in a legend"
        );
        assert!(text.contains("<image"), "heat maps are embedded rasters");
    }
}
