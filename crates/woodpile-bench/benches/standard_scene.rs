//! `cargo bench -p woodpile-bench`: the standard scene (N = 100, one defect eps = 10, t = 150)
//! by the methods and steps that reach |ΔE_tr| <= 1e-7, with and without the active window.
#![allow(clippy::unwrap_used)]

use woodpile_bench::{fixed, run};
use woodpile_sim::integrate::{Method, MethodChoice, Plan};
use woodpile_sim::simulation::run_with_plan;
use woodpile_sim::testing::fixed_dt;

fn main() {
    divan::main();
}

/// E_tr of the standard scene by `method` at fixed step `dt` (what every bench returns, so
/// that the work cannot be optimised away).
fn trapped(method: Method, dt: f64) -> f64 {
    run(&fixed(method, dt)).unwrap().fractions.trapped
}

/// RK4 at the step of the C and numba baselines (dt = 0.01, |ΔE_tr| = 2.3e-8).
#[divan::bench]
fn rk4_dt_0_01() -> f64 {
    trapped(Method::Rk4, 0.01)
}

/// The same on the full chain, every site every step: what the active window saves.
#[divan::bench]
fn rk4_dt_0_01_full_chain() -> f64 {
    let scene = fixed(Method::Rk4, 0.01);
    let plan = Plan::choose(
        &scene.model,
        MethodChoice::Named(Method::Rk4),
        fixed_dt(0.01),
    )
    .unwrap();
    run_with_plan(&scene, &plan, &mut (), false)
        .unwrap()
        .fractions
        .trapped
}

/// One method at one fixed step, named for the bench list.
#[derive(Debug, Clone, Copy)]
struct Setting(Method, f64);

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} dt = {}", self.0.name(), self.1)
    }
}

/// The cheapest settings of each method within |ΔE_tr| <= 1e-7 on this scene:
/// - RK4 at dt = 0.02 (6.4e-8);
/// - RK4 with exact contact events at dt = 0.06 (3.4e-8);
/// - Nyström's three-stage method with exact contact events at dt = 0.06 (2.2e-9), and at
///   dt = 0.1 (4.4e-8; R and T are off by 2e-6 there);
/// - Yoshida's fourth-order composition at dt = 0.01 (1.3e-8).
const CHEAPEST: [Setting; 5] = [
    Setting(Method::Rk4, 0.02),
    Setting(Method::Rk4Contact, 0.06),
    Setting(Method::Rkn4Contact, 0.06),
    Setting(Method::Rkn4Contact, 0.1),
    Setting(Method::Yoshida4, 0.01),
];

#[divan::bench(args = CHEAPEST)]
fn cheapest_within_1e_7(setting: Setting) -> f64 {
    trapped(setting.0, setting.1)
}
