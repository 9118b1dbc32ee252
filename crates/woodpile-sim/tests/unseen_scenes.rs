//! `auto` on scenes no calibration chose: one scene of each sweep kind (F4, F5, F6, F7 coarse,
//! F7 fine) drawn from the sweeps' grids by a fixed seed (`testing::sampled_sweep_scenes`), each
//! against a reference of its own (`rk4-contact` at dt = 0.001, 0.00025 for a nonlinear
//! resonator: 20 to 40 times finer than auto's steps at 1e-6). The larger survey behind the README's table is
//! `cargo run --release -p woodpile-bench --example auto_accuracy -- 1e-6 --survey 8`.
#![allow(clippy::unwrap_used)]

use woodpile_sim::integrate::MethodChoice;
use woodpile_sim::run::simulate;
use woodpile_sim::testing::{
    paper_scene, reference_dt, reference_fractions, sampled_sweep_scenes, tolerance,
};

#[test]
fn auto_meets_its_tolerance_on_sampled_sweep_scenes() {
    let tol = 1e-6;
    for (label, defects) in sampled_sweep_scenes(1) {
        let scene = paper_scene(&defects, MethodChoice::Auto, tolerance(tol));
        let reference = reference_fractions(&scene, reference_dt(&scene.model)).unwrap();
        let out = simulate(&scene, &mut ()).unwrap();
        let error = out.fractions.largest_difference(&reference);
        assert!(
            error <= tol,
            "{label}: auto is off by {error:.1e} at tolerance {tol:.0e}"
        );
        // The estimate auto reports is an estimate of this error, not a bound, but it must be
        // of its size: a report of 1e-9 for an error of 1e-6 would mislead.
        let estimate = out.error_estimate.unwrap();
        assert!(
            error <= 10.0 * estimate.max(1e-9),
            "{label}: error {error:.1e} against an estimate of {estimate:.1e}"
        );
    }
}
