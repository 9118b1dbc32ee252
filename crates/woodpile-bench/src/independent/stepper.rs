//! DOP853 over the reference's own right-hand side, with every contact switch located: a step
//! that ends with a bond in another [`Mode`] is taken again, shorter, until it ends within a
//! few ulps of the earliest switch. Each step then integrates one smooth right-hand side, and
//! the error control meets the tolerance across every onset, the √c of a Hertzian law and the
//! jump of a linear dashpot included.

use super::chain::{Chain, Mode};
use woodpile_sim::integrate::DOP853_TABLEAU as TABLEAU;

/// The step's stages and scratch, sized once.
pub struct Stepper<'a> {
    chain: &'a Chain,
    rtol: f64,
    stages: Vec<Vec<f64>>,
    stage_state: Vec<f64>,
    /// Right-hand sides evaluated so far.
    pub evals: u64,
}

/// What one trial step gave: its length, the new state and its error norm (accept at ≤ 1).
struct Trial {
    h: f64,
    y: Vec<f64>,
    error: f64,
}

impl Trial {
    /// Whether the step meets the tolerance (a NaN error does not).
    fn passes(&self) -> bool {
        self.error <= 1.0
    }

    /// What the next step's length is this one's times: DOP853's controller, below 1 after a
    /// rejection.
    fn factor(&self) -> f64 {
        match self.error {
            e if e.is_nan() => 0.2,
            0.0 => 10.0,
            e if self.passes() => (0.9 * e.powf(-0.125)).clamp(0.2, 10.0),
            e => (0.9 * e.powf(-0.125)).clamp(0.2, 0.9),
        }
    }
}

/// How the integration went.
#[derive(Debug, Clone, Copy, Default)]
pub struct Counts {
    /// Accepted steps, those ending at a switch included.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Located switches (several bonds switching at once count once).
    pub switches: u64,
    /// Right-hand sides evaluated.
    pub evals: u64,
}

/// The most right-hand sides one reference run may take before it is called failed.
const EVAL_BUDGET: u64 = 2_000_000_000;

impl<'a> Stepper<'a> {
    /// A stepper for `chain` with relative and absolute tolerance `rtol`.
    pub fn new(chain: &'a Chain, rtol: f64) -> Self {
        let len = chain.state_len();
        Stepper {
            chain,
            rtol,
            stages: vec![vec![0.0; len]; TABLEAU.b.len()],
            stage_state: vec![0.0; len],
            evals: 0,
        }
    }

    /// One DOP853 step of `h` from `(t, y)` with the bonds held in `modes`.
    fn trial(&mut self, t: f64, y: &[f64], h: f64, modes: &[Mode]) -> Trial {
        for i in 0..self.stages.len() {
            self.stage_state.copy_from_slice(y);
            for (j, a) in TABLEAU.a[i].iter().enumerate() {
                for (s, k) in self.stage_state.iter_mut().zip(&self.stages[j]) {
                    *s += h * a * k;
                }
            }
            let mut k = std::mem::take(&mut self.stages[i]);
            self.chain
                .derivative(t + TABLEAU.c[i] * h, &self.stage_state, modes, &mut k);
            self.stages[i] = k;
        }
        self.evals += self.stages.len() as u64;
        let (mut err5, mut err3) = (0.0, 0.0);
        let mut next = y.to_vec();
        for (c, y_next) in next.iter_mut().enumerate() {
            let (mut inc, mut e5, mut e3) = (0.0, 0.0, 0.0);
            for (s, k) in self.stages.iter().enumerate() {
                inc += TABLEAU.b[s] * k[c];
                e5 += TABLEAU.e5[s] * k[c];
                e3 += TABLEAU.e3[s] * k[c];
            }
            *y_next = y[c] + h * inc;
            let scale = self.rtol * (1.0 + y[c].abs().max(y_next.abs()));
            err5 += (e5 / scale).powi(2);
            err3 += (e3 / scale).powi(2);
        }
        // The larger of the two embedded estimates, not DOP853's blend of them, which damps
        // the 5th-order estimate where the 3rd-order one is large: near a Hertzian onset,
        // where the force grows as a power of the time since it, that blend let the steps
        // through with errors a hundred times the tolerance (seen as a reference that moved
        // by 1e-7 between rtol 1e-13 and 1e-14 on a 2,000-switch chain).
        let error = h.abs() * (err5.max(err3) / y.len() as f64).sqrt();
        Trial { h, y: next, error }
    }

    /// Integrates `y` from 0 to `t_end`, locating every switch.
    pub fn run(&mut self, y: &mut Vec<f64>, t_end: f64) -> Result<Counts, String> {
        let chain = self.chain;
        let mut counts = Counts::default();
        let mut modes = Vec::new();
        chain.modes_at(y, &chain.all_open(), &mut modes);
        let mut after = Vec::new();
        let (mut t, mut h) = (0.0, 1e-3_f64.min(t_end));
        while t < t_end {
            h = h.min(t_end - t);
            let trial = self.trial(t, y, h, &modes);
            if !trial.passes() {
                counts.rejected += 1;
                h *= trial.factor();
                if h < 1e-15 * t.max(1.0) {
                    return Err(format!("the step fell to {h:.1e} at t = {t}"));
                }
                continue;
            }
            chain.modes_at(&trial.y, &modes, &mut after);
            let taken = match after == modes {
                true => trial,
                false => {
                    let switch = self.step_to_switch(t, y, h, &modes);
                    // The switch may end where the old mode's force is singular (a Hertzian
                    // contact opening): the shortened step must pass the error check too.
                    if !switch.passes() {
                        counts.rejected += 1;
                        h = switch.h * switch.factor();
                        continue;
                    }
                    counts.switches += 1;
                    chain.modes_at(&switch.y, &modes, &mut after);
                    switch
                }
            };
            modes.clone_from(&after);
            t += taken.h;
            h = taken.h * taken.factor();
            *y = taken.y;
            counts.steps += 1;
            if self.evals > EVAL_BUDGET {
                return Err(format!("over {EVAL_BUDGET} evaluations at t = {t}"));
            }
        }
        counts.evals = self.evals;
        Ok(counts)
    }

    /// The shortest step from `(t, y)` after which some bond has left its mode, found by
    /// bisection within (0, `h`].
    fn step_to_switch(&mut self, t: f64, y: &[f64], h: f64, modes: &[Mode]) -> Trial {
        let (mut before, mut after) = (0.0, h);
        let mut at_after = None;
        let mut probe = Vec::new();
        let resolution = 4.0 * f64::EPSILON * t.max(1.0);
        while after - before > resolution {
            let mid = 0.5 * (before + after);
            let trial = self.trial(t, y, mid, modes);
            self.chain.modes_at(&trial.y, modes, &mut probe);
            match probe == modes {
                true => before = mid,
                false => {
                    after = mid;
                    at_after = Some(trial);
                }
            }
        }
        at_after.unwrap_or_else(|| self.trial(t, y, after, modes))
    }
}
