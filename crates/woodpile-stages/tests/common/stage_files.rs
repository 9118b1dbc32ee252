//! Stage files the end-to-end tests share: those of woodpile-stages (through `common`) and
//! those of woodpile-cli (included by path), so that a fixture and its variants are written once.
#![allow(dead_code)]

/// A sweep over L in {0, 1} and eps in {0.5, 1, 1.5} on a chain of 25 sites, to t = 12.
pub const SWEEP: &str = r#"
kind = "sweep"
[axes]
L = [0, 1]
eps = { from = 0.5, to = 1.5, step = 0.5 }
[scene]
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0, method = "rk4", dt = 0.02, sample_every = 2.0 }
[[scene.defect]]
site = 0
through = "$L"
eps = "$eps"
"#;

/// [`SWEEP`] without the L axis: one defect at site 0, eps in {0.5, 1, 1.5}.
pub fn single_defect_sweep() -> String {
    SWEEP
        .replace("L = [0, 1]\n", "")
        .replace("through = \"$L\"\n", "")
}

pub const REDUCE: &str = r#"
kind = "reduce"
inputs = ["sweep"]
at = 12.0
"#;

pub const BEST: &str = r#"
kind = "reduce"
inputs = ["sweep"]
[maximize]
over = ["eps"]
"#;

pub const REPORT: &str = r#"
kind = "report"
inputs = ["sweep", "at_end"]
markdown = "REPORT.md"
title = "Tiny report"

[[quote]]
figure = "X1"
quantity = "E_tr at L = 0, eps = 1, end"
paper = PAPER
agree = 1e-12
as_run = "t = 12"
ours = { stage = "at_end", column = "E_tr", where = { L = 0, eps = 1.0 } }
[[quote.convention]]
name = "read-out time"
source = { stage = "sweep", column = "E_tr", where = { L = 0, eps = 1.0 }, scan = "t" }
[[quote.convention]]
name = "largest over the grid"
source = { stage = "at_end", column = "E_tr", max = "E_tr", locate = ["L", "eps"] }
"#;

pub const WORK_PRECISION: &str = r#"
kind = "workprecision"
repeats = 1
reference_tolerance = 1e-12
[[scene]]
name = "tiny"
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0 }
defect = [{ site = 0, eps = 2.0 }]
[[method]]
name = "rk4"
dt = [0.2, 0.1, 0.05]
[[method]]
name = "dop853"
tolerance = [1e-6]
"#;

pub const WORK_PRECISION_CHART: &str = r#"
kind = "render"
inputs = ["wp"]
title = "work-precision"
where = { scene = 0 }
[lines]
x = "log10_wall_ms"
y = ["log10_error"]
series = "method_index"
series_label = "method"
x_label = "log10 ms"
y_label = "log10 error"
"#;

/// A figure of R and E_tr against eps from the `at_end` reduction; `TITLE` is its title.
pub const FIGURE: &str = r#"
kind = "render"
inputs = ["at_end"]
title = "TITLE"
[lines]
x = "eps"
y = ["R", "E_tr"]
x_label = "eps"
y_label = "fraction"
"#;

/// [`SWEEP`] with L = 0 only and eps from 0.5 to `eps_to` by 0.5.
pub fn single_defect_sweep_to(eps_to: f64) -> String {
    SWEEP.replace("L = [0, 1]", "L = [0]").replace(
        "eps = { from = 0.5, to = 1.5, step = 0.5 }",
        &format!("eps = {{ from = 0.5, to = {eps_to:?}, step = 0.5 }}"),
    )
}

/// A design stage on [`SWEEP`]'s chain with `auto` at `tolerance`: one or two resonators at
/// sites 0 to 3, seeded; `budget` trials, `refine` refinement steps, the best verified at
/// `verify` and its robustness sampled `samples` times at each of `spreads`.
pub fn design(budget: u32, refine: u32, tolerance: f64, verify: f64, robustness: &str) -> String {
    format!(
        r#"
kind = "design"
seed = 7
budget = {budget}
refine = {refine}
objective = "E_tr"
verify_tolerance = {verify:e}
robustness = {{ {robustness} }}
[scene]
chain = {{ n = 12 }}
impulse = {{ site = -6 }}
run = {{ t_end = 12.0, method = "auto", tolerance = {tolerance:e} }}
fractions = {{ region = [-1, 4] }}
[space]
resonators = [1, 2]
sites = [0, 3]
eps = {{ min = 0.1, max = 10.0, log = true }}
kappa = {{ min = 0.5, max = 2.0 }}
"#
    )
}

/// A sweep stage file over `axes` (the lines of its `[axes]` table) on a chain of 2 n + 1
/// sites struck at site -n/2, run by RK4 as `(t_end, dt, sample_every)`, with one defect per
/// `(site, eps)`.
pub fn sweep_file(axes: &str, n: u32, run: (f64, f64, f64), defects: &[(i32, &str)]) -> String {
    let (t_end, dt, sample_every) = run;
    let mut text = format!(
        "kind = \"sweep\"\n[axes]\n{axes}\n[scene]\nchain = {{ n = {n} }}\nimpulse = {{ site = -{} }}\n\
         run = {{ t_end = {t_end:?}, method = \"rk4\", dt = {dt:?}, sample_every = {sample_every:?} }}\n",
        n / 2
    );
    for (site, eps) in defects {
        text += &format!("[[scene.defect]]\nsite = {site}\neps = \"{eps}\"\n");
    }
    text
}
