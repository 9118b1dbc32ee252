//! A resonator (paper Eq. 3, 7, 14): its site, mass ratio, coupling kappa (constant or a tanh
//! ramp) and exponent p, and the frequencies its pair with the host vibrates at.

/// The resonator coupling strength kappa, constant or switched on by a tanh ramp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Coupling {
    /// kappa(t) = kappa.
    Constant(f64),
    /// kappa(t) = k1 + (k2 - k1) (1 + tanh((t - t0)/tau)) / 2 (paper Eq. 14).
    Ramp {
        /// Value long before t0.
        k1: f64,
        /// Value long after t0.
        k2: f64,
        /// Centre of the ramp.
        t0: f64,
        /// Width of the ramp (> 0).
        tau: f64,
    },
}

impl Coupling {
    /// kappa at time `t`.
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Coupling::Constant(k) => k,
            Coupling::Ramp { k1, k2, t0, tau } => {
                k1 + (k2 - k1) * 0.5 * (1.0 + ((t - t0) / tau).tanh())
            }
        }
    }

    /// Whether kappa depends on time (the energy is then not conserved).
    pub fn is_time_dependent(&self) -> bool {
        matches!(self, Coupling::Ramp { k1, k2, .. } if k1 != k2)
    }

    /// The largest value kappa takes over all times.
    pub fn max_value(&self) -> f64 {
        match *self {
            Coupling::Constant(k) => k,
            Coupling::Ramp { k1, k2, .. } => k1.max(k2),
        }
    }
}

/// One internal resonator: a mass `eps` attached to site `site` by the force
/// `kappa(t) (u_site - v)^p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resonator {
    /// Host site (0-based internal index).
    pub site: usize,
    /// Mass ratio eps = m / M (Eq. 4), > 0.
    pub eps: f64,
    /// Coupling strength kappa(t) >= 0.
    pub coupling: Coupling,
    /// Coupling exponent: 1 (linear) or odd >= 3 (nonlinear, Section IV.B).
    pub p: u32,
}

impl Resonator {
    /// A resonator at `site` of mass ratio `eps`, coupled with the constant strength `kappa`
    /// and exponent `p`.
    pub fn constant(site: usize, eps: f64, kappa: f64, p: u32) -> Resonator {
        Resonator {
            site,
            eps,
            coupling: Coupling::Constant(kappa),
            p,
        }
    }

    /// Linear angular frequency of the host (mass `host_mass`) and resonator pair vibrating
    /// against each other: omega^2 = kappa (1/m + 1/eps), at the largest kappa the coupling takes.
    /// For p > 1 this is the frequency at unit stretch, a scale rather than a constant.
    pub fn linear_omega(&self, host_mass: f64) -> f64 {
        (self.coupling.max_value() * (1.0 / host_mass + 1.0 / self.eps)).sqrt()
    }

    /// The fastest the pair can vibrate in a motion of total energy `energy`. For p = 1 this
    /// is [`Resonator::linear_omega`]. For p > 1 the stiffness p kappa a^(p-1) grows with the
    /// stretch a, and a is bounded by the energy: kappa a^(p+1) / (p+1) <= energy. So this is
    /// the stiffness at that largest stretch: a bound the run cannot exceed.
    pub fn omega_within(&self, host_mass: f64, energy: f64) -> f64 {
        if self.p == 1 {
            return self.linear_omega(host_mass);
        }
        let kappa = self.coupling.max_value();
        if kappa <= 0.0 {
            return 0.0;
        }
        let p = f64::from(self.p);
        let stretch = ((p + 1.0) * energy / kappa).powf(1.0 / (p + 1.0));
        (p * kappa * stretch.powf(p - 1.0) * (1.0 / host_mass + 1.0 / self.eps)).sqrt()
    }
}

/// `x^p` for the odd coupling exponents (p = 1 is the common case and skips `powi`).
#[inline(always)]
pub fn odd_power(x: f64, p: u32) -> f64 {
    match p {
        1 => x,
        3 => x * x * x,
        _ => x.powi(p as i32),
    }
}
