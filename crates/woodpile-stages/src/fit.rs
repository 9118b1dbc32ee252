//! `kind = "fit"`: Levenberg–Marquardt fits of the paper's forms to columns of one table.
//!
//! ```toml
//! kind = "fit"
//! inputs = ["f4_fractions"]
//! x = "eps"
//! where = { L = 0 }                        # optional: keep rows where these columns equal these values (numbers or strings)
//! [[model]]
//! name = "T1"
//! y = "T"
//! form = "power"                           # A x^B + C, or "tanh": A tanh(B x) + C
//! start = [0.5, -0.05, 0.3]
//! paper = [0.5630, -0.0110, 0.3345]        # optional: the paper's coefficients, for comparison
//! x_range = [0.0, 1.0]                     # optional: fit only rows with lo <= x <= hi
//! ```
//!
//! One output row per model: A, B, C with standard errors, the relative error
//! ‖y − f‖/‖y‖, and, when given, the paper's coefficients and *their* relative error on our
//! data, so the two fits can be judged on the same numbers. A model that cannot be fitted keeps
//! its row with null coefficients and the reason in `failure`; the stage still writes its
//! table, and the run ends non-zero naming it.

use polars::prelude::DataFrame;
use serde_json::json;

use woodpile_analysis::lm::{fit, Fit, Form};
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::{Ends, Fields};
use woodpile_pipeline::kind::{wrong_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{f64_column, matching_rows, rows_frame, Cell, Match, Row};
use woodpile_pipeline::Output;

/// A parsed fit stage.
#[derive(Debug, Clone, PartialEq)]
pub struct FitStage {
    /// The x column.
    pub x: String,
    /// Row filter: column = value.
    pub filter: Vec<(String, Match)>,
    /// The models.
    pub models: Vec<Model>,
}

/// One fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Its name in the output.
    pub name: String,
    /// The y column.
    pub y: String,
    /// The form.
    pub form: Form,
    /// Starting A, B, C.
    pub start: [f64; 3],
    /// The paper's A, B, C.
    pub paper: Option<[f64; 3]>,
    /// Fit only rows with x in this inclusive range.
    pub x_range: Option<[f64; 2]>,
}

fn triple(fields: &Fields<'_>, key: &str, value: Option<toml::Value>) -> Result<Option<[f64; 3]>> {
    let Some(value) = value else { return Ok(None) };
    let numbers: Option<Vec<f64>> = value.as_array().map(|a| {
        a.iter()
            .filter_map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
            .collect()
    });
    match numbers.as_deref() {
        Some(&[a, b, c]) if value.as_array().is_some_and(|v| v.len() == 3) => Ok(Some([a, b, c])),
        _ => Err(fields.error(key, "expected three numbers [A, B, C]")),
    }
}

impl FitStage {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<FitStage> {
        let x: String = fields.required("x")?;
        let filter = fields.equality_filter("where")?;
        let raw = fields.take("model");
        let Some(toml::Value::Array(entries)) = raw else {
            return Err(fields.error("model", "expected one or more [[model]] tables"));
        };
        let mut models = Vec::new();
        for (i, entry) in entries.into_iter().enumerate() {
            let toml::Value::Table(table) = entry else {
                return Err(fields.error(&format!("model[{i}]"), "expected a table"));
            };
            let mut f = fields.nested(&format!("model[{i}]"), table);
            let name: String = f.required("name")?;
            let y: String = f.required("y")?;
            let form = f.choice("form", &Form::OPTIONS, None)?;
            let start = f.take("start");
            let start = triple(&f, "start", start)?
                .ok_or_else(|| f.error("start", "missing (expected [A, B, C])"))?;
            let paper = f.take("paper");
            let paper = triple(&f, "paper", paper)?;
            let x_range = f.interval("x_range", Ends::MayMeet)?;
            f.finish()?;
            models.push(Model {
                name,
                y,
                form,
                start,
                paper,
                x_range,
            });
        }
        if models.is_empty() {
            return Err(fields.error("model", "expected one or more [[model]] tables"));
        }
        Ok(FitStage { x, filter, models })
    }

    pub(crate) fn compute(&self, stage: &str, input: &DataFrame) -> Result<Output> {
        let fail = |reason: String| PipelineError::stage(stage, reason);
        let column = |name: &str| f64_column(input, name).map_err(|e| fail(e.to_string()));
        let keep = matching_rows(input, &self.filter)
            .map_err(|e| PipelineError::stage(stage, e.to_string()))?;
        let xs = column(&self.x)?;
        let mut out = Vec::with_capacity(self.models.len());
        let mut failures = Vec::new();
        for m in &self.models {
            let ys = column(&m.y)?;
            let (x, y): (Vec<f64>, Vec<f64>) = keep
                .iter()
                .filter_map(|&r| Some((xs[r]?, ys[r]?)))
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .filter(|(a, _)| m.x_range.is_none_or(|[lo, hi]| (lo..=hi).contains(a)))
                .unzip();
            let fitted = fit(m.form, &x, &y, m.start).map(|result| {
                let paper_error = m.paper.map(|p| {
                    let ssr: f64 = x
                        .iter()
                        .zip(&y)
                        .map(|(&a, &b)| (m.form.eval(p, a) - b).powi(2))
                        .sum();
                    ssr.sqrt() / y.iter().map(|v| v * v).sum::<f64>().sqrt()
                });
                let span = |pick: fn(f64, f64) -> f64| x.iter().copied().reduce(pick);
                Fitted {
                    fit: result,
                    x_range: (span(f64::min), span(f64::max)),
                    paper_error,
                }
            });
            // A fit that fails is a row with its reason, as a failed scene is.
            if let Err(reason) = &fitted {
                failures.push(format!("model `{}`: {reason}", m.name));
            }
            out.push(ModelRow {
                model: m,
                n: x.len(),
                fitted,
            });
        }
        let rows = out.len();
        let summary = json!({"models": rows, "rows_used": keep.len(), "failed": failures.len()});
        Ok(Output::table(rows_frame(&out)?, summary).with_failures(failures))
    }
}

/// What fitting one model gave.
struct Fitted {
    fit: Fit,
    /// The x range of the points used.
    x_range: (Option<f64>, Option<f64>),
    /// The paper's coefficients' relative error on the same points.
    paper_error: Option<f64>,
}

/// One output row: a model, the points it used, and its fit or why there is none.
struct ModelRow<'a> {
    model: &'a Model,
    n: usize,
    fitted: std::result::Result<Fitted, String>,
}

impl Row for ModelRow<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let m = self.model;
        let ok = self.fitted.as_ref().ok();
        let param = |k: usize| ok.map(|f| f.fit.params[k]);
        let error = |k: usize| ok.map(|f| f.fit.std_errors[k]);
        let paper = |k: usize| m.paper.map(|p| p[k]);
        vec![
            ("model", m.name.clone().into()),
            ("form", m.form.name().into()),
            ("y", m.y.clone().into()),
            ("A", param(0).into()),
            ("B", param(1).into()),
            ("C", param(2).into()),
            ("se_A", error(0).into()),
            ("se_B", error(1).into()),
            ("se_C", error(2).into()),
            ("relative_error", ok.map(|f| f.fit.relative_error).into()),
            ("x_min", ok.and_then(|f| f.x_range.0).into()),
            ("x_max", ok.and_then(|f| f.x_range.1).into()),
            ("n", Cell::from(self.n as i64)),
            ("iterations", ok.map(|f| f.fit.iterations as i64).into()),
            ("paper_A", paper(0).into()),
            ("paper_B", paper(1).into()),
            ("paper_C", paper(2).into()),
            (
                "paper_relative_error",
                ok.and_then(|f| f.paper_error).into(),
            ),
            ("failure", self.fitted.as_ref().err().cloned().into()),
        ]
    }
}

impl Kind for FitStage {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        let [input] = stage.inputs.as_slice() else {
            return wrong_inputs("a fit stage reads exactly one table");
        };
        match inputs.get::<crate::render::Render>(input) {
            Some(_) => Err((
                "inputs[0]".into(),
                format!("`{input}` is a render stage: read a data table"),
            )),
            None => Ok(()),
        }
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let frame = ctx.input(&ctx.stage.inputs[0])?;
        self.compute(ctx.name(), &frame)
    }
}
