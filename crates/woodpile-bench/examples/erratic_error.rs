//! Why a Richardson pair can agree while both runs miss: on a two-defect scene the fraction
//! errors of `rk4-contact` and `rkn4-contact` at t = 150 are erratic in dt (steps 0.040 to
//! 0.059 by 0.001, samples only at t = 150), and they come in jumps, not a steady drift: the
//! time series of the errors (every 2 time units) at dt = 0.05 and 0.5/11 shows the state
//! error growing smoothly while T and E_tr jump when bursts of energy leave the region
//! between the defects. Reference: `rk4-contact` at dt = 0.0005.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example erratic_error [-- EPS1 EPS2]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_sim::energy::{energy_density, Fractions};
use woodpile_sim::integrate::{Method, MethodChoice, Observer};
use woodpile_sim::model::Model;
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{fixed_dt, paper_scene, PaperDefect};

/// Every sampled state.
struct States(Vec<(f64, Vec<f64>)>);

impl Observer for States {
    fn observe(&mut self, _: &Model, t: f64, y: &[f64]) {
        self.0.push((t, y.to_vec()));
    }
    fn reset(&mut self) {
        self.0.clear();
    }
}

fn scene(defects: &[PaperDefect], method: Method, dt: f64, every: f64) -> Scenario {
    let mut s = paper_scene(defects, MethodChoice::Named(method), fixed_dt(dt));
    s.sample_every = every;
    s
}

fn states(s: &Scenario) -> Vec<(f64, Vec<f64>)> {
    let mut out = States(Vec::new());
    simulate(s, &mut out).unwrap();
    out.0
}

fn main() {
    let arg = |k: usize, default: f64| {
        std::env::args()
            .nth(k)
            .map_or(default, |s| s.parse().unwrap())
    };
    let defects = [
        PaperDefect::linear(0, arg(1, 87.0), 1.0),
        PaperDefect::linear(20, arg(2, 37.0), 1.0),
    ];
    let final_fractions = |method, dt| {
        simulate(&scene(&defects, method, dt, 150.0), &mut ())
            .unwrap()
            .fractions
    };
    let reference = final_fractions(Method::Rk4Contact, 0.0005);
    println!("errors at t = 150 (T, E_tr) against dt");
    for k in 0..20 {
        let dt = 0.040 + 0.001 * k as f64;
        let a = final_fractions(Method::Rk4Contact, dt);
        let b = final_fractions(Method::Rkn4Contact, dt);
        println!(
            "dt {dt:.3}  rk4-contact {:+.1e} {:+.1e}  rkn4-contact {:+.1e} {:+.1e}",
            a.transmitted - reference.transmitted,
            a.trapped - reference.trapped,
            b.transmitted - reference.transmitted,
            b.trapped - reference.trapped,
        );
    }
    let reference_scene = scene(&defects, Method::Rk4Contact, 0.0005, 0.5);
    let reference = states(&reference_scene);
    let runs =
        [0.05, 0.5 / 11.0].map(|dt| (dt, states(&scene(&defects, Method::Rkn4Contact, dt, 0.5))));
    let model = &reference_scene.model;
    let mut density = vec![0.0; model.n_sites()];
    let mut fractions = |t: f64, y: &[f64]| {
        energy_density(model, t, y, &mut density);
        Fractions::from_density(&density, reference_scene.region)
    };
    println!("rkn4-contact errors in time: T, E_tr and the largest state error");
    for (k, (t, y_ref)) in reference.iter().enumerate().step_by(4) {
        let f_ref = fractions(*t, y_ref);
        let mut line = format!("t {t:5.1}");
        for (dt, run) in &runs {
            let y = &run[k].1;
            let f = fractions(*t, y);
            let state = y
                .iter()
                .zip(y_ref)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            line += &format!(
                "  dt {dt:.4}: {:+.1e} {:+.1e} {:.1e}",
                f.transmitted - f_ref.transmitted,
                f.trapped - f_ref.trapped,
                state
            );
        }
        println!("{line}");
    }
}
