//! `kind = "spectrum"`: one table of a scene's linear picture about its static state (a
//! precompression): the Bloch bands of its host cell, the complex wavenumber in their gaps, its
//! normal modes (damped ones too), their shapes, or the transmission of its defect region
//! between uniform leads; or `measured`, that transmission measured from the scene's own
//! nonlinear run (its impulse, recorded at a probe past the region) beside the linear one.
//! Frequencies are in Hz for a `[physical]` scene (cycles per unit time
//! otherwise); docs/spectrum.md has the equations and conventions. The scene may be a grid
//! (`[axes]` and placeholders, as a sweep's): each point's rows then carry `point` and the axes.
//!
//! ```toml
//! kind = "spectrum"
//! table = "transmission"   # bands | wavenumber | modes | damped | shapes | transmission | measured
//! # cell = [0, 1]          # the host cell, paper sites (default: found)
//! # frequencies = { min = "1 kHz", max = "20 kHz", points = 400 }   # transmission, measured
//! # probe = 40             # measured only: the probe site past the region
//! # frequency_unit = "kHz" # a physical scene's `frequency` column in Hz (default), kHz or MHz
//! [scene]
//! chain = { n = 50, precompression = 1.0 }
//! defect = [{ site = 0, eps = 0.5, kappa = 0.3 }]
//! ```
//!
//! Output: the table's columns (docs/spectrum.md), after `point` and the axes when the scene
//! has axes. A scene without a static load, a cell that does not repeat, or a frequency range
//! outside the leads' band stops the stage, naming the key.

use crate::grid::AxisValue;
use serde_json::json;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{no_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::Columns;
use woodpile_pipeline::Output;
use woodpile_scene::units_out::SCALED;
use woodpile_spectrum::measured::{check, measure};
use woodpile_spectrum::scene::{scene_spectrum, Asked, Frequency, Refusal, SceneRequest};
use woodpile_spectrum::tables::{summary, table, Column, Part, Values};

use crate::sweep::Sweep;

/// A parsed spectrum stage.
#[derive(Debug, Clone)]
pub struct Spectrum {
    /// The scenes.
    pub sweep: Sweep,
    /// Which table.
    pub part: Part,
    /// What is asked beyond the defaults.
    pub request: SceneRequest,
    /// For `table = "measured"`: the probe (paper site), or the default.
    pub probe: Option<i64>,
    /// `frequency_unit` of a physical scene's table: its name and how many Hz it is.
    pub unit: Option<(String, f64)>,
}

/// The frequency units a physical scene's table may be given in.
const UNITS: [(&str, f64); 3] = [("Hz", 1.0), ("kHz", 1e3), ("MHz", 1e6)];

impl Spectrum {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Spectrum> {
        let name: String = fields.required("table")?;
        let part = Part::parse(&name).map_err(|reason| fields.error("table", reason))?;
        let cell = match fields.take("cell") {
            None => None,
            Some(value) => {
                let pair: Option<Vec<i64>> = value
                    .as_array()
                    .map(|a| a.iter().filter_map(|x| x.as_integer()).collect());
                match pair.as_deref() {
                    Some(&[lo, hi]) if lo <= hi => Some([lo, hi]),
                    _ => {
                        return Err(
                            fields.error("cell", "expected [lo, hi] paper sites with lo <= hi")
                        )
                    }
                }
            }
        };
        let frequencies = match fields.optional::<toml::Table>("frequencies")? {
            None => None,
            Some(table) => Some(frequency_range(fields.nested("frequencies", table))?),
        };
        let probe = fields.optional::<i64>("probe")?;
        if probe.is_some() && part != Part::Measured {
            return Err(fields.error("probe", "is read only with table = \"measured\""));
        }
        let unit = match fields.optional::<String>("frequency_unit")? {
            None => None,
            Some(name) => {
                let Some(&(_, hz)) = UNITS.iter().find(|(n, _)| *n == name) else {
                    return Err(
                        fields.error("frequency_unit", "expected \"Hz\", \"kHz\" or \"MHz\"")
                    );
                };
                Some((name, hz))
            }
        };
        let sweep = Sweep::parse(fields)?;
        if unit.is_some() && sweep.scene_at(0)?.physical.is_none() {
            return Err(fields.error(
                "frequency_unit",
                "needs a [physical] scene: a scaled scene's frequencies are cycles per unit time",
            ));
        }
        let stage = Spectrum {
            sweep,
            part,
            request: SceneRequest { cell, frequencies },
            probe,
            unit,
        };
        // Refuse a bad request now (status, dry runs), not when the stage runs: the grid's
        // corners exercise the extremes of every axis.
        for point in [0, stage.sweep.count() - 1] {
            let scene = stage.sweep.scene_at(point)?;
            let spectrum =
                scene_spectrum(&scene, &stage.request).map_err(|r| refusal(fields, r))?;
            if part == Part::Measured {
                check(&scene, &spectrum, probe).map_err(|r| refusal(fields, r))?;
            }
        }
        Ok(stage)
    }

    /// Every point's table, one after another.
    fn compute(&self, ctx: &Context<'_>) -> Result<Output> {
        let stage = ctx.name();
        let mut rows: Vec<(Vec<AxisValue>, Vec<Column>)> = Vec::new();
        let mut summaries = Vec::new();
        for point in 0..self.sweep.count() {
            let scene = self.sweep.scene_at(point)?;
            let failed =
                |r: Refusal| PipelineError::stage(stage, format!("point {point}: {}", r.reason));
            let mut spectrum = scene_spectrum(&scene, &self.request).map_err(failed)?;
            if self.part == Part::Measured {
                spectrum.measured =
                    Some(measure(&scene, &spectrum, self.probe, &|| false).map_err(failed)?);
            }
            let columns = table(&spectrum, self.part).map_err(|reason| {
                PipelineError::stage(
                    stage,
                    format!("point {point}: no `{}` table: {reason}", self.part.name()),
                )
            })?;
            summaries.push(summary(&spectrum));
            rows.push((self.sweep.values(point), self.in_unit(columns)));
        }
        let unit = self.unit.as_ref().map(|(name, _)| name.as_str());
        // What a figure may call the frequency axis: the stage's unit, Hz, or the model's own.
        let physical = summaries.first().is_some_and(|p| p["units"] == "SI");
        let column_unit = match (unit, physical) {
            (Some(name), _) => name,
            (None, true) => "Hz",
            (None, false) => SCALED,
        };
        Ok(Output::table(
            self.frame(rows)?,
            json!({
                "table": self.part.name(),
                "frequency_unit": unit,
                "column_units": { "frequency": column_unit },
                "points": summaries,
            }),
        ))
    }

    /// The `frequency` column in the stage's `frequency_unit`.
    fn in_unit(&self, mut columns: Vec<Column>) -> Vec<Column> {
        let Some((_, hz)) = self.unit else {
            return columns;
        };
        for column in columns.iter_mut().filter(|c| c.name == "frequency") {
            if let Values::F64(values) = &mut column.values {
                values.iter_mut().for_each(|f| *f /= hz);
            }
        }
        columns
    }

    /// The points' tables stacked, each row after its point and axis values when there are
    /// axes.
    fn frame(
        &self,
        points: Vec<(Vec<AxisValue>, Vec<Column>)>,
    ) -> Result<polars::prelude::DataFrame> {
        let axes = &self.sweep.grid.axes;
        let mut out: Vec<Column> = Vec::new();
        let mut prefix: Vec<Vec<f64>> = vec![Vec::new(); axes.len() + 1];
        for (point, (values, columns)) in points.into_iter().enumerate() {
            let height = columns.first().map_or(0, |c| len(&c.values));
            prefix[0].extend(std::iter::repeat_n(point as f64, height));
            for (column, value) in prefix[1..].iter_mut().zip(&values) {
                column.extend(std::iter::repeat_n(value.as_f64(), height));
            }
            match out.is_empty() {
                true => out = columns,
                false => out.iter_mut().zip(columns).for_each(|(a, b)| append(a, b)),
            }
        }
        let mut frame = Columns::new();
        if !axes.is_empty() {
            frame.i64("point", prefix[0].iter().map(|&p| Some(p as i64)).collect());
            for (axis, values) in axes.iter().zip(&prefix[1..]) {
                match axis.is_integer() {
                    true => frame.i64(&axis.name, values.iter().map(|&v| Some(v as i64)).collect()),
                    false => frame.f64(&axis.name, values.iter().map(|&v| Some(v)).collect()),
                };
            }
        }
        for column in out {
            push(&mut frame, column);
        }
        frame.into_frame()
    }
}

/// `frequencies = { min, max, points }`: each end a number or text with a unit.
fn frequency_range(mut f: Fields<'_>) -> Result<(Frequency, Frequency, usize)> {
    let mut end = |key: &str| -> Result<Frequency> {
        match f.take(key) {
            Some(toml::Value::Float(x)) => Ok(Frequency::Number(x)),
            Some(toml::Value::Integer(x)) => Ok(Frequency::Number(x as f64)),
            Some(toml::Value::String(text)) => Ok(Frequency::Text(text)),
            Some(_) => Err(f.error(key, "expected a number, or text such as \"2 kHz\"")),
            None => Err(f.error(key, "is required")),
        }
    };
    let (min, max) = (end("min")?, end("max")?);
    let points = f.optional::<i64>("points")?.unwrap_or(400);
    if points < 1 {
        return Err(f.error("points", "must be at least 1"));
    }
    f.finish()?;
    Ok((min, max, points as usize))
}

/// A refusal as the stage file's error, naming the key it is about.
fn refusal(fields: &Fields<'_>, r: Refusal) -> PipelineError {
    match r.asked {
        Asked::Scene => fields.error("scene", r.reason),
        Asked::Cell => fields.error("cell", r.reason),
        Asked::Frequencies => fields.error("frequencies", r.reason),
        Asked::Probe => fields.error("probe", r.reason),
        Asked::Sampling => fields.error("scene.run.sample_every", r.reason),
        Asked::Window => fields.error("scene.run.t_end", r.reason),
        Asked::Run => fields.error("scene", r.reason),
    }
}

fn len(values: &Values) -> usize {
    match values {
        Values::F64(v) => v.len(),
        Values::I64(v) => v.len(),
    }
}

/// Appends `b`'s values to `a` (the same column of another point).
fn append(a: &mut Column, b: Column) {
    match (&mut a.values, b.values) {
        (Values::F64(x), Values::F64(y)) => x.extend(y),
        (Values::I64(x), Values::I64(y)) => x.extend(y),
        // A part's columns have one type each, whatever the point: never reached.
        (Values::F64(_), Values::I64(_)) | (Values::I64(_), Values::F64(_)) => {}
    }
}

/// Appends `column` to a table under construction.
fn push(frame: &mut Columns, column: Column) {
    match column.values {
        Values::F64(v) => frame.f64(column.name, v.into_iter().map(Some).collect()),
        Values::I64(v) => frame.i64(column.name, v.into_iter().map(Some).collect()),
    };
}

/// The table of `columns` alone (what `woodpile spectrum --out` writes).
pub fn frame_of(columns: Vec<Column>) -> Result<polars::prelude::DataFrame> {
    let mut frame = Columns::new();
    for column in columns {
        push(&mut frame, column);
    }
    frame.into_frame()
}

impl Kind for Spectrum {
    fn check_inputs(&self, stage: &Stage, _inputs: &Inputs<'_>) -> KindCheck {
        no_inputs(stage)
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.compute(ctx)
    }
}
