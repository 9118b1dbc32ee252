//! `kind = "reduce"`: read a sweep's fractions at one time, one row per point, or the best
//! point of each group.
//!
//! ```toml
//! kind = "reduce"
//! inputs = ["f4_sweep"]      # exactly one sweep
//! at = 150.0                 # read-out time (a sample time of the sweep); default: t_end
//! [maximize]                 # optional: keep, per value of the other axes, the point where
//! column = "E_tr"            #   this column (E_tr, R or T) is largest
//! over = ["eps"]             #   searching over these axes
//! ```
//!
//! Over a sweep of `[physical]` scenes `at` may carry a unit, `at = "0.5 ms"` (s, ms, us or
//! µs, ns). Over a sweep with `units = "SI"` it is read in each point's own seconds, and a bare
//! number is refused; over a scaled sweep it is converted with the sweep's time scale, which
//! all its points must share (an axis over the impact velocity or the masses moves it: read
//! such a sweep in SI, or in scaled time).
//!
//! Because sweeps keep time series, changing `at` re-runs this stage only, never a simulation.

use serde_json::json;

use crate::grid::Axis;
use crate::schema::{sweep, Fraction};
use crate::sweep::Sweep;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{wrong_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{f64_column, rows_frame, str_column, Cell, Row};
use woodpile_pipeline::Output;
use woodpile_scene::units_out::Units;
use woodpile_sim::{Share, ShareSet};

/// A parsed reduce stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Reduce {
    /// Read-out time; `None` means each point's last sample.
    pub at: Option<f64>,
    /// A read-out time with a unit (`at = "0.5 ms"`), in seconds: converted with the input
    /// sweep's time scale when the stage runs (its points must share one).
    pub at_seconds: Option<f64>,
    /// Optional maximisation.
    pub maximize: Option<Maximize>,
}

/// Keep the best point per group.
#[derive(Debug, Clone, PartialEq)]
pub struct Maximize {
    /// The fraction maximised.
    pub column: Fraction,
    /// The axes searched; the others form the groups.
    pub over: Vec<String>,
}

impl Reduce {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Reduce> {
        let (at, at_seconds) = match fields.take("at") {
            None => (None, None),
            Some(toml::Value::String(text)) => {
                let seconds =
                    woodpile_scene::seconds(&text).map_err(|reason| fields.error("at", reason))?;
                (None, Some(seconds))
            }
            Some(value) => {
                let t = value
                    .as_float()
                    .or_else(|| value.as_integer().map(|i| i as f64))
                    .ok_or_else(|| {
                        fields.error(
                            "at",
                            "expected a time: a number (scaled) or text such as \"0.5 ms\"",
                        )
                    })?;
                (Some(t), None)
            }
        };
        if at.or(at_seconds).is_some_and(|t| t < 0.0) {
            return Err(fields.error("at", "the read-out time must be >= 0"));
        }
        let maximize = match fields.optional::<toml::Table>("maximize")? {
            None => None,
            Some(table) => {
                let mut m = fields.nested("maximize", table);
                let column = m.choice("column", &Fraction::OPTIONS, Some(Fraction::Trapped))?;
                let over: Vec<String> = m.required("over")?;
                if over.is_empty() {
                    return Err(m.error("over", "name at least one axis"));
                }
                m.finish()?;
                Some(Maximize { column, over })
            }
        };
        Ok(Reduce {
            at,
            at_seconds,
            maximize,
        })
    }

    /// Checks the names in `maximize.over` against the input sweep's axes.
    pub(crate) fn check_axes(&self, axes: &[Axis]) -> Result<(), String> {
        for name in self.maximize.iter().flat_map(|m| &m.over) {
            if !axes.iter().any(|a| &a.name == name) {
                let known: Vec<&str> = axes.iter().map(|a| a.name.as_str()).collect();
                return Err(format!(
                    "`{name}` is not an axis of the input (axes: {known:?})"
                ));
            }
        }
        Ok(())
    }

    /// Reduces the sweep table `input`, whose grid axes are `axes`.
    pub(crate) fn compute(
        &self,
        stage: &str,
        input: &polars::prelude::DataFrame,
        (axes, at): (&[Axis], Option<f64>),
    ) -> Result<Output> {
        let sweep = SweepRows::read(input, axes)?;
        let picks = sweep
            .read_out(at)
            .map_err(|r| PipelineError::stage(stage, r))?;
        let rows: Vec<Pick> = match &self.maximize {
            None => picks,
            Some(m) => maximize(&picks, axes, m),
        };
        let shares = sweep.shares();
        let reduced: Vec<Reduced> = rows
            .iter()
            .map(|pick| Reduced { axes, pick, shares })
            .collect();
        let failed: usize = rows.iter().map(|p| p.failed).sum();
        Ok(Output::table(
            rows_frame(&reduced)?,
            json!({"rows": rows.len(), "failed_points": failed, "at": at}),
        ))
    }
}

impl Reduce {
    /// The read-out time in the units of `sweep`'s table: seconds as given for an SI table
    /// (each point's samples are at its own seconds), converted to the scaled time of a
    /// scaled one; a bare number is scaled time, which an SI table does not have.
    fn read_at(&self, input: &str, sweep: &Sweep) -> std::result::Result<Option<f64>, String> {
        match (self.at, self.at_seconds, sweep.units()) {
            (Some(_), _, Units::Si) => Err(format!(
                "`{input}` is in SI (units = \"SI\"), so a bare number has no meaning: give the time with a unit, such as \"0.5 ms\""
            )),
            (at, None, _) => Ok(at),
            (_, Some(seconds), Units::Si) => Ok(Some(seconds)),
            (_, Some(seconds), Units::Scaled) => scaled_at(seconds, sweep).map(Some),
        }
    }
}

/// `seconds` in the sweep's scaled time: every point of a physical sweep must share one time
/// scale (an axis that moves the impact velocity or the masses moves it, and each point's
/// samples are then at other seconds: read such a sweep at a scaled time).
fn scaled_at(seconds: f64, sweep: &Sweep) -> std::result::Result<f64, String> {
    let mut scale: Option<f64> = None;
    for point in 0..sweep.count() {
        let scene = sweep.scene_at(point).map_err(|e| e.to_string())?;
        let Some(physical) = scene.physical else {
            return Err("a time with a unit needs a sweep of [physical] scenes; give a number in scaled time".into());
        };
        let here = physical.scales.time_s();
        match scale {
            Some(s) if s != here => {
                return Err(format!(
                    "the sweep's points have different time scales ({s:e} s and {here:e} s at point {point}): give `at` in scaled time"
                ))
            }
            _ => scale = Some(here),
        }
    }
    let scale = scale.ok_or("the sweep has no points")?;
    Ok(seconds / scale)
}

/// An output row: a point (or the best of a group) read out at the time.
struct Reduced<'a> {
    axes: &'a [Axis],
    pick: &'a Pick,
    /// The input's shares (S and D where it has them).
    shares: ShareSet,
}

impl Row for Reduced<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let p = self.pick;
        let mut cells: Vec<(&str, Cell)> = self
            .axes
            .iter()
            .zip(&p.axes)
            .map(|(axis, &v)| {
                let cell = match axis.is_integer() {
                    true => Cell::from(v as i64),
                    false => Cell::from(v),
                };
                (axis.name.as_str(), cell)
            })
            .collect();
        let at = |f: fn(&Sample) -> f64| p.row.as_ref().map(f);
        cells.push((sweep::TIME, at(|r| r.t).into()));
        for share in self.shares.iter() {
            cells.push((share.name(), p.row.and_then(|r| r.share(share)).into()));
        }
        cells.extend([
            (sweep::ENERGY, at(|r| r.e).into()),
            (
                sweep::ERROR_ESTIMATE,
                p.row.and_then(|r| r.error_estimate).into(),
            ),
            ("points", Cell::from(p.points as i64)),
            ("failed", Cell::from(p.failed as i64)),
            (sweep::FAILURE, p.failure.clone().into()),
        ]);
        cells
    }
}

/// One sample row of a sweep.
#[derive(Debug, Clone, Copy)]
struct Sample {
    t: f64,
    r: f64,
    tr: f64,
    e_tr: f64,
    /// The striker's share S, where the sweep has one.
    s: Option<f64>,
    /// The dissipated share D, where the sweep has one.
    d: Option<f64>,
    e: f64,
    error_estimate: Option<f64>,
}

impl Sample {
    /// `share`'s value (`None` for S or D where the sweep has none).
    fn share(&self, share: Share) -> Option<f64> {
        match share {
            Share::Reflected => Some(self.r),
            Share::Transmitted => Some(self.tr),
            Share::Trapped => Some(self.e_tr),
            Share::Striker => self.s,
            Share::Dissipated => self.d,
        }
    }
}

/// The chosen row of a point (or of a group, after maximisation).
#[derive(Debug, Clone)]
struct Pick {
    axes: Vec<f64>,
    row: Option<Sample>,
    points: usize,
    failed: usize,
    failure: Option<String>,
}

/// A sweep table as columns.
struct SweepRows {
    point: Vec<Option<f64>>,
    axes: Vec<Vec<Option<f64>>>,
    t: Vec<Option<f64>>,
    r: Vec<Option<f64>>,
    tr: Vec<Option<f64>>,
    e_tr: Vec<Option<f64>>,
    /// S and D, for the sweeps that have them.
    s: Option<Vec<Option<f64>>>,
    d: Option<Vec<Option<f64>>>,
    e: Vec<Option<f64>>,
    error_estimate: Vec<Option<f64>>,
    failure: Vec<Option<String>>,
}

impl SweepRows {
    fn read(frame: &polars::prelude::DataFrame, axes: &[Axis]) -> Result<Self> {
        Ok(Self {
            point: f64_column(frame, sweep::POINT)?,
            axes: axes
                .iter()
                .map(|a| f64_column(frame, &a.name))
                .collect::<Result<_>>()?,
            t: f64_column(frame, sweep::TIME)?,
            r: f64_column(frame, Fraction::Reflected.column())?,
            tr: f64_column(frame, Fraction::Transmitted.column())?,
            e_tr: f64_column(frame, Fraction::Trapped.column())?,
            s: optional_column(frame, sweep::STRIKER)?,
            d: optional_column(frame, sweep::DISSIPATED)?,
            e: f64_column(frame, sweep::ENERGY)?,
            error_estimate: f64_column(frame, sweep::ERROR_ESTIMATE)?,
            failure: str_column(frame, sweep::FAILURE)?,
        })
    }

    /// Whether the table has S and D.
    /// The shares the table has: S and D where their columns are.
    fn shares(&self) -> ShareSet {
        ShareSet {
            striker: self.s.is_some(),
            dissipative: self.d.is_some(),
        }
    }

    fn row(&self, i: usize) -> Option<Sample> {
        Some(Sample {
            t: self.t[i]?,
            r: self.r[i]?,
            tr: self.tr[i]?,
            e_tr: self.e_tr[i]?,
            s: self.s.as_ref().and_then(|c| c[i]),
            d: self.d.as_ref().and_then(|c| c[i]),
            e: self.e[i]?,
            error_estimate: self.error_estimate[i],
        })
    }

    /// One pick per point: the sample at `at` (or the last one).
    fn read_out(&self, at: Option<f64>) -> std::result::Result<Vec<Pick>, String> {
        let mut picks = Vec::new();
        let mut start = 0;
        while start < self.point.len() {
            let mut end = start + 1;
            while end < self.point.len() && self.point[end] == self.point[start] {
                end += 1;
            }
            let axes: Vec<f64> = self
                .axes
                .iter()
                .map(|c| c[start].unwrap_or(f64::NAN))
                .collect();
            let pick = if let Some(reason) = &self.failure[start] {
                Pick {
                    axes,
                    row: None,
                    points: 1,
                    failed: 1,
                    failure: Some(reason.clone()),
                }
            } else {
                // A sample within a billionth of the time or of the sampling interval: the
                // same test in scaled units (intervals near 1) and in seconds (near 1e-6).
                let interval = match (self.t[start], self.t.get(start + 1).copied().flatten()) {
                    (Some(first), Some(second)) if end > start + 1 => (second - first).abs(),
                    _ => 1.0,
                };
                let chosen = match at {
                    None => Some(end - 1),
                    Some(t) => (start..end).find(|&i| {
                        self.t[i].is_some_and(|s| (s - t).abs() <= 1e-9 * t.abs().max(interval))
                    }),
                };
                let Some(i) = chosen else {
                    let (first, last) = (self.t[start], self.t[end - 1]);
                    return Err(format!(
                        "read-out time at = {} is not a sample time of the input (samples from {} to {}): pick a multiple of the sweep's run.sample_every",
                        at.unwrap_or_default(),
                        first.unwrap_or(f64::NAN),
                        last.unwrap_or(f64::NAN)
                    ));
                };
                Pick {
                    axes,
                    row: self.row(i),
                    points: 1,
                    failed: 0,
                    failure: None,
                }
            };
            picks.push(pick);
            start = end;
        }
        Ok(picks)
    }
}

/// A float column the sweep table has only for some scenes (S, D), or `None`.
fn optional_column(
    frame: &polars::prelude::DataFrame,
    name: &str,
) -> Result<Option<Vec<Option<f64>>>> {
    match frame.column(name) {
        Ok(_) => Ok(Some(f64_column(frame, name)?)),
        Err(_) => Ok(None),
    }
}

/// The best pick per group (groups in order of first appearance, i.e. grid order).
fn maximize(picks: &[Pick], axes: &[Axis], m: &Maximize) -> Vec<Pick> {
    let grouping: Vec<usize> = (0..axes.len())
        .filter(|&k| !m.over.contains(&axes[k].name))
        .collect();
    let group_of = |p: &Pick| {
        grouping
            .iter()
            .map(|&k| p.axes[k].to_bits())
            .collect::<Vec<u64>>()
    };
    let value = |p: &Pick| p.row.map(|r| m.column.of(r.r, r.tr, r.e_tr));
    let mut order: Vec<Vec<u64>> = Vec::new();
    let mut best: std::collections::HashMap<Vec<u64>, Pick> = std::collections::HashMap::new();
    for p in picks {
        let g = group_of(p);
        match best.get_mut(&g) {
            None => {
                order.push(g.clone());
                best.insert(g, p.clone());
            }
            Some(b) => {
                let (points, failed) = (b.points + 1, b.failed + p.failed);
                // Strictly greater: ties keep the first point in grid order.
                if value(p).is_some_and(|v| value(b).is_none_or(|w| v > w)) {
                    *b = p.clone();
                }
                b.points = points;
                b.failed = failed;
                if b.row.is_some() {
                    b.failure = None;
                }
            }
        }
    }
    order.into_iter().filter_map(|g| best.remove(&g)).collect()
}

impl Kind for Reduce {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        let [input] = stage.inputs.as_slice() else {
            return wrong_inputs("a reduce stage reads exactly one sweep");
        };
        match inputs.get::<Sweep>(input) {
            Some(sweep) => self
                .check_axes(&sweep.grid.axes)
                .map_err(|reason| ("maximize.over".to_string(), reason)),
            None => Err((
                "inputs[0]".into(),
                format!(
                    "`{input}` is a {} stage; a reduce reads a sweep",
                    inputs.kind_of(input)
                ),
            )),
        }
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let input = &ctx.stage.inputs[0];
        let frame = ctx.input(input)?;
        let upstream = ctx.upstream(input)?;
        let sweep = upstream
            .get::<Sweep>()
            .ok_or_else(|| PipelineError::stage(ctx.name(), format!("`{input}` is not a sweep")))?;
        let at = self
            .read_at(input, sweep)
            .map_err(|reason| PipelineError::stage(ctx.name(), format!("at: {reason}")))?;
        let mut output = self.compute(ctx.name(), &frame, (&sweep.grid.axes, at))?;
        // The sweep's scene, grid and tolerance, so the table explains itself without its input.
        let params = upstream.params.value();
        output.summary["input"] = json!({
            "stage": input,
            "scene": params.get("scene"),
            "axes": params.get("axes"),
            "tolerance": params.pointer("/scene/run/tolerance"),
        });
        Ok(output)
    }
}
