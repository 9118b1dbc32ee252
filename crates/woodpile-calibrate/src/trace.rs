//! A measured trace: velocities of rods at times, in SI, as a lab's probe records them.

/// Velocities of rods at times: row i is rod `rod[i]` (its paper site) moving at
/// `velocity[i]` m/s at `t[i]` s after the impact.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    /// Seconds after the impact (the simulation's t = 0).
    pub t: Vec<f64>,
    /// Paper site numbers.
    pub rod: Vec<i64>,
    /// Measured velocities, m/s.
    pub velocity: Vec<f64>,
    /// Each row's standard deviation, m/s, if known: residuals are divided by it (weighted
    /// least squares). Without it every row weighs alike.
    pub sigma: Option<Vec<f64>>,
}

impl Trace {
    /// Checks the columns agree in length and hold finite numbers, times ≥ 0 and sigmas > 0.
    /// The reason names the column and row.
    pub fn check(&self) -> Result<(), String> {
        let n = self.t.len();
        if n == 0 {
            return Err("the trace has no rows".into());
        }
        if self.rod.len() != n || self.velocity.len() != n {
            return Err(format!(
                "columns t, rod and velocity have {n}, {} and {} rows: they must have as many",
                self.rod.len(),
                self.velocity.len()
            ));
        }
        if let Some(i) = self.t.iter().position(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err(format!(
                "t at row {i} is {}: times are seconds ≥ 0",
                self.t[i]
            ));
        }
        if let Some(i) = self.velocity.iter().position(|v| !v.is_finite()) {
            return Err(format!("velocity at row {i} is {}", self.velocity[i]));
        }
        if let Some(sigma) = &self.sigma {
            if sigma.len() != n {
                return Err(format!("column sigma has {} rows, not {n}", sigma.len()));
            }
            if let Some(i) = sigma.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
                return Err(format!("sigma at row {i} is {}: it must be > 0", sigma[i]));
            }
        }
        Ok(())
    }

    /// The lowest and highest rod.
    pub fn rods(&self) -> (i64, i64) {
        let lo = self.rod.iter().copied().min().unwrap_or(0);
        let hi = self.rod.iter().copied().max().unwrap_or(0);
        (lo, hi)
    }

    /// The probe's spacing: the smallest gap between distinct times of one rod (rods may be
    /// recorded at offset times, whose gaps across rods say nothing of the probe). The
    /// simulation samples a fraction of it ([`crate::prediction`]).
    pub fn spacing(&self) -> f64 {
        // Every row as (rod, time), sorted once: a rod's gaps are then its neighbours'.
        let mut rows: Vec<(i64, f64)> = self
            .rod
            .iter()
            .copied()
            .zip(self.t.iter().copied())
            .collect();
        rows.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let smallest = rows
            .windows(2)
            .filter(|w| w[0].0 == w[1].0 && w[1].1 > w[0].1)
            .map(|w| w[1].1 - w[0].1)
            .fold(f64::INFINITY, f64::min);
        match smallest.is_finite() {
            true => smallest,
            // One time a rod: sample at the earliest.
            false => self
                .t
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
                .max(f64::MIN_POSITIVE),
        }
    }

    /// The last time.
    pub fn end(&self) -> f64 {
        self.t.iter().copied().fold(0.0, f64::max)
    }

    /// Each row's weight, 1/σ (1 without σ).
    pub fn weights(&self) -> Vec<f64> {
        match &self.sigma {
            Some(sigma) => sigma.iter().map(|s| 1.0 / s).collect(),
            None => vec![1.0; self.t.len()],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two rods recorded every 2 µs, one 1 ns after the other: the probe's spacing is 2 µs,
    /// not the nanosecond between the rods.
    #[test]
    fn the_spacing_is_one_rods_own() {
        let t: Vec<f64> = (1..=5)
            .flat_map(|k| [k as f64 * 2e-6, k as f64 * 2e-6 + 1e-9])
            .collect();
        let rod = (0..10).map(|i| i % 2).collect();
        let trace = Trace {
            velocity: vec![0.0; t.len()],
            t,
            rod,
            sigma: None,
        };
        assert!(
            (trace.spacing() - 2e-6).abs() < 1e-15,
            "{}",
            trace.spacing()
        );
    }
}
