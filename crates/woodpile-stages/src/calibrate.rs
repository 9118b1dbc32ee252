//! `kind = "calibrate"`: a physical scene's keys fitted to a measured trace
//! (`woodpile_calibrate`). The trace is a CSV or parquet file of the project with columns `t`
//! (s after the impact), `rod` (paper site) and `velocity` (m/s), and optionally `sigma` (each
//! row's standard deviation, m/s, which weights it). Each parameter is a scene key by its
//! dotted name with its box; every simulation of the fit runs the one step `auto` verifies on
//! the starting scene, and the fitted scene is then run by `auto` and must agree
//! (docs/calibration.md).
//!
//! ```toml
//! kind = "calibrate"
//! trace = "pipeline/experiment/trace_synthetic.csv"
//! scene = "scenes/my_chain.toml"          # an SI scene (with [physical])
//! [parameters]
//! "damping.contact" = { min = 100.0, max = 20000.0, start = 3000.0 }
//! "defect[0].quality_factor" = { min = 2.0, max = 500.0 }
//! ```
//!
//! Output: the trace's rows with `fitted` (m/s) and `residual` (measured minus fitted) beside
//! them; the summary lists each estimate with its standard error and 95% interval, the RMS,
//! the method and step, and the verification. A fit that does not converge, or whose step
//! `auto` does not confirm, stops the stage: no numbers are written.

use serde_json::json;
use woodpile_calibrate::{calibrate, Calibration, Parameter, Trace};
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Kind};
use woodpile_pipeline::table::{f64_column, Columns};
use woodpile_pipeline::Output;

/// A parsed calibrate stage.
#[derive(Debug, Clone)]
pub struct Calibrate {
    /// The trace file, relative to the project, and the blake3 digest of its bytes when the
    /// stage was loaded.
    pub trace: (String, String),
    /// The scene table.
    pub scene: toml::Table,
    /// The keys to fit.
    pub parameters: Vec<Parameter>,
}

impl Calibrate {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Calibrate> {
        let trace: toml::Table = fields.required("trace")?;
        let text = |key: &str| trace.get(key).and_then(|v| v.as_str()).map(String::from);
        let (Some(file), Some(digest)) = (text("file"), text("blake3")) else {
            return Err(fields.error("trace", "expected the path of a data file"));
        };
        let scene: toml::Table = fields.required("scene")?;
        let table: toml::Table = fields.required("parameters")?;
        let mut parameters = Vec::new();
        for (key, value) in table {
            let field = format!("parameters.\"{key}\"");
            let bounds = value.as_table().ok_or_else(|| {
                fields.error(&field, "expected { min, max } or { min, max, start }")
            })?;
            let number = |name: &str| {
                let value = bounds.get(name)?;
                value
                    .as_float()
                    .or_else(|| value.as_integer().map(|i| i as f64))
            };
            let (Some(min), Some(max)) = (number("min"), number("max")) else {
                return Err(fields.error(&field, "expected { min, max } (numbers)"));
            };
            let parameter = Parameter {
                key,
                min,
                max,
                start: number("start"),
            };
            parameter
                .check()
                .map_err(|reason| fields.error(&field, reason))?;
            parameters.push(parameter);
        }
        if parameters.is_empty() {
            return Err(fields.error("parameters", "name at least one key to fit"));
        }
        Ok(Calibrate {
            trace: (file, digest),
            scene,
            parameters,
        })
    }

    /// The trace, read from the project and checked against the digest the stage was keyed by.
    fn read_trace(&self, ctx: &Context<'_>) -> Result<Trace> {
        let (file, digest) = &self.trace;
        let path = woodpile_files::layout::contained(ctx.root, file)
            .map_err(|reason| PipelineError::stage(ctx.name(), format!("trace: {reason}")))?;
        let bytes = std::fs::read(&path).map_err(|e| PipelineError::io(&path, e.to_string()))?;
        if blake3::hash(&bytes).to_hex().as_str() != digest {
            return Err(PipelineError::stage(
                ctx.name(),
                format!(
                    "trace: {} changed since the pipeline was loaded",
                    path.display()
                ),
            ));
        }
        let frame = match path.extension().and_then(|e| e.to_str()) {
            Some("parquet") => parquet_frame(&bytes),
            _ => csv_frame(&bytes),
        }
        .map_err(|reason| PipelineError::stage(ctx.name(), format!("trace {file}: {reason}")))?;
        trace_of(&frame)
            .map_err(|reason| PipelineError::stage(ctx.name(), format!("trace {file}: {reason}")))
    }
}

impl Kind for Calibrate {
    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let trace = self.read_trace(ctx)?;
        let stage = ctx.name();
        let fit = calibrate(
            &self.scene,
            &ctx.stage.file,
            &trace,
            &self.parameters,
            &|| false,
        )
        .map_err(|reason| PipelineError::stage(stage, reason))?;
        if !fit.verification.passed {
            let v = fit.verification;
            return Err(PipelineError::stage(
                stage,
                format!(
                    "the fitted scene run by auto differs from the fit's step by {:.3e} m/s, more than the {:.3e} allowed: the fit's step was too coarse for it",
                    v.max_difference, v.allowed
                ),
            ));
        }
        Ok(Output::table(frame(&trace, &fit)?, summary(&fit)).with_simulated(fit.simulations))
    }
}

/// The trace's rows with the fit beside them.
fn frame(trace: &Trace, fit: &Calibration) -> Result<polars::prelude::DataFrame> {
    let some = |v: &[f64]| v.iter().map(|x| Some(*x)).collect::<Vec<_>>();
    let mut columns = Columns::new();
    columns
        .f64("t", some(&trace.t))
        .i64("rod", trace.rod.iter().map(|r| Some(*r)).collect())
        .f64("velocity", some(&trace.velocity))
        .f64("fitted", some(&fit.fitted))
        .f64("residual", some(&fit.residuals));
    columns.into_frame()
}

/// The manifest's summary: the estimates, the residuals' size, the step and its check.
fn summary(fit: &Calibration) -> serde_json::Value {
    let estimates: Vec<serde_json::Value> = fit
        .estimates
        .iter()
        .map(|e| {
            json!({"key": e.key, "value": e.value, "std_error": e.std_error,
                   "low": e.low, "high": e.high, "at_bound": e.at_bound})
        })
        .collect();
    json!({
        "estimates": estimates,
        "rms": fit.rms,
        "method": fit.method,
        "dt_s": fit.dt_s,
        "iterations": fit.iterations,
        "simulations": fit.simulations,
        "verification": {
            "max_difference": fit.verification.max_difference,
            "allowed": fit.verification.allowed,
        },
        "scene": fit.scene.to_string(),
        "column_units": {"t": "s", "velocity": "m/s", "fitted": "m/s", "residual": "m/s"},
    })
}

/// The columns of a trace table.
fn trace_of(frame: &polars::prelude::DataFrame) -> std::result::Result<Trace, String> {
    let column = |name: &str| -> std::result::Result<Vec<f64>, String> {
        let values = f64_column(frame, name).map_err(|e| e.to_string())?;
        values
            .iter()
            .enumerate()
            .map(|(i, v)| v.ok_or_else(|| format!("column `{name}` is empty at row {i}")))
            .collect()
    };
    let sigma = match frame.column("sigma") {
        Ok(_) => Some(column("sigma")?),
        Err(_) => None,
    };
    let rods = column("rod")?;
    if let Some(i) = rods.iter().position(|r| r.fract() != 0.0) {
        return Err(format!(
            "column `rod` at row {i} is {}: rods are whole paper sites",
            rods[i]
        ));
    }
    Ok(Trace {
        t: column("t")?,
        rod: rods.iter().map(|&r| r as i64).collect(),
        velocity: column("velocity")?,
        sigma,
    })
}

fn parquet_frame(bytes: &[u8]) -> std::result::Result<polars::prelude::DataFrame, String> {
    use polars::prelude::{ParquetReader, SerReader};
    ParquetReader::new(std::io::Cursor::new(bytes))
        .finish()
        .map_err(|e| e.to_string())
}

/// A CSV of numbers: a header of names, then rows of as many numbers, comma-separated (`#`
/// lines are comments).
fn csv_frame(bytes: &[u8]) -> std::result::Result<polars::prelude::DataFrame, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not UTF-8 text".to_string())?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or("no header line")?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut values: Vec<Vec<Option<f64>>> = vec![Vec::new(); names.len()];
    for (n, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(format!(
                "line {}: {} values for {} columns",
                n + 1,
                cells.len(),
                names.len()
            ));
        }
        for (column, cell) in values.iter_mut().zip(cells) {
            let x: f64 = cell
                .parse()
                .map_err(|_| format!("line {}: `{cell}` is not a number", n + 1))?;
            column.push(Some(x));
        }
    }
    let mut columns = Columns::new();
    for (name, column) in names.iter().zip(values) {
        columns.f64(name, column);
    }
    columns.into_frame().map_err(|e| e.to_string())
}
