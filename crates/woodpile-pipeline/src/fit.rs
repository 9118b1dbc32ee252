//! `kind = "fit"`: Levenberg–Marquardt fits of the paper's forms to columns of one table.
//!
//! ```toml
//! kind = "fit"
//! inputs = ["f4_fractions"]
//! x = "eps"
//! where = { L = 0 }                        # optional: keep rows where these columns equal these values
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

use crate::error::{PipelineError, Result};
use crate::fields::Fields;
use crate::kind::{Context, Inputs, Kind, KindCheck};
use crate::stage::Stage;
use crate::table::{f64_column, matching_rows, Columns};
use crate::Output;
use woodpile_analysis::lm::{fit, Fit, Form};

/// A parsed fit stage.
#[derive(Debug, Clone, PartialEq)]
pub struct FitStage {
    /// The x column.
    pub x: String,
    /// Row filter: column = value.
    pub filter: Vec<(String, f64)>,
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
            let form_name: String = f.required("form")?;
            let form = Form::from_name(&form_name).ok_or_else(|| {
                f.error(
                    "form",
                    format!("unknown form `{form_name}` (forms: power, tanh)"),
                )
            })?;
            let start = f.take("start");
            let start = triple(&f, "start", start)?
                .ok_or_else(|| f.error("start", "missing (expected [A, B, C])"))?;
            let paper = f.take("paper");
            let paper = triple(&f, "paper", paper)?;
            let x_range = match f.optional::<Vec<f64>>("x_range")?.as_deref() {
                None => None,
                Some(&[lo, hi]) if lo <= hi => Some([lo, hi]),
                Some(_) => return Err(f.error("x_range", "expected [lo, hi] with lo <= hi")),
            };
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

    pub(crate) fn run(&self, stage: &str, input: &DataFrame) -> Result<Output> {
        let fail = |reason: String| PipelineError::stage(stage, reason);
        let column = |name: &str| f64_column(input, name).map_err(|e| fail(e.to_string()));
        let keep = matching_rows(input, &self.filter)
            .map_err(|e| PipelineError::stage(stage, e.to_string()))?;
        let xs = column(&self.x)?;
        let mut out = Rows::default();
        let mut failures = Vec::new();
        for m in &self.models {
            let ys = column(&m.y)?;
            let (x, y): (Vec<f64>, Vec<f64>) = keep
                .iter()
                .filter_map(|&r| Some((xs[r]?, ys[r]?)))
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .filter(|(a, _)| m.x_range.is_none_or(|[lo, hi]| (lo..=hi).contains(a)))
                .unzip();
            let result = match fit(m.form, &x, &y, m.start) {
                Ok(result) => result,
                Err(reason) => {
                    // A fit that fails is a row with its reason, as a failed scene is.
                    failures.push(format!("model `{}`: {reason}", m.name));
                    out.push_failure(m, x.len(), reason);
                    continue;
                }
            };
            let paper_error = m.paper.map(|p| {
                let ssr: f64 = x
                    .iter()
                    .zip(&y)
                    .map(|(&a, &b)| (m.form.eval(p, a) - b).powi(2))
                    .sum();
                ssr.sqrt() / y.iter().map(|v| v * v).sum::<f64>().sqrt()
            });
            let span = |pick: fn(f64, f64) -> f64| x.iter().copied().reduce(pick);
            out.push(
                m,
                &result,
                (span(f64::min), span(f64::max)),
                x.len(),
                paper_error,
            );
        }
        let rows = out.name.len();
        Ok(Output {
            frame: out.into_columns().into_frame()?,
            summary: json!({"models": rows, "rows_used": keep.len(), "failed": failures.len()}),
            failures,
        })
    }
}

#[derive(Default)]
struct Rows {
    name: Vec<Option<String>>,
    form: Vec<Option<String>>,
    y: Vec<Option<String>>,
    params: [Vec<Option<f64>>; 3],
    errors: [Vec<Option<f64>>; 3],
    relative_error: Vec<Option<f64>>,
    x_min: Vec<Option<f64>>,
    x_max: Vec<Option<f64>>,
    n: Vec<Option<i64>>,
    iterations: Vec<Option<i64>>,
    paper: [Vec<Option<f64>>; 3],
    paper_relative_error: Vec<Option<f64>>,
    failure: Vec<Option<String>>,
}

impl Rows {
    fn push(
        &mut self,
        m: &Model,
        f: &Fit,
        (x_min, x_max): (Option<f64>, Option<f64>),
        n: usize,
        paper_error: Option<f64>,
    ) {
        self.x_min.push(x_min);
        self.x_max.push(x_max);
        self.name.push(Some(m.name.clone()));
        self.form.push(Some(m.form.name().to_string()));
        self.y.push(Some(m.y.clone()));
        for k in 0..3 {
            self.params[k].push(Some(f.params[k]));
            self.errors[k].push(Some(f.std_errors[k]));
            self.paper[k].push(m.paper.map(|p| p[k]));
        }
        self.relative_error.push(Some(f.relative_error));
        self.n.push(Some(n as i64));
        self.iterations.push(Some(f.iterations as i64));
        self.paper_relative_error.push(paper_error);
        self.failure.push(None);
    }

    /// A model that could not be fitted: its name and inputs, null coefficients, the reason.
    fn push_failure(&mut self, m: &Model, n: usize, reason: String) {
        self.name.push(Some(m.name.clone()));
        self.form.push(Some(m.form.name().to_string()));
        self.y.push(Some(m.y.clone()));
        for k in 0..3 {
            self.params[k].push(None);
            self.errors[k].push(None);
            self.paper[k].push(m.paper.map(|p| p[k]));
        }
        self.relative_error.push(None);
        self.x_min.push(None);
        self.x_max.push(None);
        self.n.push(Some(n as i64));
        self.iterations.push(None);
        self.paper_relative_error.push(None);
        self.failure.push(Some(reason));
    }

    fn into_columns(self) -> Columns {
        let mut c = Columns::new();
        c.str("model", self.name)
            .str("form", self.form)
            .str("y", self.y);
        let [a, b, cc] = self.params;
        let [sa, sb, sc] = self.errors;
        let [pa, pb, pc] = self.paper;
        c.f64("A", a).f64("B", b).f64("C", cc);
        c.f64("se_A", sa).f64("se_B", sb).f64("se_C", sc);
        c.f64("relative_error", self.relative_error);
        c.f64("x_min", self.x_min).f64("x_max", self.x_max);
        c.i64("n", self.n).i64("iterations", self.iterations);
        c.f64("paper_A", pa).f64("paper_B", pb).f64("paper_C", pc);
        c.f64("paper_relative_error", self.paper_relative_error);
        c.str("failure", self.failure);
        c
    }
}

impl Kind for FitStage {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        let [input] = stage.inputs.as_slice() else {
            return Err((
                "inputs".into(),
                "a fit stage reads exactly one table".into(),
            ));
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
        self.run(ctx.name(), &frame)
    }
}
