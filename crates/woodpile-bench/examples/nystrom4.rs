//! The two Nyström-4 steppers side by side on the standard scene (dt = 0.02, t = 150, active
//! window, contact events corrected): the hand-written `Rkn4` that `rkn4-contact` runs, and
//! the tableau stepper `Rkn<3>` with `NYSTROM4`. Best of 15 runs each, one thread, and the
//! largest difference of their end states.
//!
//! `cargo run --release -p woodpile-bench --example nystrom4`
#![allow(clippy::unwrap_used, clippy::print_stdout)]

use std::time::Instant;

use woodpile_bench::{drive_fixed, fixed};
use woodpile_sim::integrate::{ContactMode, Method, Rkn, Rkn4, Stepper, NYSTROM4};

fn run(stepper: &mut dyn Stepper) -> (f64, Vec<f64>) {
    let scene = fixed(Method::Rkn4Contact, 0.02);
    let start = Instant::now();
    let (y, _) = drive_fixed(&scene, stepper, (0.02, 1.0), None).unwrap();
    (start.elapsed().as_secs_f64() * 1e3, y)
}

fn main() {
    let scene = fixed(Method::Rkn4Contact, 0.02);
    let model = &scene.model;
    let (mut hand_ms, mut tableau_ms) = (f64::INFINITY, f64::INFINITY);
    let (mut hand_y, mut tableau_y) = (Vec::new(), Vec::new());
    for _ in 0..15 {
        let (ms, y) = run(&mut Rkn4::with_contact_events(model));
        (hand_ms, hand_y) = (hand_ms.min(ms), y);
        let (ms, y) = run(&mut Rkn::new(model, NYSTROM4, ContactMode::Corrected));
        (tableau_ms, tableau_y) = (tableau_ms.min(ms), y);
    }
    let largest = hand_y
        .iter()
        .zip(&tableau_y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("hand-written Rkn4:      {hand_ms:.2} ms");
    println!(
        "Rkn<3> with NYSTROM4:   {tableau_ms:.2} ms ({:.2}x)",
        tableau_ms / hand_ms
    );
    println!("largest state difference: {largest:.1e}");
}
