//! Observers: what a run records at its sample times, kept out of the numerics.
//!
//! - [`FractionSeries`]: R, T, E_tr and E as time series, so that a different read-out time is a
//!   re-reduction rather than a re-simulation.
//! - [`FractionSeries::kinetic`]: kinetic-energy fractions normalised by the impact energy, as
//!   the woodpile experiment measures them (paper Fig. 2 c, f).
//! - [`SpaceTimeField`]: a decimated site-by-time velocity map (paper Figs. 3, 8, 10).
//! - [`SiteField`]: displacements, velocities and energies of a range of sites, and every
//!   resonator's displacement and velocity, at every sample, in full precision (one scene's
//!   field for analysis, `woodpile simulate --field`, Python's `fields`).

use crate::energy::{energy_density, kinetic_density, Fractions, Region};
use crate::integrate::Observer;
use crate::model::Model;

/// Which energy a [`FractionSeries`] splits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeriesKind {
    /// Total energy density, shares normalised by E(t): they sum to one.
    Energy,
    /// Kinetic energy only, shares divided by a fixed `normalisation` (the impact energy), as the
    /// woodpile experiment measures them: kinetic energy is not conserved, so they need not sum
    /// to one.
    Kinetic {
        /// The energy the shares are divided by (> 0).
        normalisation: f64,
    },
}

/// Fractions of one region at every sample: R(t), T(t), E_tr(t) and the total.
#[derive(Debug, Clone, PartialEq)]
pub struct FractionSeries {
    region: Region,
    kind: SeriesKind,
    density: Vec<f64>,
    /// Sample times.
    pub t: Vec<f64>,
    /// Share left of the region.
    pub reflected: Vec<f64>,
    /// Share right of the region.
    pub transmitted: Vec<f64>,
    /// Share inside the region.
    pub trapped: Vec<f64>,
    /// The striker's share S (all zero without a striker).
    pub striker: Vec<f64>,
    /// The energy split at each sample (total, or kinetic).
    pub energy: Vec<f64>,
    /// D, the share dissipated so far (all zero for a conservative chain).
    pub dissipated: Vec<f64>,
    /// E(0), from the first sample: what a dissipative chain's shares are divided by.
    e_initial: Option<f64>,
}

impl FractionSeries {
    /// An empty total-energy series for `region` of `model`.
    pub fn new(model: &Model, region: Region) -> Self {
        Self::of_kind(model, region, SeriesKind::Energy)
    }

    /// An empty kinetic-energy series for `region`, divided by `normalisation`.
    pub fn kinetic(model: &Model, region: Region, normalisation: f64) -> Self {
        Self::of_kind(model, region, SeriesKind::Kinetic { normalisation })
    }

    /// Frees the per-site scratch the sampling used (a float a site): after the run only the
    /// samples are needed, and a sweep that keeps many points of a long chain keeps just them.
    pub fn drop_scratch(&mut self) {
        self.density = Vec::new();
    }

    fn of_kind(model: &Model, region: Region, kind: SeriesKind) -> Self {
        Self {
            region,
            kind,
            density: vec![0.0; model.n_sites()],
            t: Vec::new(),
            reflected: Vec::new(),
            transmitted: Vec::new(),
            trapped: Vec::new(),
            striker: Vec::new(),
            energy: Vec::new(),
            dissipated: Vec::new(),
            e_initial: None,
        }
    }
}

impl Observer for FractionSeries {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        let scale = match self.kind {
            SeriesKind::Energy => {
                energy_density(model, t, y, &mut self.density);
                None
            }
            SeriesKind::Kinetic { normalisation } => {
                kinetic_density(model, y, &mut self.density);
                Some(normalisation)
            }
        };
        let f = Fractions::from_density(&self.density, self.region);
        let held = f.total;
        let e_initial = *self.e_initial.get_or_insert(held);
        // A dissipative chain's total-energy shares are of E(0), with D beside them.
        let (factor, dissipated) = match (scale, model.is_dissipative()) {
            (Some(n), _) => (f.total / n, model.dissipated(y) / n),
            (None, true) => (held / e_initial, model.dissipated(y) / e_initial),
            (None, false) => (1.0, 0.0),
        };
        self.t.push(t);
        self.reflected.push(f.reflected * factor);
        self.transmitted.push(f.transmitted * factor);
        self.trapped.push(f.trapped * factor);
        self.striker.push(f.striker * factor);
        self.energy.push(held);
        self.dissipated.push(dissipated);
    }

    fn reset(&mut self) {
        for v in [
            &mut self.t,
            &mut self.reflected,
            &mut self.transmitted,
            &mut self.trapped,
            &mut self.striker,
            &mut self.energy,
            &mut self.dissipated,
        ] {
            v.clear();
        }
        self.e_initial = None;
    }
}

/// Site velocities u_n'(t) on a decimated grid: every `time_stride`-th sample and every
/// `site_stride`-th site. Stored as f32: a picture needs no more, and the file stays small.
#[derive(Debug, Clone, PartialEq)]
pub struct SpaceTimeField {
    time_stride: usize,
    site_stride: usize,
    seen: usize,
    /// Sample times kept.
    pub t: Vec<f64>,
    /// Internal indices of the sites kept.
    pub sites: Vec<usize>,
    /// Velocities, row-major: `velocity[i * sites.len() + k]` is site `sites[k]` at `t[i]`.
    pub velocity: Vec<f32>,
}

impl SpaceTimeField {
    /// A field keeping every `time_stride`-th sample and every `site_stride`-th site (both >= 1).
    pub fn new(model: &Model, time_stride: usize, site_stride: usize) -> Self {
        let site_stride = site_stride.max(1);
        Self {
            time_stride: time_stride.max(1),
            site_stride,
            seen: 0,
            t: Vec::new(),
            sites: (0..model.n_sites()).step_by(site_stride).collect(),
            velocity: Vec::new(),
        }
    }
}

impl Observer for SpaceTimeField {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        let keep = self.seen.is_multiple_of(self.time_stride);
        self.seen += 1;
        if !keep {
            return;
        }
        let velocities = &y[model.n_dof()..];
        self.t.push(t);
        self.velocity
            .extend(self.sites.iter().map(|&s| velocities[s] as f32));
    }

    fn reset(&mut self) {
        self.seen = 0;
        self.t.clear();
        self.velocity.clear();
    }
}

/// Displacements u_n(t), velocities u_n'(t), energies and kinetic energies of the sites
/// `first..=last` (internal indices), and every resonator's displacement w_j(t) and velocity
/// w_j'(t), at every sample, as f64, row-major (time × site, time × resonator): what a user
/// analyses, where [`SpaceTimeField`] is what a figure draws. Each sample appends one row to
/// each flat vector, so the arrays can be handed on whole, without a copy per sample.
#[derive(Debug, Clone, PartialEq)]
pub struct SiteField {
    first: usize,
    last: usize,
    /// Sample times.
    pub t: Vec<f64>,
    /// Displacements: `displacement[i * width + k]` is site `first + k` at `t[i]`.
    pub displacement: Vec<f64>,
    /// Velocities, laid out as `displacement`.
    pub velocity: Vec<f64>,
    /// Each site's energy e_n (its mass's kinetic energy, half of each of its bonds, its wall
    /// or soft end, and its resonator's kinetic and spring energy), laid out as `displacement`:
    /// over the whole chain they sum to E(t).
    pub energy: Vec<f64>,
    /// Each site's kinetic energy, its host mass applied and its resonator's included: what
    /// the woodpile experiment measures. Laid out as `displacement`.
    pub kinetic: Vec<f64>,
    /// Every resonator's displacement: `resonator_displacement[i * R + j]` is resonator `j`
    /// (in the model's order) at `t[i]`.
    pub resonator_displacement: Vec<f64>,
    /// Every resonator's velocity, laid out as `resonator_displacement`.
    pub resonator_velocity: Vec<f64>,
    /// Scratch: one sample's per-site density over the whole chain.
    density: Vec<f64>,
}

impl SiteField {
    /// A field of the sites `first..=last` of `model`, clamped to the chain.
    pub fn new(model: &Model, first: usize, last: usize) -> Self {
        let top = model.n_sites().saturating_sub(1);
        let last = last.min(top);
        Self {
            first: first.min(last),
            last,
            t: Vec::new(),
            displacement: Vec::new(),
            velocity: Vec::new(),
            energy: Vec::new(),
            kinetic: Vec::new(),
            resonator_displacement: Vec::new(),
            resonator_velocity: Vec::new(),
            density: vec![0.0; model.n_sites()],
        }
    }

    /// The internal indices of the sites kept.
    pub fn sites(&self) -> std::ops::RangeInclusive<usize> {
        self.first..=self.last
    }

    /// Number of sites kept per sample.
    pub fn width(&self) -> usize {
        self.last - self.first + 1
    }
}

/// Most values a [`SiteField`] array may hold (160 MB of f64 each for displacement and
/// velocity): a thousand times the paper's largest map.
pub const MAX_FIELD_VALUES: u64 = 20_000_000;

impl Observer for SiteField {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        let (n_sites, n_dof) = (model.n_sites(), model.n_dof());
        let (q, v) = y.split_at(n_dof);
        self.t.push(t);
        self.displacement.extend_from_slice(&q[self.sites()]);
        self.velocity.extend_from_slice(&v[self.sites()]);
        self.resonator_displacement
            .extend_from_slice(&q[n_sites..n_dof]);
        self.resonator_velocity
            .extend_from_slice(&v[n_sites..n_dof]);
        energy_density(model, t, y, &mut self.density);
        self.energy
            .extend_from_slice(&self.density[self.first..=self.last]);
        kinetic_density(model, y, &mut self.density);
        self.kinetic
            .extend_from_slice(&self.density[self.first..=self.last]);
    }

    fn reset(&mut self) {
        for v in [
            &mut self.t,
            &mut self.displacement,
            &mut self.velocity,
            &mut self.energy,
            &mut self.kinetic,
            &mut self.resonator_displacement,
            &mut self.resonator_velocity,
        ] {
            v.clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Accuracy, Method, MethodChoice};
    use crate::simulation::simulate;
    use crate::testing::{paper_scene, PaperDefect};

    fn scene() -> crate::simulation::Scenario {
        let accuracy = Accuracy {
            tolerance: 1e-6,
            tolerance_explicit: true,
            dt: Some(0.02),
        };
        let mut s = paper_scene(
            &[PaperDefect::linear(0, 3.0, 1.0)],
            MethodChoice::Named(Method::Rk4),
            accuracy,
        );
        s.t_end = 60.0;
        s
    }

    /// The series samples 0, 1, ..., t_end, its shares sum to one, and its last entry is the
    /// run's final fractions.
    #[test]
    fn fraction_series_ends_at_the_final_fractions() {
        let s = scene();
        let mut series = FractionSeries::new(&s.model, s.region);
        let out = simulate(&s, &mut series).unwrap();
        assert_eq!(series.t.len(), 61);
        assert_eq!(series.t[0], 0.0);
        assert_eq!(*series.t.last().unwrap(), 60.0);
        for i in 0..series.t.len() {
            let sum = series.reflected[i] + series.transmitted[i] + series.trapped[i];
            assert!((sum - 1.0).abs() < 1e-12);
        }
        assert_eq!(*series.trapped.last().unwrap(), out.fractions.trapped);
        // Before the wave arrives everything is reflected-side energy (the impulse is at -25).
        assert!((series.reflected[0] - 1.0).abs() < 1e-15);
    }

    /// Kinetic fractions start as the whole impact energy on the left and never exceed it.
    #[test]
    fn kinetic_series_is_normalised_by_the_impact_energy() {
        let s = scene();
        let mut kin = FractionSeries::kinetic(&s.model, s.region, 0.5);
        simulate(&s, &mut kin).unwrap();
        assert!((kin.reflected[0] - 1.0).abs() < 1e-15);
        for i in 0..kin.t.len() {
            let total = kin.reflected[i] + kin.transmitted[i] + kin.trapped[i];
            assert!(
                total <= 1.0 + 1e-9 && total > 0.0,
                "t = {}: {total}",
                kin.t[i]
            );
        }
    }

    /// The field keeps every k-th sample and site, row-major, and resets cleanly.
    #[test]
    fn space_time_field_is_decimated() {
        let s = scene();
        let mut field = SpaceTimeField::new(&s.model, 2, 4);
        simulate(&s, &mut field).unwrap();
        assert_eq!(field.sites.len(), 51); // 201 sites, every 4th
        assert_eq!(field.t.len(), 31); // 61 samples, every 2nd
        assert_eq!(field.velocity.len(), field.t.len() * field.sites.len());
        // At t = 0 only the impulse site (index 75) moves, and it is kept only if 4 divides 75.
        let moving: usize = field.velocity[..51].iter().filter(|v| **v != 0.0).count();
        assert_eq!(moving, usize::from(75 % 4 == 0));
        field.reset();
        assert!(field.t.is_empty() && field.velocity.is_empty());
    }

    /// The site field keeps every sample of its sites in full precision: the same velocities
    /// as the decimated f32 map, the displacements of the final state at t_end.
    #[test]
    fn site_field_keeps_its_sites_at_every_sample() {
        let s = scene();
        let mut both = (
            SiteField::new(&s.model, 70, 80),
            SpaceTimeField::new(&s.model, 1, 1),
        );
        let out = simulate(&s, &mut both).unwrap();
        let (field, map) = both;
        assert_eq!(field.width(), 11);
        assert_eq!(field.t, map.t);
        assert_eq!(field.velocity.len(), 61 * 11);
        for (i, row) in field.velocity.chunks(11).enumerate() {
            for (k, v) in row.iter().enumerate() {
                assert_eq!(*v as f32, map.velocity[i * 201 + 70 + k]);
            }
        }
        let last_row = &field.displacement[60 * 11..];
        assert_eq!(last_row, &out.final_state[70..=80]);
        // Only the impulse site (index 75) moves at t = 0.
        assert_eq!(field.velocity[5], 1.0);
        assert_eq!(
            field.velocity[..11].iter().filter(|v| **v != 0.0).count(),
            1
        );
    }

    /// Over the whole chain the site energies sum to E(t) and the kinetic energies to the
    /// chain's kinetic energy; the resonator columns are the state's resonator entries, and
    /// the field's last row is the final state.
    #[test]
    fn site_energies_sum_to_the_total_and_resonators_are_recorded() {
        let s = scene();
        let n = s.model.n_sites();
        let mut both = (
            SiteField::new(&s.model, 0, n - 1),
            FractionSeries::new(&s.model, s.region),
        );
        let out = simulate(&s, &mut both).unwrap();
        let (field, series) = both;
        let samples = field.t.len();
        assert_eq!(field.energy.len(), samples * n);
        assert_eq!(field.resonator_displacement.len(), samples);
        for (i, row) in field.energy.chunks(n).enumerate() {
            let total: f64 = row.iter().sum();
            assert!(
                (total - series.energy[i]).abs() <= 1e-12 * series.energy[i],
                "{i}"
            );
        }
        for (i, (kinetic, energy)) in field
            .kinetic
            .chunks(n)
            .zip(field.energy.chunks(n))
            .enumerate()
        {
            let (u, v) = (
                &field.displacement[i * n..(i + 1) * n],
                &field.velocity[i * n..(i + 1) * n],
            );
            let w = field.resonator_velocity[i];
            let expected: f64 = v.iter().map(|v| 0.5 * v * v).sum::<f64>() + 0.5 * 3.0 * w * w;
            let sum: f64 = kinetic.iter().sum();
            assert!(
                (sum - expected).abs() <= 1e-12 * expected.max(1e-300),
                "{i}"
            );
            assert!(kinetic.iter().zip(energy).all(|(k, e)| *k <= *e + 1e-15));
            assert_eq!(u.len(), n);
        }
        let nd = s.model.n_dof();
        assert_eq!(
            field.resonator_displacement[samples - 1],
            out.final_state[n]
        );
        assert_eq!(
            field.resonator_velocity[samples - 1],
            out.final_state[nd + n]
        );
        // At t = 0 only the impulse site moves, and the resonator is at rest.
        assert_eq!(
            (field.resonator_displacement[0], field.resonator_velocity[0]),
            (0.0, 0.0)
        );
    }

    /// An observer that asks to stop ends the run at the next sample, `auto`'s verification
    /// runs included, with `Cancelled` rather than numbers.
    #[test]
    fn a_cancelled_run_stops_at_the_next_sample() {
        struct StopAfter(usize, usize);
        impl Observer for StopAfter {
            fn observe(&mut self, _: &Model, _: f64, _: &[f64]) {
                self.0 += 1;
            }
            fn reset(&mut self) {}
            fn cancelled(&self) -> bool {
                self.0 >= self.1
            }
        }
        let mut s = scene();
        let mut stop = StopAfter(0, 5);
        let err = simulate(&s, &mut stop).unwrap_err();
        assert!(
            matches!(err, crate::SimError::Cancelled { t } if t == 4.0),
            "{err:?}"
        );
        s.method = MethodChoice::Auto;
        let mut stop = StopAfter(0, 0);
        let err = simulate(&s, &mut stop).unwrap_err();
        // The coarse verification run is the first to see the request, at its first sample.
        assert!(
            matches!(err, crate::SimError::Cancelled { t } if t == 1.0),
            "{err:?}"
        );
    }
}
