//! The dimensional form (paper Eq. 1, Section III) and its rescaling to the dimensionless model.
//!
//! With reference mass M (a regular site), Hertz constant a (N/m^{3/2}) and impact velocity V:
//!
//! ```text
//! L = (M V^2 / a)^{2/5}     u = L u',   t = (L / V) t'
//! eps   = m / M                                  (Eq. 4)
//! kappa = K L^{p+1} / (M V^2)                    (= K / (M^{1/5} a^{4/5} V^{2/5}) for p = 1)
//! m_n'  = M_n / M                                (per-site mass ratios)
//! ```
//!
//! The kappa formula for general p follows from the same substitution in eps v'' = K (u - v)^p.

use crate::error::ModelError;

/// Scales of one physical chain: the reference mass, contact constant and impact velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    /// Reference site mass M in kg.
    pub mass_kg: f64,
    /// Hertz contact constant a in N/m^{3/2}.
    pub hertz: f64,
    /// Impact velocity V in m/s.
    pub velocity: f64,
}

impl Scales {
    /// Validated scales: all three must be finite and > 0.
    pub fn new(mass_kg: f64, hertz: f64, velocity: f64) -> Result<Self, ModelError> {
        for (what, value) in [
            ("mass", mass_kg),
            ("contact constant a", hertz),
            ("velocity", velocity),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ModelError::NotPositive {
                    what: format!("physical {what}"),
                    value,
                });
            }
        }
        Ok(Self {
            mass_kg,
            hertz,
            velocity,
        })
    }

    /// Length scale L = (M V^2 / a)^{2/5} in metres.
    pub fn length_m(&self) -> f64 {
        (self.mass_kg * self.velocity * self.velocity / self.hertz).powf(0.4)
    }

    /// Time scale L / V in seconds: physical time = this * dimensionless time.
    pub fn time_s(&self) -> f64 {
        self.length_m() / self.velocity
    }

    /// Dimensionless mass ratio of a mass in kg.
    pub fn mass_ratio(&self, mass_kg: f64) -> f64 {
        mass_kg / self.mass_kg
    }

    /// Dimensionless coefficient of a linear dashpot c (N·s/m): c T / M.
    pub fn dashpot(&self, c: f64) -> f64 {
        c * self.time_s() / self.mass_kg
    }

    /// Dimensionless coefficient of a Hertzian dashpot γ (N·s/m^{3/2}), whose force is
    /// γ √δ δ̇: γ L^{1/2} T / M.
    pub fn hertzian_dashpot(&self, gamma: f64) -> f64 {
        gamma * self.length_m().sqrt() * self.time_s() / self.mass_kg
    }

    /// Dimensionless stiffness of a linear spring k (N/m): k T² / M.
    pub fn spring(&self, k: f64) -> f64 {
        k * self.time_s().powi(2) / self.mass_kg
    }

    /// Dimensionless coupling kappa of a spring K (N/m^p) with exponent p.
    pub fn kappa(&self, stiffness: f64, p: u32) -> f64 {
        stiffness * self.length_m().powi(p as i32 + 1)
            / (self.mass_kg * self.velocity * self.velocity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// kappa for p = 1 agrees with the paper's closed form K / (M^{1/5} a^{4/5} V^{2/5}).
    #[test]
    fn linear_kappa_matches_the_closed_form() {
        let s = Scales::new(0.866e-3, 2.47e9, 1.98).unwrap();
        let k = 3.961e6;
        let closed = k / (s.mass_kg.powf(0.2) * s.hertz.powf(0.8) * s.velocity.powf(0.4));
        assert!((s.kappa(k, 1) / closed - 1.0).abs() < 1e-12);
    }

    /// A linear spring is a p = 1 coupling, and a dashpot's force over a spring's is a rate
    /// times a time: the conversions agree with kappa and with each other.
    #[test]
    fn springs_and_dashpots_rescale_consistently() {
        let s = Scales::new(0.866e-3, 2.47e9, 1.98).unwrap();
        assert!((s.spring(3.0e5) / s.kappa(3.0e5, 1) - 1.0).abs() < 1e-12);
        // c u̇ against k u at u̇ = u / T_phys: the ratio c / (k T_phys) is unit-free.
        let (c, k, t_phys) = (40.0, 3.0e5, 1e-4);
        let dimensionless = s.dashpot(c) / (s.spring(k) * (t_phys / s.time_s()));
        assert!((dimensionless - c / (k * t_phys)).abs() < 1e-12);
        // The Hertzian dashpot at an overlap of one length scale is the linear one.
        assert!(
            (s.hertzian_dashpot(c) / s.length_m().sqrt() - s.dashpot(c)).abs()
                < 1e-12 * s.dashpot(c)
        );
    }

    /// The rescaling makes the Hertz law unit-free: a L^{1/2} T^2 / M = 1.
    #[test]
    fn time_scale_balances_hertz_law() {
        let s = Scales::new(0.866e-3, 2.47e9, 1.98).unwrap();
        let balance = s.hertz * s.length_m().sqrt() * s.time_s().powi(2) / s.mass_kg;
        assert!((balance - 1.0).abs() < 1e-12);
        assert!(Scales::new(0.0, 1.0, 1.0).is_err());
    }
}
