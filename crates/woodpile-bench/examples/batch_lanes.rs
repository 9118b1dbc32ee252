//! The batch-mode prototype: four scenes of one sweep advanced together, one per lane of an
//! AVX2 register, against the same four scenes run one after another by the scalar path
//! (which is itself vectorised along the chain, four sites per register).
//!
//! What is batched: `rkn6` (Dormand–El-Mikkawy–Prince RKN6 with its first-same-as-last reuse)
//! with contact events left to the quadrature (`ContactMode::Plain`), at a fixed step, on the
//! union of the lanes' active windows: the force loop, the stage sums and the window
//! bookkeeping, which are about four fifths of a scene's instructions (docs/performance.md,
//! "Where a scene's time goes"). Each lane does exactly the scalar path's operations in its
//! order, so its fractions must equal the scalar plain run's bit for bit: checked on every
//! batch. The contact-event correction (the rest) is not batched here; the scalar
//! `rkn6-contact` time is printed beside to show its share.
//!
//! Scenes: consecutive points of the F7 coarse grid (defects at 0 and 20, eps1 and eps2 the
//! lanes' parameters), the sweep batch mode is meant for.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example batch_lanes [-- BATCHES [DT]]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used, unsafe_code)]

use std::time::Instant;
use woodpile_bench::drive_fixed;
use woodpile_pipeline::Pipeline;
use woodpile_sim::energy::{energy_density, Fractions};
use woodpile_sim::force::hertz_force;
use woodpile_sim::integrate::{ContactMode, Rkn, RknTableau, DPRKN6};
use woodpile_sim::model::{Boundary, Coupling};
use woodpile_sim::simulation::Scenario;
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

/// Scenes per batch: the f64 lanes of an AVX2 register.
const LANES: usize = 4;
type Lanes = [f64; LANES];
const ZERO: Lanes = [0.0; LANES];
/// Stages of DPRKN6.
const S: usize = 6;
/// The scalar path's active-window margin for a six-stage method (`ActiveSites`).
const MARGIN: usize = 2 * S + 2;

/// Four scenes that share a chain and their resonators' sites, in structure-of-arrays form:
/// entry k of every vector is dof k, its four lanes the four scenes.
#[derive(Clone)]
struct Batch {
    n_sites: usize,
    fixed_ends: bool,
    /// (site, coupling per lane, eps per lane) of each resonator; all linear (p = 1).
    resonators: Vec<(usize, Lanes, Lanes)>,
    q: Vec<Lanes>,
    v: Vec<Lanes>,
    q_stage: Vec<Lanes>,
    a: [Vec<Lanes>; S],
    /// Sites any lane has moved (the scalar path's `ActiveSites`, over the union).
    moved: (usize, usize),
}

impl Batch {
    fn new(scenes: &[Scenario]) -> Option<Batch> {
        let m0 = &scenes[0].model;
        let n_sites = m0.n_sites();
        let n_dof = m0.n_dof();
        let shared = scenes.iter().all(|s| {
            let m = &s.model;
            m.n_sites() == n_sites
                && m.boundary() == m0.boundary()
                && m.resonators().len() == m0.resonators().len()
                && m.resonators()
                    .iter()
                    .zip(m0.resonators())
                    .all(|(r, r0)| r.site == r0.site && r.p == 1)
                && (0..n_sites).all(|i| m.site_mass(i) == 1.0)
                && s.impulse_site == scenes[0].impulse_site
        });
        if !shared || scenes.len() != LANES {
            return None;
        }
        let resonators = (0..m0.resonators().len())
            .map(|j| {
                let site = m0.resonators()[j].site;
                let kappa =
                    std::array::from_fn(|l| match scenes[l].model.resonators()[j].coupling {
                        Coupling::Constant(k) => k,
                        _ => f64::NAN,
                    });
                let eps = std::array::from_fn(|l| scenes[l].model.resonators()[j].eps);
                (site, kappa, eps)
            })
            .collect();
        let mut v = vec![ZERO; n_dof];
        for (l, s) in scenes.iter().enumerate() {
            v[s.impulse_site][l] = s.impulse_velocity;
        }
        let site = scenes[0].impulse_site;
        Some(Batch {
            n_sites,
            fixed_ends: m0.boundary() == Boundary::Fixed,
            resonators,
            q: vec![ZERO; n_dof],
            v,
            q_stage: vec![ZERO; n_dof],
            a: std::array::from_fn(|_| vec![ZERO; n_dof]),
            moved: (site, site),
        })
    }

    fn window(&self) -> (usize, usize) {
        (
            self.moved.0.saturating_sub(MARGIN),
            (self.moved.1 + MARGIN).min(self.n_sites - 1),
        )
    }

    fn n_dof(&self) -> usize {
        self.q.len()
    }

    /// The force loop of `Model::accelerations_impl`, lane by lane, same operations.
    #[inline(always)]
    fn accelerations(q: &[Lanes], acc: &mut [Lanes], batch: &BatchShape, (lo, hi): (usize, usize)) {
        let n = batch.n_sites;
        let (u, rv) = q.split_at(n);
        let (acc_u, acc_v) = acc.split_at_mut(n);
        let mut previous = ZERO;
        let u_w = &u[lo..=hi];
        let acc_w = &mut acc_u[lo..=hi];
        for (pair, acc) in u_w.windows(2).zip(acc_w.iter_mut()) {
            let f = lanewise(pair[0], pair[1], |a, b| {
                let d = (a - b).max(0.0);
                d * d.sqrt()
            });
            *acc = lanewise(previous, f, |p, f| p - f);
            previous = f;
        }
        acc_u[hi] = previous;
        if batch.fixed_ends {
            for l in 0..LANES {
                if lo == 0 {
                    acc_u[0][l] += hertz_force(-u[0][l]);
                }
                if hi == n - 1 {
                    acc_u[n - 1][l] -= hertz_force(u[n - 1][l]);
                }
            }
        }
        for (j, &(site, kappa, eps)) in batch.resonators.iter().enumerate() {
            if site < lo || site > hi {
                continue;
            }
            for l in 0..LANES {
                let f = kappa[l] * (u[site][l] - rv[j][l]);
                acc_u[site][l] -= f;
                acc_v[j][l] = f / eps[l];
            }
        }
    }

    /// One RKN6 step of every lane (the scalar `Rkn::raw_step` with FSAL, no contact tracking).
    #[inline(always)]
    fn step_body(&mut self, h: f64, first: bool) {
        let shape = BatchShape {
            n_sites: self.n_sites,
            fixed_ends: self.fixed_ends,
            resonators: &self.resonators,
        };
        let (lo, hi) = self.window();
        let ranges = [lo..hi + 1, self.n_sites..self.n_dof()];
        let tab: RknTableau<S> = DPRKN6;
        for i in 0..S {
            if i > 0 {
                for r in ranges.clone() {
                    let cv = tab.c[i] * h;
                    let qs = &mut self.q_stage[r.clone()];
                    for ((qs, q), v) in qs
                        .iter_mut()
                        .zip(&self.q[r.clone()])
                        .zip(&self.v[r.clone()])
                    {
                        *qs = lanewise(*q, *v, |q, v| q + cv * v);
                    }
                    for j in 0..i {
                        let w = h * h * tab.a[i][j];
                        if w != 0.0 {
                            add_scaled(qs, &self.a[j][r.clone()], w);
                        }
                    }
                }
            }
            if i == 0 && !first {
                self.a.swap(0, S - 1);
                continue;
            }
            let (qs, acc) = if i == 0 {
                (&self.q, &mut self.a[0])
            } else {
                (&self.q_stage, &mut self.a[i])
            };
            Self::accelerations(qs, acc, &shape, (lo, hi));
        }
        for r in ranges {
            self.q[r.clone()].copy_from_slice(&self.q_stage[r.clone()]);
            for i in 0..S {
                let wv = h * tab.b_prime[i];
                if wv != 0.0 {
                    add_scaled(&mut self.v[r.clone()], &self.a[i][r.clone()], wv);
                }
            }
        }
        // The window's margins are all that can have started moving.
        let moving = |k: usize| self.q[k] != ZERO || self.v[k] != ZERO;
        let new_lo = (lo..self.moved.0)
            .find(|&k| moving(k))
            .unwrap_or(self.moved.0);
        let new_hi = (self.moved.1 + 1..=hi)
            .rev()
            .find(|&k| moving(k))
            .unwrap_or(self.moved.1);
        self.moved = (new_lo, new_hi);
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn step_avx2(&mut self, h: f64, first: bool) {
        self.step_body(h, first);
    }

    fn step(&mut self, h: f64, first: bool) {
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the CPU has the features the copy was compiled for.
            unsafe { self.step_avx2(h, first) }
        } else {
            self.step_body(h, first);
        }
    }

    /// Runs every lane to `t_end` with the scalar driver's fixed-step sequence (one sample
    /// interval), and returns each lane's state `[q, q']`.
    fn run(&mut self, t_end: f64, dt: f64) -> Vec<Vec<f64>> {
        let n_steps = (t_end / dt - 1e-9).ceil().max(1.0) as u64;
        let h = t_end / n_steps as f64;
        for i in 0..n_steps {
            self.step(h, i == 0);
        }
        (0..LANES)
            .map(|l| {
                self.q
                    .iter()
                    .chain(&self.v)
                    .map(|x| x[l])
                    .collect::<Vec<f64>>()
            })
            .collect()
    }
}

/// `op` on each lane of `x` and `y`.
#[inline(always)]
fn lanewise(x: Lanes, y: Lanes, op: impl Fn(f64, f64) -> f64) -> Lanes {
    std::array::from_fn(|l| op(x[l], y[l]))
}

/// `dst += w x`, lane by lane.
#[inline(always)]
fn add_scaled(dst: &mut [Lanes], x: &[Lanes], w: f64) {
    for (d, x) in dst.iter_mut().zip(x) {
        *d = lanewise(*d, *x, |d, x| d + w * x);
    }
}

/// What the force loop needs of a batch (borrowed apart from its state).
struct BatchShape<'a> {
    n_sites: usize,
    fixed_ends: bool,
    resonators: &'a [(usize, Lanes, Lanes)],
}

fn fractions(scene: &Scenario, y: &[f64]) -> Fractions {
    let mut density = vec![0.0; scene.model.n_sites()];
    energy_density(&scene.model, scene.t_end, y, &mut density);
    Fractions::from_density(&density, scene.region)
}

/// One scalar run of `scene` by DPRKN6 in `mode` at `dt`, one sample interval; its state.
fn scalar(scene: &Scenario, mode: ContactMode, dt: f64) -> Vec<f64> {
    let mut stepper = Rkn::new(&scene.model, DPRKN6, mode);
    drive_fixed(scene, &mut stepper, (dt, scene.t_end), None)
        .unwrap()
        .0
}

/// Best of `passes` wall times of `work`, in ms.
fn best_ms(passes: usize, mut work: impl FnMut()) -> f64 {
    (0..passes)
        .map(|_| {
            let t0 = Instant::now();
            work();
            t0.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let batches: usize = args.next().map_or(8, |a| a.parse().unwrap());
    let dt: f64 = args.next().map_or(0.05, |a| a.parse().unwrap());
    let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
    let scenes: Vec<Scenario> = sampled_sweep_scenes(&pipeline, LANES * batches)
        .unwrap()
        .into_iter()
        .filter(|(name, _)| name.starts_with("F7 coarse"))
        .map(|(_, s)| s)
        .collect();
    let batches: Vec<&[Scenario]> = scenes.chunks_exact(LANES).collect();
    println!(
        "{} batches of {LANES} F7 coarse scenes, rkn6 at dt = {dt}, one thread, best of 5\n",
        batches.len()
    );
    let (mut plain_ms, mut batch_ms, mut contact_ms) = (0.0, 0.0, 0.0);
    for batch in &batches {
        let lanes = Batch::new(batch).expect("the scenes share a chain");
        let mut states = Vec::new();
        batch_ms += best_ms(5, || {
            let mut b = lanes.clone();
            states = b.run(batch[0].t_end, dt);
        });
        let mut plain = Vec::new();
        plain_ms += best_ms(5, || {
            plain = batch
                .iter()
                .map(|s| scalar(s, ContactMode::Plain, dt))
                .collect();
        });
        contact_ms += best_ms(5, || {
            for s in batch.iter() {
                std::hint::black_box(scalar(s, ContactMode::Corrected, dt));
            }
        });
        for (l, s) in batch.iter().enumerate() {
            let (fb, fs) = (fractions(s, &states[l]), fractions(s, &plain[l]));
            assert!(
                fb == fs,
                "lane {l} differs from the scalar run: {fb:?} vs {fs:?}"
            );
        }
    }
    let n = scenes.len() as f64;
    println!("| path | ms per scene | scalar plain / this |");
    println!("|---|---|---|");
    for (label, ms) in [
        (
            "scalar rkn6, plain (one scene at a time, vectorised along the chain)",
            plain_ms,
        ),
        ("batched rkn6, plain (four scenes in the lanes)", batch_ms),
        (
            "scalar rkn6-contact (auto's method, events corrected)",
            contact_ms,
        ),
    ] {
        println!("| {label} | {:.3} | {:.2} |", ms / n, plain_ms / ms);
    }
    println!("\nEvery lane's fractions equal the scalar plain run's, bit for bit.");
}
