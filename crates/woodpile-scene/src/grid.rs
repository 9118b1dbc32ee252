//! A sweep's parameter grid: named axes, each a list or a `{ from, to, step }` range, and the
//! Cartesian product of their values in a fixed order (axes sorted by name, the last varying
//! fastest). Range values are computed as `from + i * step` and rounded to 12 significant
//! digits, so `0.1 + 2 * 0.1` is the `0.3` a user typed elsewhere and two sweeps that share a
//! value share its cached point.

use woodpile_sim::simulation::batch_size;

use crate::columns;

/// One value of an axis: integers stay integers (p, L), the rest are floats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisValue {
    /// An integer value.
    Int(i64),
    /// A float value.
    Float(f64),
}

impl AxisValue {
    /// The value as TOML, for substitution into a scene.
    pub fn to_toml(self) -> toml::Value {
        match self {
            AxisValue::Int(i) => toml::Value::Integer(i),
            AxisValue::Float(x) => toml::Value::Float(x),
        }
    }

    /// The value as a float.
    pub fn as_f64(self) -> f64 {
        match self {
            AxisValue::Int(i) => i as f64,
            AxisValue::Float(x) => x,
        }
    }
}

impl std::fmt::Display for AxisValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AxisValue::Int(i) => write!(f, "{i}"),
            AxisValue::Float(x) => write!(f, "{x}"),
        }
    }
}

/// A named axis and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The name, used as `$name` in the scene template and as the output column.
    pub name: String,
    /// Integer axes hold only `Int`s, float axes only `Float`s.
    pub values: Vec<AxisValue>,
}

impl Axis {
    /// Whether the axis holds integers.
    pub fn is_integer(&self) -> bool {
        matches!(self.values.first(), Some(AxisValue::Int(_)))
    }
}

/// Each axis with its value at one point, as `name{between}value`: how messages and labels
/// name a point.
pub fn named_values(axes: &[Axis], values: &[AxisValue], between: &str) -> Vec<String> {
    axes.iter()
        .zip(values)
        .map(|(a, v)| format!("{}{between}{v}", a.name))
        .collect()
}

/// ` (at eps = 1, L = 2)`, for messages about the point at `values`; empty without axes.
pub fn at_point(axes: &[Axis], values: &[AxisValue]) -> String {
    if axes.is_empty() {
        return String::new();
    }
    format!(" (at {})", named_values(axes, values, " = ").join(", "))
}

/// Most points a single sweep may have: a hundred times the paper's largest grid (10^4). A
/// run plans every point (about 1.4 KB each) and keeps its series, so beyond this a grid
/// needs gigabytes before its first simulation: split it into several sweeps (or fix a typo
/// in `step`). The pipeline's sweep also bounds the memory of the series themselves.
pub const MAX_POINTS: usize = 1_000_000;

/// Most memory a sweep may need for its points: their planned scenes and their series.
pub const MAX_SWEEP_BYTES: f64 = 4e9;

/// Bytes a scene holds per site while it runs: its model, its state and its stepper's stages.
const RUNNING_BYTES_PER_SITE: f64 = 200.0;

/// Bytes a scene holds per site once planned, before it runs (masses, inverse masses, contact
/// coefficients): what a list of scenes given at once holds for every one of them.
pub const PLANNED_BYTES_PER_SITE: f64 = 40.0;

/// Refuses, before anything runs, a sweep of `points` scenes like `scene` (its largest) that
/// would hold more than [`MAX_SWEEP_BYTES`]. What a sweep holds: for every point, its cache key
/// and outcome (about 1.4 KB, whatever the chain) and its series (five numbers a sample, six with a striker, in the
/// point and again in the output table); and, while it runs, the scenes of one batch per
/// worker thread (groups of four neighbours, [`batch_size`]), each with its state (about 200
/// bytes a site). A point's scene and final state are not kept: a sweep of a long chain would
/// otherwise hold a chain's worth of floats per point. The error is the reason, with the
/// estimate.
pub fn check_sweep_memory(points: usize, scene: &crate::Scene) -> Result<(), String> {
    let bytes = held_bytes(points, scene, 0.0);
    match bytes > MAX_SWEEP_BYTES {
        false => Ok(()),
        true => Err(format!(
            "{points} points of {} samples on {} sites would take about {:.1} GB in memory, more than the {:.0} GB a sweep may use; split the grid or sample less often",
            samples(scene),
            scene.scenario.model.n_sites(),
            bytes / 1e9,
            MAX_SWEEP_BYTES / 1e9
        )),
    }
}

/// [`check_sweep_memory`] for a list of scenes given at once (Python's `simulate_many`), which
/// are all planned before the first runs: each holds its chain until the list is done.
pub fn check_list_memory(scenes: &[crate::Scene]) -> Result<(), String> {
    let Some(largest) = scenes.iter().max_by_key(|s| s.scenario.model.n_sites()) else {
        return Ok(());
    };
    let planned: f64 = scenes
        .iter()
        .map(|s| s.scenario.model.n_sites() as f64 * PLANNED_BYTES_PER_SITE)
        .sum();
    let bytes = held_bytes(scenes.len(), largest, planned);
    match bytes > MAX_SWEEP_BYTES {
        false => Ok(()),
        true => Err(format!(
            "{} scenes of up to {} sites would take about {:.1} GB in memory, more than the {:.0} GB a call may use; simulate fewer or shorter chains at a time",
            scenes.len(),
            largest.scenario.model.n_sites(),
            bytes / 1e9,
            MAX_SWEEP_BYTES / 1e9
        )),
    }
}

/// The samples a scene's series records.
fn samples(scene: &crate::Scene) -> u64 {
    let s = &scene.scenario;
    woodpile_sim::integrate::intervals(s.t_end, s.sample_every) + 1
}

/// What `points` scenes like `scene` (the largest) hold at most, run a batch per thread, with
/// `planned` bytes held besides.
fn held_bytes(points: usize, scene: &crate::Scene, planned: f64) -> f64 {
    let s = &scene.scenario;
    // The workers a run starts: RAYON_NUM_THREADS where set, else one per core.
    let threads = crate::threads::asked_threads()
        .ok()
        .flatten()
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let running = points.min(threads.saturating_mul(batch_size(points)));
    let in_flight = (running * s.model.n_sites()) as f64 * RUNNING_BYTES_PER_SITE;
    // A point's series: its times and energies, and each share it reports (S with a striker,
    // D with losses).
    let shares = woodpile_sim::ShareSet::of(&s.model, &s.region)
        .iter()
        .count();
    let columns = 2 + shares as u64;
    points as f64 * (1400.0 + (samples(scene) * columns * 8 * 2) as f64) + in_flight + planned
}

/// Column names an axis may not take: every column a sweep's table ([`crate::columns`]), a vary
/// stage or Python's `simulate_many` writes beside the axes, so that no axis value is ever
/// overwritten by a result of its name, nor a result by an axis.
pub const RESERVED: &[&str] = &[
    columns::POINT,
    columns::TIME,
    columns::REFLECTED,
    columns::TRANSMITTED,
    columns::TRAPPED,
    columns::STRIKER,
    columns::DISSIPATED,
    columns::ENERGY,
    columns::METHOD,
    columns::DT,
    columns::STEPS,
    columns::ERROR_ESTIMATE,
    columns::ENERGY_DRIFT,
    columns::END_REACHED_AT,
    columns::FAILURE,
    columns::SCENE_KEY,
    "rhs_evals",
    "total_rhs_evals",
    "E_initial",
    "E_final",
    "design",
    "design_index",
];

/// `(dotted key relative to the axes table, reason)`; an empty key is the table as a whole.
/// The caller knows the file and where the table sits.
pub type AxisError = (String, String);

/// Parses an `[axes]` table: each key an axis name, each value a list of numbers or a range
/// `{ from, to, step }`; the product may have at most [`MAX_POINTS`] points.
pub fn parse_axes(table: toml::Table) -> Result<Vec<Axis>, AxisError> {
    let mut axes = Vec::new();
    for (name, value) in table {
        if !is_identifier(&name) || RESERVED.contains(&name.as_str()) {
            return Err((
                name,
                format!("an axis name must be an identifier and not one of {RESERVED:?}"),
            ));
        }
        let values = match value {
            toml::Value::Array(items) => list(&name, items)?,
            toml::Value::Table(table) => {
                range(table).map_err(|(key, reason)| (format!("{name}.{key}"), reason))?
            }
            _ => {
                return Err((
                    name,
                    "expected an array of numbers or a table { from, to, step }".into(),
                ))
            }
        };
        axes.push(Axis { name, values });
    }
    let total = axes
        .iter()
        .try_fold(1usize, |n, a| n.checked_mul(a.values.len()));
    if !matches!(total, Some(n) if n <= MAX_POINTS) {
        return Err((String::new(), format!(
            "{} points, more than the {MAX_POINTS} a sweep may have (about 1.4 KB each to plan, plus the series); split the grid",
            total.map_or("over 2^64".to_string(), |n| n.to_string())
        )));
    }
    Ok(axes)
}

fn list(name: &str, items: Vec<toml::Value>) -> Result<Vec<AxisValue>, AxisError> {
    let error = |reason: &str| (name.to_string(), reason.to_string());
    if items.is_empty() {
        return Err(error("an axis needs at least one value"));
    }
    let all_int = items.iter().all(|v| v.is_integer());
    items
        .into_iter()
        .map(|v| match v {
            toml::Value::Integer(i) if all_int => Ok(AxisValue::Int(i)),
            toml::Value::Integer(i) => Ok(AxisValue::Float(i as f64)),
            toml::Value::Float(x) if x.is_finite() => Ok(AxisValue::Float(x)),
            _ => Err(error("expected finite numbers")),
        })
        .collect()
}

/// A `{ from, to, step }` table; error keys are relative to it.
fn range(mut table: toml::Table) -> Result<Vec<AxisValue>, AxisError> {
    let error = |key: &str, reason: String| (key.to_string(), reason);
    let mut take = |key: &str| table.remove(key);
    let (from, to) = (take("from"), take("to"));
    let (step, count, log) = (take("step"), take("count"), take("log"));
    if let Some(key) = table.keys().next() {
        return Err(error(
            key,
            "unknown key (a range has from, to, and step or count, log)".into(),
        ));
    }
    let missing = |key: &str| error(key, "missing (expected a value)".into());
    let (from, to) = (
        from.ok_or_else(|| missing("from"))?,
        to.ok_or_else(|| missing("to"))?,
    );
    let number = |value: &toml::Value, key: &str| -> Result<f64, AxisError> {
        match *value {
            toml::Value::Integer(v) => Ok(v as f64),
            toml::Value::Float(v) if v.is_finite() => Ok(v),
            _ => Err(error(key, "expected a number".into())),
        }
    };
    let log = match log {
        None => false,
        Some(toml::Value::Boolean(b)) => b,
        Some(_) => return Err(error("log", "expected true or false".into())),
    };
    match (step, count) {
        (Some(step), None) if !log => {
            let all_int = from.is_integer() && to.is_integer() && step.is_integer();
            let (from, to, step) = (
                number(&from, "from")?,
                number(&to, "to")?,
                number(&step, "step")?,
            );
            stepped(from, to, step, all_int)
        }
        (Some(_), None) => Err(error(
            "log",
            "a log range is spaced by `count`, not `step`".into(),
        )),
        (None, Some(count)) => {
            let (from, to) = (number(&from, "from")?, number(&to, "to")?);
            let count = match count {
                toml::Value::Integer(n) if (1..=MAX_POINTS as i64).contains(&n) => n as usize,
                _ => {
                    return Err(error(
                        "count",
                        format!("expected a whole number from 1 to {MAX_POINTS}"),
                    ))
                }
            };
            counted(from, to, count, log)
        }
        (Some(_), Some(_)) => Err(error("count", "give `step` or `count`, not both".into())),
        (None, None) => Err(error(
            "step",
            "missing (expected `step`, or `count`)".into(),
        )),
    }
}

/// `from, from + step, ..., to`.
fn stepped(from: f64, to: f64, step: f64, all_int: bool) -> Result<Vec<AxisValue>, AxisError> {
    let error = |key: &str, reason: String| (key.to_string(), reason);
    if step <= 0.0 || to < from {
        return Err(error("step", "need step > 0 and to >= from".into()));
    }
    let n = ((to - from) / step).round();
    if n >= MAX_POINTS as f64 {
        return Err(error("step", format!("more than {MAX_POINTS} values")));
    }
    if (from + n * step - to).abs() > 1e-9 * step.max(to.abs()) {
        return Err(error(
            "to",
            format!("{to} is not from + k * step ({from} + k * {step})"),
        ));
    }
    let values = (0..=n as i64)
        .map(|i| {
            if all_int {
                AxisValue::Int(from as i64 + i * step as i64)
            } else {
                AxisValue::Float(round_sig(from + i as f64 * step, GRID_DIGITS))
            }
        })
        .collect();
    Ok(values)
}

/// `count` values from `from` to `to`, both included, evenly spaced or (with `log`) evenly
/// spaced in the logarithm; rounded to 12 significant digits.
fn counted(from: f64, to: f64, count: usize, log: bool) -> Result<Vec<AxisValue>, AxisError> {
    let error = |key: &str, reason: &str| (key.to_string(), reason.to_string());
    if to < from || (count == 1 && to != from) {
        return Err(error("to", "need to >= from (and to = from for count = 1)"));
    }
    if log && from <= 0.0 {
        return Err(error("from", "a log range needs from > 0"));
    }
    let at = |i: usize| {
        if i + 1 == count {
            return to;
        }
        let f = i as f64 / (count - 1).max(1) as f64;
        if log {
            (from.ln() + f * (to.ln() - from.ln())).exp()
        } else {
            from + f * (to - from)
        }
    };
    let values: Vec<AxisValue> = (0..count)
        .map(|i| AxisValue::Float(round_sig(at(i), GRID_DIGITS)))
        .collect();
    if values.windows(2).any(|w| w[0] == w[1]) {
        return Err(error(
            "count",
            "values so close that they round to the same number",
        ));
    }
    Ok(values)
}

/// Significant digits of a grid value: what a user would type, far finer than any physics.
const GRID_DIGITS: usize = 12;

/// `x` rounded to `digits` significant digits through its decimal form, so that it is the
/// nearest double to what a user would type: the one rounding of every generated parameter
/// (grid values here, a design's eps and kappa).
pub fn round_sig(x: f64, digits: usize) -> f64 {
    let places = digits.saturating_sub(1);
    format!("{x:.places$e}").parse().unwrap_or(x)
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The `index`-th point of the product of `axes` (last axis fastest).
pub fn point(axes: &[Axis], mut index: usize) -> Vec<AxisValue> {
    let mut values = vec![AxisValue::Int(0); axes.len()];
    for (slot, axis) in values.iter_mut().zip(axes).rev() {
        let n = axis.values.len();
        *slot = axis.values[index % n];
        index /= n;
    }
    values
}

/// Number of points in the product of `axes` (1 for no axes: a single scene).
pub fn point_count(axes: &[Axis]) -> usize {
    axes.iter().map(|a| a.values.len()).product()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(text: &str) -> Result<Vec<Axis>, AxisError> {
        parse_axes(toml::from_str(text).unwrap())
    }

    #[test]
    fn counted_ranges_are_linear_or_logarithmic() {
        let a = axes("eps = { from = 0.1, to = 100.0, count = 31, log = true }").unwrap();
        let v: Vec<f64> = a[0].values.iter().map(|v| v.as_f64()).collect();
        assert_eq!(v.len(), 31);
        assert_eq!((v[0], v[10], v[20], v[30]), (0.1, 1.0, 10.0, 100.0));
        let b = axes("x = { from = 0, to = 1, count = 5 }").unwrap();
        let w: Vec<f64> = b[0].values.iter().map(|v| v.as_f64()).collect();
        assert_eq!(w, [0.0, 0.25, 0.5, 0.75, 1.0]);
        let key = |t: &str| axes(t).unwrap_err().0;
        assert_eq!(
            key("x = { from = 0, to = 1, count = 5, log = true }"),
            "x.from"
        );
        assert_eq!(
            key("x = { from = 1, to = 2, step = 1, count = 2 }"),
            "x.count"
        );
        assert_eq!(
            key("x = { from = 1, to = 2, step = 1, log = true }"),
            "x.log"
        );
        assert_eq!(key("x = { from = 1, to = 2, count = 0 }"), "x.count");
    }

    #[test]
    fn ranges_hit_the_decimal_values_a_user_would_type() {
        let a = axes("eps = { from = 0.1, to = 60.0, step = 0.1 }").unwrap();
        assert_eq!(a[0].values.len(), 600);
        assert_eq!(a[0].values[2], AxisValue::Float(0.3));
        assert_eq!(a[0].values[599], AxisValue::Float(60.0));
    }

    #[test]
    fn integer_lists_and_ranges_stay_integer() {
        let a = axes("L = [0, 2]\np = { from = 3, to = 19, step = 2 }").unwrap();
        assert!(a[0].is_integer() && a[1].is_integer());
        assert_eq!(a[1].values.len(), 9);
        assert_eq!(point(&a, 0), vec![AxisValue::Int(0), AxisValue::Int(3)]);
        assert_eq!(point(&a, 10), vec![AxisValue::Int(2), AxisValue::Int(5)]);
        assert_eq!(point_count(&a), 18);
    }

    #[test]
    fn bad_axes_name_their_key() {
        let key = |t: &str| axes(t).unwrap_err().0;
        assert_eq!(key("eps = { from = 0.1, to = 1.05, step = 0.1 }"), "eps.to");
        assert_eq!(key("eps = { from = 0.1, to = 1.0 }"), "eps.step");
        assert_eq!(
            key("eps = { from = 1, to = 2, step = 1, by = 3 }"),
            "eps.by"
        );
        assert_eq!(key("t = [1.0]"), "t");
        assert!(axes("eps = []").unwrap_err().1.contains("at least one"));
        assert_eq!(key("eps = \"x\""), "eps");
    }
}
