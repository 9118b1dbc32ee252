//! What an experimenter cuts, in SI units: the masses, Hertz coefficients and bending modes of
//! rods and spheres (the paper's Model section, generalised).
//!
//! - A rod's mass is ρ π d²/4 L.
//! - Two crossed rods (axes at 90°) touch through a Hertz contact F = a δ^{3/2}. For equal
//!   rods of one material a = 2E√R / (3(1−ν²)), R = d/2. In general the contact of two bodies
//!   with principal relative radii R′ and R″ is elliptical, and a follows from Hertz's solution
//!   with complete elliptic integrals (Johnson, *Contact Mechanics*, 1985, §3.4; Hertz 1882):
//!   [`hertz_coefficient`]. Crossed rods have R′ = R₁, R″ = R₂; a sphere of radius R_s on a rod
//!   of radius R_c has R′ = R_s (along the rod) and 1/R″ = 1/R_s + 1/R_c (across it).
//! - A defect rod's first free-free bending mode, from Timoshenko beam theory (rotary inertia
//!   and shear; Timoshenko 1921, Huang 1961) with Cowper's shear coefficient for a solid
//!   circle, k = 6(1+ν)/(7+6ν) (Cowper 1966): [`free_free_bending_frequency`]. For the paper's
//!   fused-quartz rods (d = 5 mm) it gives 55.8 kHz at L = 20 mm and 15.3 kHz at 40 mm, where
//!   Euler–Bernoulli theory gives 63.7 and 15.9 kHz (tests below).

use std::f64::consts::PI;

/// An isotropic elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E in Pa.
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Density ρ in kg/m³.
    pub density: f64,
}

impl Material {
    /// The contact modulus E/(1−ν²) of one body: two bodies combine as
    /// 1/E* = 1/E₁′ + 1/E₂′.
    pub fn plane_strain_modulus(&self) -> f64 {
        self.youngs_modulus / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }
}

/// A circular rod.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rod {
    /// Length L in m.
    pub length: f64,
    /// Diameter d in m.
    pub diameter: f64,
    /// What it is made of.
    pub material: Material,
}

impl Rod {
    /// ρ π d²/4 L, in kg.
    pub fn mass(&self) -> f64 {
        self.material.density * self.area() * self.length
    }

    fn area(&self) -> f64 {
        PI * self.diameter * self.diameter / 4.0
    }
}

/// The combined contact modulus E* of two materials.
pub fn contact_modulus(a: &Material, b: &Material) -> f64 {
    1.0 / (1.0 / a.plane_strain_modulus() + 1.0 / b.plane_strain_modulus())
}

/// The Hertz coefficient a of two crossed rods (axes at 90°), in N/m^{3/2}.
pub fn crossed_rods_coefficient(one: &Rod, other: &Rod) -> f64 {
    hertz_coefficient(
        one.diameter / 2.0,
        other.diameter / 2.0,
        contact_modulus(&one.material, &other.material),
    )
}

/// The Hertz coefficient a of a sphere of diameter `diameter` and material `material` striking a
/// rod across its axis, in N/m^{3/2}.
pub fn sphere_on_rod_coefficient(diameter: f64, material: &Material, rod: &Rod) -> f64 {
    let (sphere, cylinder) = (diameter / 2.0, rod.diameter / 2.0);
    let across = 1.0 / (1.0 / sphere + 1.0 / cylinder);
    hertz_coefficient(sphere, across, contact_modulus(material, &rod.material))
}

/// A sphere's mass ρ π D³/6, in kg.
pub fn sphere_mass(diameter: f64, material: &Material) -> f64 {
    material.density * PI * diameter.powi(3) / 6.0
}

/// The coefficient a in F = a δ^{3/2} of two bodies whose principal relative radii of curvature
/// are `r1` and `r2` (m), with contact modulus `modulus` E* (Pa). Circular contact (r1 = r2 = R):
/// a = (4/3) E* √R. Otherwise the contact ellipse's eccentricity e solves
/// R′/R″ = (E(e)/(1−e²) − K(e)) / (K(e) − E(e)) (complete elliptic integrals of modulus e², by
/// bisection), and a = (2π/3) E* / K(e) · √(2 R′ (K − E) / (K e²)).
pub fn hertz_coefficient(r1: f64, r2: f64, modulus: f64) -> f64 {
    let (large, small) = (r1.max(r2), r1.min(r2));
    let ratio = large / small;
    if ratio - 1.0 < 1e-12 {
        return 4.0 / 3.0 * modulus * large.sqrt();
    }
    let shape = |m: f64| {
        let (k, e) = elliptic_k_e(m);
        (e / (1.0 - m) - k) / (k - e)
    };
    let (mut lo, mut hi) = (1e-12, 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if shape(mid) > ratio {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let m = 0.5 * (lo + hi);
    let (k, e) = elliptic_k_e(m);
    2.0 / 3.0 * PI * modulus / k * (2.0 * large * (k - e) / (k * m)).sqrt()
}

/// The complete elliptic integrals K(m) and E(m) of parameter m = e², by the
/// arithmetic–geometric mean.
fn elliptic_k_e(m: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0, (1.0 - m).sqrt());
    let (mut sum, mut power) = (0.5 * m, 0.5);
    for _ in 0..40 {
        let c = 0.5 * (a - b);
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
        power *= 2.0;
        sum += power * c * c;
        if c < 1e-17 {
            break;
        }
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// Cowper's shear coefficient of a solid circular section.
pub fn cowper_shear_coefficient(poisson_ratio: f64) -> f64 {
    6.0 * (1.0 + poisson_ratio) / (7.0 + 6.0 * poisson_ratio)
}

/// The first free-free bending frequency f1 (Hz) of `rod`, by Timoshenko beam theory with
/// Cowper's shear coefficient; `None` when no mode is found (a rod far too short for beam
/// theory, or non-physical parameters).
///
/// The first mode is symmetric about the midpoint, so the half beam x ∈ [0, L/2] carries
/// W = A cosh(px) + B cos(qx), Ψ = A (p²+σ)/p sinh(px) + B (σ−q²)/q sin(qx), with
/// σ = ρω²/(kG), τ = ρω²/E, c = ρAω²/(EI) and p², q² = [∓(σ+τ) + √((σ−τ)² + 4c)]/2. A free end
/// (no moment, no shear force) at x = L/2 leaves the 2 × 2 determinant
/// D(ω) = (σ−q²) cos(qh) S − (p²+σ) C sin(qh)/q, with S = tanh(ph)/p, C = 1 below the second
/// spectrum (p² > 0) and S = sin(p̃h)/p̃, C = cos(p̃h) above it (p = i p̃). Its first root above
/// zero is found by a scan from a thousandth of the Euler–Bernoulli frequency to 1.5 times it,
/// then bisection. In the Euler–Bernoulli limit D = 0 is tan(βh) + tanh(βh) = 0, βL = 4.730.
pub fn free_free_bending_frequency(rod: &Rod) -> Option<f64> {
    let Material {
        youngs_modulus: e,
        poisson_ratio: nu,
        density: rho,
    } = rod.material;
    let valid = [e, rho, rod.length, rod.diameter]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0)
        && nu.is_finite()
        && nu > -1.0
        && nu < 0.5;
    if !valid {
        return None;
    }
    let shear = cowper_shear_coefficient(nu) * e / (2.0 * (1.0 + nu));
    let area = rod.area();
    let inertia = PI * rod.diameter.powi(4) / 64.0;
    let h = rod.length / 2.0;
    let det = |w: f64| {
        let (sigma, tau) = (rho * w * w / shear, rho * w * w / e);
        let c = rho * area * w * w / (e * inertia);
        let disc = ((sigma - tau).powi(2) + 4.0 * c).sqrt();
        let (p2, q2) = (0.5 * (disc - (sigma + tau)), 0.5 * (disc + sigma + tau));
        let q = q2.sqrt();
        let (cosine, sine) = match p2 {
            p2 if p2 > 0.0 => (1.0, (p2.sqrt() * h).tanh() / p2.sqrt()),
            p2 if p2 < 0.0 => {
                let pt = (-p2).sqrt();
                ((pt * h).cos(), (pt * h).sin() / pt)
            }
            _ => (1.0, h),
        };
        (sigma - q2) * (q * h).cos() * sine - (p2 + sigma) * cosine * (q * h).sin() / q
    };
    let euler_bernoulli =
        4.730_040_745_f64.powi(2) / (rod.length * rod.length) * (e * inertia / (rho * area)).sqrt();
    let (start, steps) = (1e-3 * euler_bernoulli, 400);
    let step = 1.5 * euler_bernoulli / f64::from(steps);
    let (mut lo, mut f_lo) = (start, det(start));
    let mut hi = None;
    for i in 1..=steps {
        let w = start + f64::from(i) * step;
        let f = det(w);
        if f_lo * f <= 0.0 {
            hi = Some(w);
            break;
        }
        (lo, f_lo) = (w, f);
    }
    let mut hi = hi?;
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        let f = det(mid);
        if f_lo * f <= 0.0 {
            hi = mid;
        } else {
            (lo, f_lo) = (mid, f);
        }
    }
    let omega = 0.5 * (lo + hi);
    omega.is_finite().then_some(omega / (2.0 * PI))
}

#[cfg(test)]
mod tests {
    use super::*;

    const FUSED_QUARTZ: Material = Material {
        youngs_modulus: 72e9,
        poisson_ratio: 0.17,
        density: 2200.0,
    };

    fn quartz_rod(length: f64) -> Rod {
        Rod {
            length,
            diameter: 5e-3,
            material: FUSED_QUARTZ,
        }
    }

    fn within(value: f64, target: f64, share: f64) -> bool {
        (value - target).abs() <= share * target
    }

    /// The paper's Model section: a = 2.47e9 N/m^{3/2} for two 5 mm fused-quartz rods.
    #[test]
    fn crossed_quartz_rods_give_the_papers_coefficient() {
        let rod = quartz_rod(20e-3);
        let a = crossed_rods_coefficient(&rod, &rod);
        assert!(within(a, 2.47e9, 0.005), "{a:e}");
        // The closed form for equal rods.
        let closed = 2.0 * 72e9 * (2.5e-3f64).sqrt() / (3.0 * (1.0 - 0.17 * 0.17));
        assert!((a - closed).abs() < 1e-9 * closed);
    }

    /// The paper's measured bending modes: 55.2 kHz (20 mm) and 15.2 kHz (40 mm), within 2 %.
    #[test]
    fn quartz_rods_bend_at_the_papers_frequencies() {
        let f20 = free_free_bending_frequency(&quartz_rod(20e-3)).unwrap();
        let f40 = free_free_bending_frequency(&quartz_rod(40e-3)).unwrap();
        assert!(within(f20, 55.2e3, 0.02), "{f20}");
        assert!(within(f40, 15.2e3, 0.02), "{f40}");
    }

    /// With the paper's split of the 40 mm rod (M = 0.838 g, m = 0.894 g), K is within 2 % of
    /// 3,961 kN/m.
    #[test]
    fn the_papers_split_gives_its_spring() {
        let f1 = free_free_bending_frequency(&quartz_rod(40e-3)).unwrap();
        let (host, resonator) = (0.838e-3, 0.894e-3);
        let k = (2.0 * PI * f1).powi(2) * host * resonator / (host + resonator);
        assert!(within(k, 3961e3, 0.02), "{k}");
        // The split is the rod's mass.
        assert!(within(quartz_rod(40e-3).mass(), host + resonator, 0.005));
    }

    /// Long slender rods approach Euler–Bernoulli's βL = 4.730.
    #[test]
    fn slender_rods_approach_euler_bernoulli() {
        let rod = Rod {
            length: 2.0,
            ..quartz_rod(1.0)
        };
        let f = free_free_bending_frequency(&rod).unwrap();
        let inertia = PI * rod.diameter.powi(4) / 64.0;
        let eb = 4.730_040_745_f64.powi(2) / 4.0 * (72e9 * inertia / (2200.0 * rod.area())).sqrt()
            / (2.0 * PI);
        assert!(within(f, eb, 1e-4), "{f} vs {eb}");
    }

    /// A sphere on a rod: the elliptical contact lies between the circular contacts of its two
    /// radii, and an elliptical solution matches the circular one as the radii meet.
    #[test]
    fn elliptical_contacts_are_bracketed_and_continuous() {
        let e_star = 37e9;
        let a = hertz_coefficient(5e-3, 5e-3 / 3.0, e_star);
        let circle = |r: f64| 4.0 / 3.0 * e_star * r.sqrt();
        assert!(a > circle(5e-3 / 3.0) && a < circle(5e-3), "{a:e}");
        let nearly = hertz_coefficient(1e-3, 1.0001e-3, e_star);
        assert!(within(nearly, circle(1e-3), 1e-3), "{nearly:e}");
    }

    #[test]
    fn no_mode_for_nonsense_rods() {
        let mut rod = quartz_rod(0.0);
        assert!(free_free_bending_frequency(&rod).is_none());
        rod.length = 0.04;
        rod.material.poisson_ratio = 0.7;
        assert!(free_free_bending_frequency(&rod).is_none());
    }
}
