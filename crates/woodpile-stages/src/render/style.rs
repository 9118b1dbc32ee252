//! A render stage's `[style]` (printed size, type, legends, panel conventions) and its
//! `labels` (how names are written in a figure), parsed once. Project-wide values go in the
//! stage folder's `defaults.toml` under `[render.style]` and `[render.labels]`; a stage's own
//! keys override them.

use std::collections::hash_map::DefaultHasher;
use std::collections::{BTreeMap, HashMap};
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex, OnceLock, Weak};

use woodpile_pipeline::error::Result;
use woodpile_pipeline::fields::Fields;
use woodpile_plot::{markup, Legend, Style};

use super::spec::flag;

/// Printed width of a figure of one panel, and of more: a journal's single column and page.
const SINGLE_COLUMN_MM: f64 = 86.0;
const FULL_PAGE_MM: f64 = 178.0;
/// Room for the figure's title, in millimetres, above the panels' rows.
const TITLE_MM: f64 = 9.0;
/// Most pixels a figure may have (a 500 mm square at 360 DPI): bounds the raster's memory.
const MAX_PIXELS: f64 = 5e7;

/// The `[style]` keys, before the number of panels is known: the printed size, unless given,
/// follows from the panels (86 mm for one, 178 mm for more; the height from `aspect`, a
/// panel's height over its width, 0.72 for lines and 0.8 for maps).
#[derive(Debug, Clone, PartialEq)]
pub struct StyleSpec {
    /// `width_mm`, if given.
    pub width_mm: Option<f64>,
    /// `height_mm`, if given.
    pub height_mm: Option<f64>,
    /// `aspect`, if given.
    pub aspect: Option<f64>,
    /// Everything else: `dpi` (300), `font_pt` (8), `legend` ("best"), `panel_letters`,
    /// `minor_grid`, `share_x`, `share_y` (off); `StyleSpec::resolve` sets its size.
    pub rest: Style,
}

impl StyleSpec {
    /// The optional `[style]` table of `fields`.
    pub(super) fn parse(fields: &mut Fields<'_>) -> Result<StyleSpec> {
        let table = fields.optional::<toml::Table>("style")?.unwrap_or_default();
        let mut f = fields.nested("style", table);
        let bounded = |f: &mut Fields<'_>, key: &str, lo: f64, hi: f64| -> Result<Option<f64>> {
            match f.optional::<f64>(key)? {
                Some(v) if !(lo..=hi).contains(&v) => {
                    Err(f.error(key, format!("expected a number from {lo} to {hi}, got {v}")))
                }
                v => Ok(v),
            }
        };
        let width_mm = bounded(&mut f, "width_mm", 20.0, 500.0)?;
        let height_mm = bounded(&mut f, "height_mm", 20.0, 500.0)?;
        let aspect = bounded(&mut f, "aspect", 0.2, 3.0)?;
        if height_mm.is_some() && aspect.is_some() {
            return Err(f.error("aspect", "give `height_mm` or `aspect`, not both"));
        }
        let dpi = bounded(&mut f, "dpi", 50.0, 1200.0)?.unwrap_or(300.0);
        let font_pt = bounded(&mut f, "font_pt", 4.0, 24.0)?.unwrap_or(8.0);
        let legend = f.choice("legend", &Legend::OPTIONS, Some(Legend::Best))?;
        let spec = StyleSpec {
            width_mm,
            height_mm,
            aspect,
            rest: Style {
                dpi,
                font_pt,
                legend,
                panel_letters: flag(&mut f, "panel_letters")?,
                minor_grid: flag(&mut f, "minor_grid")?,
                share_x: flag(&mut f, "share_x")?,
                share_y: flag(&mut f, "share_y")?,
                ..Style::default()
            },
        };
        let (w, h) = (
            spec.width_mm.unwrap_or(FULL_PAGE_MM),
            spec.height_mm.unwrap_or(500.0),
        );
        if (w * dpi / 25.4) * (h.min(3.0 * w) * dpi / 25.4) > MAX_PIXELS {
            return Err(f.error(
                "dpi",
                format!("{dpi} DPI makes the figure more than {MAX_PIXELS:e} pixels"),
            ));
        }
        f.finish()?;
        Ok(spec)
    }

    /// The style of a figure of `panels` panels, `columns` per row, of maps or of lines.
    pub(super) fn resolve(&self, panels: usize, columns: usize, maps: bool) -> Style {
        let columns = columns.clamp(1, panels.max(1));
        let rows = panels.div_ceil(columns).max(1);
        let width_mm = self.width_mm.unwrap_or(if panels <= 1 {
            SINGLE_COLUMN_MM
        } else {
            FULL_PAGE_MM
        });
        let aspect = self.aspect.unwrap_or(if maps { 0.8 } else { 0.72 });
        let height_mm = self
            .height_mm
            .unwrap_or(TITLE_MM + rows as f64 * aspect * width_mm / columns as f64)
            .min(3.0 * width_mm);
        Style {
            width_mm,
            height_mm,
            ..self.rest.clone()
        }
    }
}

/// `labels = { E_tr = "E_{tr}", eps = "\\varepsilon" }`: how a name (a curve's column, a
/// colour bar's label) is written in the figure, in the markup of [`woodpile_plot::markup`].
/// The stage's table keeps the names; only the drawing shows the labels. Most stages take
/// theirs from `defaults.toml` alone, so equal label sets are held once ([`shared`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Labels(Arc<BTreeMap<String, String>>);

/// `labels`, or an equal set already held by another stage: thousands of render stages
/// under a large `[render.labels]` would otherwise each keep a copy.
fn shared(labels: BTreeMap<String, String>) -> Arc<BTreeMap<String, String>> {
    type Pool = Mutex<HashMap<u64, Vec<Weak<BTreeMap<String, String>>>>>;
    static POOL: OnceLock<Pool> = OnceLock::new();
    let mut hasher = DefaultHasher::new();
    labels.hash(&mut hasher);
    let hash = hasher.finish();
    let mut pool = POOL
        .get_or_init(Pool::default)
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let held = pool.entry(hash).or_default();
    held.retain(|weak| weak.strong_count() > 0);
    if let Some(same) = held
        .iter()
        .filter_map(Weak::upgrade)
        .find(|h| **h == labels)
    {
        return same;
    }
    let labels = Arc::new(labels);
    held.push(Arc::downgrade(&labels));
    labels
}

impl Labels {
    pub(super) fn parse(fields: &mut Fields<'_>) -> Result<Labels> {
        let table = fields
            .optional::<toml::Table>("labels")?
            .unwrap_or_default();
        let mut f = fields.nested("labels", table);
        let mut labels = BTreeMap::new();
        for key in f.keys() {
            let text: String = f.required(&key)?;
            let drawn = markup(&text).map_err(|reason| f.error(&key, reason))?;
            labels.insert(key, drawn);
        }
        f.finish()?;
        Ok(Labels(shared(labels)))
    }

    /// `text` as drawn: its label if it has one, else its own markup rendered.
    pub(super) fn show(&self, text: &str) -> std::result::Result<String, String> {
        match self.0.get(text) {
            Some(label) => Ok(label.clone()),
            None => markup(text),
        }
    }
}
