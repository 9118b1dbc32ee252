//! `cargo bench -p woodpile-bench`: the standard scene (N = 100, one defect eps = 10, t = 150)
//! by the methods and steps that reach |ΔE_tr| <= 1e-7, with and without the active window.
#![allow(clippy::unwrap_used)]

use woodpile_bench::{fixed, run};
use woodpile_sim::integrate::{Method, MethodChoice, Plan};
use woodpile_sim::run::run_with_plan;
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

/// RK4 at dt = 0.02 (|ΔE_tr| = 6.4e-8): the cheapest RK4 within 1e-7.
#[divan::bench]
fn rk4_dt_0_02() -> f64 {
    trapped(Method::Rk4, 0.02)
}

/// RK4 with exact contact events at dt = 0.06 (|ΔE_tr| = 3.4e-8): the cheapest setting
/// within 1e-7.
#[divan::bench]
fn rk4_contact_dt_0_06() -> f64 {
    trapped(Method::Rk4Contact, 0.06)
}

/// Nyström's three-stage method with exact contact events at dt = 0.06 (|ΔE_tr| = 2.2e-9):
/// three force evaluations per step instead of four.
#[divan::bench]
fn rkn4_contact_dt_0_06() -> f64 {
    trapped(Method::Rkn4Contact, 0.06)
}

/// The same at dt = 0.1 (|ΔE_tr| = 4.4e-8; R and T are off by 2e-6 there): the issue's
/// 2 ms setting.
#[divan::bench]
fn rkn4_contact_dt_0_1() -> f64 {
    trapped(Method::Rkn4Contact, 0.1)
}

/// Yoshida's fourth-order composition at dt = 0.01 (|ΔE_tr| = 1.3e-8).
#[divan::bench]
fn yoshida4_dt_0_01() -> f64 {
    trapped(Method::Yoshida4, 0.01)
}
