//! Headless figures: panels of line plots and heat maps with colour bars, drawn by plotters to
//! PNG and SVG with an embedded DejaVu Sans (registered once), so text renders identically on
//! every machine without system font libraries. Each file is written to a temporary name and
//! renamed into place: a figure is complete or absent.
//!
//! This crate knows nothing about simulations or parquet: it draws the numbers it is given.
#![warn(missing_docs)]

mod colour;
mod draw;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;

pub use colour::viridis;
pub use draw::cell_edges;

/// Drawing failed.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct PlotError {
    /// The figure file.
    pub path: PathBuf,
    /// What went wrong.
    pub reason: String,
}

/// One curve of a line panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points in drawing order; a non-finite y breaks the line.
    pub points: Vec<(f64, f64)>,
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
    pub series: Vec<Series>,
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
    /// Values, row-major by y: `z[j * xs.len() + i]` at (xs[i], ys[j]); `None` is drawn grey.
    pub z: Vec<Option<f64>>,
    /// A marked point (e.g. the maximum) and its label.
    pub marker: Option<(f64, f64, String)>,
    /// Lines drawn over the map (e.g. a stability bound), each with a legend entry.
    pub overlays: Vec<Series>,
}

/// A panel of either kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// Line plot.
    Lines(LinePanel),
    /// Heat map.
    Heat(HeatPanel),
}

/// A figure: a title over a grid of panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Overall title.
    pub title: String,
    /// Panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
    /// Size of one panel in pixels.
    pub panel_size: (u32, u32),
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
    /// Total size in pixels.
    pub fn size(&self) -> (u32, u32) {
        let columns = self.columns.max(1) as u32;
        let rows = self.panels.len().div_ceil(self.columns.max(1)) as u32;
        (
            self.panel_size.0 * columns,
            self.panel_size.1 * rows.max(1) + draw::TITLE_HEIGHT,
        )
    }

    /// Writes `png` and `svg`, each atomically.
    pub fn render(&self, png: &Path, svg: &Path) -> Result<(), PlotError> {
        fn err(path: &Path) -> impl Fn(String) -> PlotError + '_ {
            move |reason| PlotError {
                path: path.to_path_buf(),
                reason,
            }
        }
        register_font().map_err(err(png))?;
        for path in [png, svg] {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir).map_err(|e| err(path)(e.to_string()))?;
            }
        }
        let size = self.size();
        let tmp_png = temp_path(png);
        let drawn = (|| {
            let root = BitMapBackend::new(&tmp_png, size).into_drawing_area();
            draw::figure(&root, self)?;
            root.present().map_err(|e| e.to_string())
        })();
        finish(drawn, &tmp_png, png).map_err(err(png))?;
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
            draw::figure(&root, self).map_err(err(svg))?;
            root.present().map_err(|e| err(svg)(e.to_string()))?;
        }
        let tmp_svg = temp_path(svg);
        let written = std::fs::write(&tmp_svg, text).map_err(|e| e.to_string());
        finish(written, &tmp_svg, svg).map_err(err(svg))
    }
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // The extension stays last: the PNG encoder picks the format from it.
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp.{ext}", std::process::id()))
}

fn finish(result: Result<(), String>, tmp: &Path, path: &Path) -> Result<(), String> {
    match result.and_then(|()| std::fs::rename(tmp, path).map_err(|e| e.to_string())) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(tmp);
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_png_and_svg_with_text() {
        let dir = tempfile::tempdir().unwrap();
        let figure = Figure {
            title: "test".into(),
            columns: 2,
            panel_size: (400, 300),
            panels: vec![
                Panel::Lines(LinePanel {
                    title: "L = 0".into(),
                    x_label: "ε".into(),
                    y_label: "fraction".into(),
                    series: vec![Series {
                        label: "E_tr".into(),
                        points: vec![(0.0, 0.1), (1.0, 0.3), (2.0, f64::NAN), (3.0, 0.2)],
                    }],
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
                    overlays: vec![Series {
                        label: "bound".into(),
                        points: vec![(1.5, 0.5), (1.5, 3.5)],
                    }],
                }),
            ],
        };
        let (png, svg) = (dir.path().join("f.png"), dir.path().join("f.svg"));
        figure.render(&png, &svg).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<svg") && text.contains("E_tr") && text.contains("test"));
        assert!(text.contains("bound"), "the overlay has a legend entry");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            2,
            "no temporaries left"
        );
    }
}
