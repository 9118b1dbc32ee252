//! The text a figure shows, from the names its table keeps: every title and label through the
//! stage's `labels` and the markup of `woodpile_plot::markup`, a curve's legend through its
//! `series_style` label, and a robust colour scale stated in its colour bar's label. Runs after
//! the plotted numbers are taken, so the table keeps the names and only the drawing changes.

use woodpile_plot::Panel;

use super::spec::{PanelSpec, Plot, ZRange};
use super::style::Labels;

/// The share of |z| a robust colour scale spans.
const ROBUST_QUANTILE: f64 = 0.99;

/// Sets the robust colour range of every map whose spec asks for one (`z_range = "robust"`,
/// the default of diverging maps): symmetric, to the 99th percentile of |z| of its panel.
pub(super) fn robust_ranges(panels: &mut [Panel], specs: &[&PanelSpec]) {
    for (panel, spec) in panels.iter_mut().zip(specs) {
        if let (
            Panel::Heat(h),
            Plot::Heatmap {
                z_range: ZRange::Robust,
                ..
            },
        ) = (panel, &spec.plot)
        {
            let mut magnitudes: Vec<f64> =
                h.z.iter()
                    .flatten()
                    .filter(|v| v.is_finite())
                    .map(|v| v.abs())
                    .collect();
            if magnitudes.is_empty() {
                continue;
            }
            magnitudes.sort_by(f64::total_cmp);
            let k = ((magnitudes.len() - 1) as f64 * ROBUST_QUANTILE).round() as usize;
            let m = magnitudes[k];
            if m > 0.0 {
                h.z_range = Some((-m, m));
            }
        }
    }
}

/// Rewrites `panel`'s texts as drawn.
pub(super) fn show(panel: &mut Panel, spec: &PanelSpec, labels: &Labels) -> Result<(), String> {
    let marks = match panel {
        Panel::Lines(p) => {
            p.title = labels.show(&p.title)?;
            p.x_label = labels.show(&p.x_label)?;
            p.y_label = labels.show(&p.y_label)?;
            let styles = match &spec.plot {
                Plot::Lines { styles, .. } => styles.as_slice(),
                Plot::Heatmap { .. } => &[],
            };
            for s in &mut p.series {
                s.label = match styles
                    .iter()
                    .find(|c| c.name == s.label)
                    .and_then(|c| c.label.as_ref())
                {
                    Some(label) => woodpile_plot::markup(label)?,
                    None => labels.show(&s.label)?,
                };
            }
            &mut p.marks
        }
        Panel::Heat(h) => {
            h.title = labels.show(&h.title)?;
            h.x_label = labels.show(&h.x_label)?;
            h.y_label = labels.show(&h.y_label)?;
            h.z_label = labels.show(&h.z_label)?;
            if matches!(
                spec.plot,
                Plot::Heatmap {
                    z_range: ZRange::Robust,
                    ..
                }
            ) {
                h.z_label.push_str(" (scale: 99th percentile of |value|)");
            }
            for o in &mut h.overlays {
                o.label = labels.show(&o.label)?;
            }
            &mut h.marks
        }
    };
    for m in marks {
        m.label = labels.show(&m.label)?;
    }
    Ok(())
}
