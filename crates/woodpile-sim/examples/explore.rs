use woodpile_sim::energy::{energy_density, Fractions};
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice, Plan, StepControl};
use woodpile_sim::model::Coupling;
use woodpile_sim::testing::{paper_scene, PaperDefect};

fn run(plan: &Plan, d: &[PaperDefect]) -> (f64, f64) {
    let s = paper_scene(d, MethodChoice::Auto, Accuracy { tolerance: 1.0, tolerance_explicit: false, dt: None });
    let mut y = s.model.rest_state();
    s.model.apply_impulse(&mut y, s.impulse_site, 1.0).unwrap();
    let st = plan.run(&s.model, &mut y, 150.0, 1.0, &mut ()).unwrap();
    let mut e = vec![0.0; s.model.n_sites()];
    energy_density(&s.model, 150.0, &y, &mut e);
    (Fractions::from_density(&e, s.region).trapped, st.max_energy_drift)
}

fn main() {
    let lin = PaperDefect::linear;
    let scenes: Vec<(&str, Vec<PaperDefect>)> = vec![
        ("eps3", vec![lin(0, 3.0, 1.0)]),
        ("eps0.01", vec![lin(0, 0.01, 1.0)]),
        ("L2", vec![lin(0, 10.0, 1.0), lin(1, 10.0, 1.0), lin(2, 10.0, 1.0)]),
        ("p7", vec![PaperDefect { site: 0, eps: 0.2, coupling: Coupling::Constant(1.0), p: 7 }]),
        ("p19e0.01", vec![PaperDefect { site: 0, eps: 0.01, coupling: Coupling::Constant(1.0), p: 19 }]),
        ("sep", vec![lin(0, 13.0, 1.0), lin(20, 100.0, 1.0)]),
        ("ramp", vec![PaperDefect { site: 0, eps: 10.0, coupling: Coupling::Ramp { k1: 0.0, k2: 2.5, t0: 40.0, tau: 0.1 }, p: 1 }, lin(20, 10.0, 2.5)]),
    ];
    for (name, d) in &scenes {
        let (reference, _) = run(&Plan { method: Method::Rk4, control: StepControl::Fixed { dt: 0.001 }, rtol: 0.0, atol: 0.0, drift_limit: 1.0 }, d);
        let (ref2, _) = run(&Plan { method: Method::Yoshida6, control: StepControl::Fixed { dt: 0.002 }, rtol: 0.0, atol: 0.0, drift_limit: 1.0 }, d);
        print!("{name:>9}: ref {reference:.12} (y6 diff {:.1e})", (ref2 - reference).abs());
        for m in [Method::Rk4, Method::Yoshida4, Method::Yoshida6] {
            for dt in [0.02, 0.01] {
                let (e, drift) = run(&Plan { method: m, control: StepControl::Fixed { dt }, rtol: 0.0, atol: 0.0, drift_limit: 1.0 }, d);
                print!(" | {} {dt}: {:.1e} d{:.0e}", m.name(), (e - reference).abs(), drift);
            }
        }
        println!();
    }
}
