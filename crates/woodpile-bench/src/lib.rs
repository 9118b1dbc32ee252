//! The scene every speed claim is measured on, shared by the divan benchmarks and the
//! comparison binary: the paper's standard chain (N = 100, fixed walls, impulse at -25, t = 150)
//! with one linear defect eps = 10, kappa = 1 at site 0, the scene of the C and numba
//! timings (`baseline/`).

pub mod independent;
pub mod paper;
pub mod sweeps;

use woodpile_sim::integrate::{
    drive, Accuracy, DriveConfig, Method, MethodChoice, Plan, Stats, StepControl, Stepper,
};
use woodpile_sim::simulation::{auto_first_step, simulate, Outcome, Scenario};
use woodpile_sim::testing::{fixed_dt, paper_scene, tolerance, PaperDefect};
use woodpile_sim::SimError;

/// The standard scene integrated by `method` with `accuracy`.
pub fn standard_scene(method: MethodChoice, accuracy: Accuracy) -> Scenario {
    paper_scene(&[PaperDefect::linear(0, 10.0, 1.0)], method, accuracy)
}

/// The standard scene as a scene file, `defect` added to its resonator's table and `tail` to
/// the file, resolved: how the damped measurements add one kind of loss at a time.
pub fn standard_scene_with(defect: &str, tail: &str) -> Scenario {
    let text = format!(
        "[chain]\nn = 100\nboundary = \"fixed\"\n[impulse]\nsite = -25\nvelocity = 1.0\n\
         [[defect]]\nsite = 0\neps = 10.0\nkappa = 1.0\np = 1\n{defect}\n\
         [run]\nt_end = 150.0\nmethod = \"auto\"\ntolerance = 1e-8\n{tail}"
    );
    match woodpile_scene::parse(&text, std::path::Path::new("standard_scene_with.toml")) {
        Ok(scene) => scene.scenario,
        Err(e) => panic!("the standard scene with {defect:?} and {tail:?}: {e}"),
    }
}

/// The standard scene with a dashpot of 0.05 on every contact, of law `law` (`"hertzian"` or
/// `"linear"`): the damped measurements' contact-dashpot rows.
pub fn standard_scene_with_dashpot(law: &str) -> Scenario {
    standard_scene_with("", &format!("[damping]\ncontact = 0.05\nlaw = \"{law}\""))
}

/// The standard scene by a named fixed-step method at step `dt`.
pub fn fixed(method: Method, dt: f64) -> Scenario {
    standard_scene(MethodChoice::Named(method), fixed_dt(dt))
}

/// Simulates `scenario` without observers.
pub fn run(scenario: &Scenario) -> Result<Outcome, SimError> {
    simulate(scenario, &mut ())
}

/// `scene` by `method` at the fixed step `dt`, or `None` when the run blew up or lost its
/// energy (an estimate would then say "halve"): the experiments on `auto`'s estimates.
pub fn at_fixed_step(scene: &Scenario, method: Method, dt: f64) -> Option<Outcome> {
    let s = Scenario {
        method: MethodChoice::Named(method),
        accuracy: fixed_dt(dt),
        ..scene.clone()
    };
    run(&s).ok()
}

/// The first step of `auto`'s ladder on `scene` at tolerance `tol` (`None` when `auto` has
/// no plan for it).
pub fn auto_first_step_at(scene: &Scenario, tol: f64) -> Option<f64> {
    let s = Scenario {
        accuracy: tolerance(tol),
        ..scene.clone()
    };
    let plan = Plan::choose(&s.model, s.method, s.accuracy).ok()?;
    Some(auto_first_step(&s, &plan))
}

/// `scene` from its impulse to its end by `stepper` at the fixed step `dt`, on the active
/// window, observed every `sample_every` and stopped when the energy drifts by more than
/// `drift_limit`: the final state `[q, q']` and the run's stats. For the examples that compare
/// steppers `Plan` does not offer (plain contact treatments, batched lanes).
pub fn drive_fixed(
    scene: &Scenario,
    stepper: &mut dyn Stepper,
    (dt, sample_every): (f64, f64),
    drift_limit: Option<f64>,
) -> Result<(Vec<f64>, Stats), SimError> {
    let model = &scene.model;
    let mut y = model.rest_state();
    model.apply_impulse(&mut y, scene.impulse_site, scene.impulse_velocity)?;
    let cfg = DriveConfig {
        t_end: scene.t_end,
        sample_every,
        control: StepControl::Fixed { dt },
        max_steps: 100_000_000,
        energy_drift_limit: drift_limit,
        active_window: true,
    };
    let stats = drive(model, stepper, &mut y, &cfg, &mut ())?;
    Ok((y, stats))
}

/// `work` applied to every item on two threads (this machine's two cores), results in the
/// items' order. For the survey examples, whose scenes are independent and each take long
/// enough that a static split (even items on one thread, odd on the other) balances well.
pub fn on_two_cores<T: Sync, R: Send>(items: &[T], work: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let work = &work;
    let mut tagged: Vec<(usize, R)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..2)
            .map(|first| {
                s.spawn(move || {
                    (first..items.len())
                        .step_by(2)
                        .map(|i| (i, work(&items[i])))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|worker| worker.join().expect("a survey worker panicked"))
            .collect()
    });
    tagged.sort_by_key(|(i, _)| *i);
    tagged.into_iter().map(|(_, r)| r).collect()
}
