//! A measured lever for damped chains, kept so that its numbers can be measured again
//! (docs/methods.md, "A higher-order method with the same events"): Butcher's seven-stage
//! explicit Runge–Kutta method of order 6 in first-order form, with `rk4-contact`'s contact
//! events (its quadrature made of the tableau's weights) and switch location, for chains whose
//! forces depend on velocities. Not a method a scene can name: at equal force evaluations it is
//! no more accurate than `rk4-contact` on a contact dashpot, whose events set the error.

use super::stage_step::{stage_accelerations, FixedStepScratch};
use super::switches::{self, Staged};
use super::{drive, DriveConfig, StepControl, StepOutcome, StepSpan, Stepper, MAX_STEPS};
use crate::energy::Fractions;
use crate::error::SimError;
use crate::model::Model;
use crate::simulation::{end_fractions, struck, Scenario};

const S: usize = 7;
const C: [f64; S] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0, 0.5, 0.5, 1.0];
const A: [[f64; S]; S] = [
    [0.0; S],
    [1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 2.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0, 0.0, 0.0, 0.0, 0.0],
    [
        -1.0 / 16.0,
        9.0 / 8.0,
        -3.0 / 16.0,
        -3.0 / 8.0,
        0.0,
        0.0,
        0.0,
    ],
    [0.0, 9.0 / 8.0, -3.0 / 8.0, -3.0 / 4.0, 0.5, 0.0, 0.0],
    [
        9.0 / 44.0,
        -9.0 / 11.0,
        63.0 / 44.0,
        18.0 / 11.0,
        0.0,
        -16.0 / 11.0,
        0.0,
    ],
];
const B: [f64; S] = [
    11.0 / 120.0,
    0.0,
    27.0 / 40.0,
    27.0 / 40.0,
    -4.0 / 15.0,
    -4.0 / 15.0,
    11.0 / 120.0,
];

/// b̄_j = Σ_i b_i a_ij: the weight of stage j's force in the position change h² Σ b̄_j F_j.
const fn b_bar() -> [f64; S] {
    let mut out = [0.0; S];
    let mut j = 0;
    while j < S {
        let mut i = 0;
        while i < S {
            out[j] += B[i] * A[i][j];
            i += 1;
        }
        j += 1;
    }
    out
}
const B_BAR: [f64; S] = b_bar();

/// What the method's weights make of a bond's seven stage forces.
fn rk6_quadrature(f: [f64; S], h: f64) -> (f64, f64) {
    let (mut impulse, mut moment) = (0.0, 0.0);
    for ((b, b_bar), f) in B.iter().zip(&B_BAR).zip(f) {
        impulse += b * f;
        moment += b_bar * f;
    }
    (h * impulse, h * h * moment)
}

/// The fractions `stepper` ends `scenario` with at the fixed step `dt`, and the force
/// evaluations it spent: a stepper no [`crate::integrate::Plan`] makes, run by the same driver.
pub fn run_fixed_step(
    scenario: &Scenario,
    stepper: &mut dyn Stepper,
    dt: f64,
) -> Result<(Fractions, u64), SimError> {
    let (mut y, e_initial) = struck(scenario)?;
    let cfg = DriveConfig {
        t_end: scenario.t_end,
        sample_every: scenario.sample_every,
        control: StepControl::Fixed { dt },
        max_steps: MAX_STEPS,
        energy_drift_limit: None,
        active_window: true,
    };
    let stats = drive(&scenario.model, stepper, &mut y, &cfg, &mut ())?;
    let (fractions, _) = end_fractions(scenario, &y, e_initial);
    Ok((fractions, stats.rhs_evals))
}

/// Butcher's RK6 with `rk4-contact`'s events and switch location.
#[derive(Debug, Clone)]
pub struct Rk6Contact {
    scratch: FixedStepScratch<S>,
    v_stage: Vec<f64>,
    kv: Vec<Vec<f64>>,
    ka: Vec<Vec<f64>>,
    power: [f64; S],
}

impl Rk6Contact {
    /// A stepper for states of `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.n_dof();
        Self {
            scratch: FixedStepScratch::new(model, ["rk6-contact"; 2], Some(rk6_quadrature)),
            v_stage: vec![0.0; n],
            kv: vec![vec![0.0; n]; S],
            ka: vec![vec![0.0; n]; S],
            power: [0.0; S],
        }
    }

    /// The seven stages from `y` over `span`, the new state (uncorrected) left in the
    /// scratch's `y_new`.
    fn seven_stages(&mut self, model: &Model, y: &[f64], span: StepSpan) {
        let StepSpan { t, h, window } = span;
        let n = model.n_dof();
        let (q, v) = y.split_at(n);
        let v = &v[..n];
        let ranges = window.dof_ranges(model);
        let s = &mut self.scratch;
        s.q_stage.copy_from_slice(q);
        self.v_stage.copy_from_slice(v);
        for i in 0..S {
            if i > 0 {
                for r in ranges.clone() {
                    for e in r {
                        let (mut dq, mut dv) = (0.0, 0.0);
                        for (j, a) in A[i][..i].iter().enumerate() {
                            dq += a * self.kv[j][e];
                            dv += a * self.ka[j][e];
                        }
                        s.q_stage[e] = q[e] + h * dq;
                        self.v_stage[e] = v[e] + h * dv;
                    }
                }
            }
            for r in ranges.clone() {
                self.kv[i][r.clone()].copy_from_slice(&self.v_stage[r]);
            }
            self.power[i] = stage_accelerations(
                model,
                s.contact.as_mut(),
                (&s.q_stage, &self.v_stage, &mut self.ka[i]),
                (t + C[i] * h, i),
                window,
            );
        }
        let (new_q, new_v) = s.y_new.split_at_mut(n);
        for r in ranges {
            for e in r {
                let (mut dq, mut dv) = (0.0, 0.0);
                for (i, b) in B.iter().enumerate() {
                    dq += b * self.kv[i][e];
                    dv += b * self.ka[i][e];
                }
                new_q[e] = q[e] + h * dq;
                new_v[e] = v[e] + h * dv;
            }
        }
        if model.is_dissipative() {
            let d = B.iter().zip(&self.power).fold(0.0, |d, (b, p)| d + b * p);
            new_v[n] = model.dissipated(y) + h * d;
        }
        s.evals += S as u64;
    }
}

impl Staged<S> for Rk6Contact {
    fn stages(&mut self, model: &Model, y: &[f64], span: StepSpan) {
        self.seven_stages(model, y, span);
    }

    fn scratch(&mut self) -> &mut FixedStepScratch<S> {
        &mut self.scratch
    }
}

impl Stepper for Rk6Contact {
    fn name(&self) -> &'static str {
        self.scratch.name()
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        switches::step(self, model, y, span)
    }

    fn reach(&self) -> usize {
        S
    }

    fn rhs_evals(&self) -> u64 {
        self.scratch.evals
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::energy::Region;
    use crate::integrate::MethodChoice;
    use crate::model::{Boundary, Resonator};
    use crate::testing::{fitted_order, fixed_dt};
    use crate::{Damping, DashpotLaw};

    /// One site with a damped resonator: the stretch x = u − v obeys μ x'' + c x' + κ x = 0
    /// from x = 0, x' = 1 (μ = ε / (1 + ε)), so D(t) is the relative motion's energy lost,
    /// ½ μ − (½ μ x'² + ½ κ x²), over the impulse's ½. The method meets it to its order, 6.
    #[test]
    fn a_damped_resonator_rings_down_at_order_six() {
        let (eps, kappa, c, t_end): (f64, f64, f64, f64) = (0.5, 2.0, 0.1, 7.5);
        let mu = eps / (1.0 + eps);
        let omega = (kappa / mu).sqrt();
        let zeta = c / (2.0 * mu * omega);
        let damped = omega * (1.0 - zeta * zeta).sqrt();
        let decay = (-zeta * omega * t_end).exp();
        let x = decay * (damped * t_end).sin() / damped;
        let x_dot =
            decay * ((damped * t_end).cos() - zeta * omega / damped * (damped * t_end).sin());
        let expected = (0.5 * mu - 0.5 * mu * x_dot * x_dot - 0.5 * kappa * x * x) / 0.5;
        let model = Model::new(
            1,
            Boundary::Free,
            vec![Resonator::constant(0, eps, kappa, 1)],
        )
        .unwrap()
        .with_damping(Damping::new(0.0, DashpotLaw::Linear, 0.0, vec![c]).unwrap())
        .unwrap();
        let scenario = Scenario {
            model,
            impulse_site: 0,
            impulse_velocity: 1.0,
            t_end,
            region: Region::new(0, 0, 1).unwrap(),
            // `run_fixed_step` reads neither: it runs the stepper it is given at its own step.
            method: MethodChoice::Auto,
            accuracy: fixed_dt(0.1),
            sample_every: t_end,
        };
        let error = |dt: f64| {
            let mut stepper = Rk6Contact::new(&scenario.model);
            let (f, _) = run_fixed_step(&scenario, &mut stepper, dt).unwrap();
            (f.dissipated - expected).abs()
        };
        let dts = [0.04, 0.02, 0.01];
        let errors: Vec<f64> = dts.iter().map(|&dt| error(dt)).collect();
        let order = fitted_order(&dts, &errors);
        assert!(order > 5.5 && order < 6.5, "order {order}: {errors:?}");
        assert!(errors[2] < 1e-12, "{errors:?}");
    }

    /// The quadrature is the tableau's: a force s^k over a unit step gets its impulse
    /// ∫ s^k ds for k ≤ 5 and its moment ∫ (1 − s) s^k ds for k ≤ 4 exactly.
    #[test]
    fn the_quadrature_integrates_polynomials_to_the_methods_order() {
        for k in 0..=5 {
            let forces = C.map(|c| c.powi(k));
            let (impulse, moment) = rk6_quadrature(forces, 1.0);
            let k = f64::from(k);
            assert!(
                (impulse - 1.0 / (k + 1.0)).abs() < 1e-15,
                "impulse, k = {k}"
            );
            if k <= 4.0 {
                let exact = 1.0 / ((k + 1.0) * (k + 2.0));
                assert!((moment - exact).abs() < 1e-15, "moment, k = {k}");
            }
        }
    }

    /// Two beads collide through a Hertz contact with a linear dashpot: the contact's events
    /// and its located steps run, and the shares meet `rk4-contact`'s at dt = 1e-4, no further
    /// off than `rk4-contact`'s at the same step.
    #[test]
    fn a_damped_collision_meets_a_finer_rk4_contact() {
        let model = Model::new(2, Boundary::Free, vec![])
            .unwrap()
            .with_damping(Damping::new(0.1, DashpotLaw::Linear, 0.0, vec![]).unwrap())
            .unwrap();
        let scenario = Scenario {
            model,
            impulse_site: 0,
            impulse_velocity: 1.0,
            t_end: 6.0,
            region: Region::new(1, 1, 2).unwrap(),
            method: MethodChoice::Named(crate::integrate::Method::Rk4Contact),
            accuracy: fixed_dt(1e-4),
            sample_every: 6.0,
        };
        let reference = crate::simulation::simulate(&scenario, &mut ())
            .unwrap()
            .fractions;
        assert!(reference.dissipated > 0.05, "{reference:?}");
        let error = |dt: f64| {
            let mut stepper = Rk6Contact::new(&scenario.model);
            let (f, _) = run_fixed_step(&scenario, &mut stepper, dt).unwrap();
            f.largest_difference(&reference)
        };
        let rk4 = |dt: f64| {
            let at = Scenario {
                accuracy: fixed_dt(dt),
                ..scenario.clone()
            };
            let out = crate::simulation::simulate(&at, &mut ()).unwrap();
            out.fractions.largest_difference(&reference)
        };
        // A collision's events make both converge unevenly (1e-6 to 5e-9 over dt = 0.04 to
        // 0.0025 for both); from dt = 0.01 on, the sixth-order method is the closer.
        for dt in [0.01, 0.005] {
            let (six, four) = (error(dt), rk4(dt));
            assert!(
                six <= four && six < 2e-8,
                "dt = {dt}: {six:e} against {four:e}"
            );
        }
    }
}
