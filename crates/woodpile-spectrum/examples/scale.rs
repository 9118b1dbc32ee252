//! Wall time of the computations on long chains: the numbers quoted in the crate's report.
//!
//! ```text
//! cargo run --release -p woodpile-spectrum --example scale
//! ```
//!
//! A 10,000-site chain: a mass-in-mass host (m1 = 1, K = 1, m2 = 0.8 on k2 = 1 at every site)
//! with 10 resonators removed and 5 light sites; transmission between monatomic leads over
//! 2,000 frequencies, then every mode in the host's stop bands. Then the dense solvers at their
//! size limit.
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;

use woodpile_spectrum::modes::MAX_DENSE_ORDER;
use woodpile_spectrum::{
    damped_modes, localised_modes, normal_modes, scatter, Cell, ChainSpec, Lead, LinearChain,
    LinearResonator,
};

fn resonator(site: usize) -> LinearResonator {
    LinearResonator {
        site,
        mass: 0.8,
        stiffness: 1.0,
        damping: 0.0,
    }
}

fn main() {
    let n = 10_000;
    let missing: Vec<usize> = (0..10).map(|i| 500 + 900 * i).collect();
    let mut spec = ChainSpec::uniform(n, 1.0, 1.0);
    spec.resonators = (0..n)
        .filter(|s| !missing.contains(s))
        .map(resonator)
        .collect();
    for i in 0..5 {
        spec.masses[950 + 1900 * i] = 0.5;
    }
    let chain = LinearChain::new(spec).unwrap();
    let lead = Lead::new(1.0, 1.0).unwrap();
    let omegas: Vec<f64> = (1..=2000)
        .map(|i| lead.cutoff() * f64::from(i) / 2001.0)
        .collect();

    let start = Instant::now();
    let spectrum = scatter(&lead, &chain, &omegas).unwrap();
    let transmission = start.elapsed();
    let passing = spectrum.iter().filter(|s| s.transmittance() > 1e-6).count();
    println!(
        "transmission: {n} sites + {} resonators, {} frequencies: {transmission:.2?} \
         ({passing} with |T|^2 > 1e-6)",
        chain.resonators().len(),
        omegas.len()
    );

    let host = Cell::new(vec![1.0], vec![1.0], vec![resonator(0)]).unwrap();
    let start = Instant::now();
    let windows = host.stop_bands(chain.frequency_bound()).unwrap();
    let modes = localised_modes(&chain, &windows).unwrap();
    let search = start.elapsed();
    println!(
        "localised modes: {} in {} windows, {search:.2?}",
        modes.len(),
        windows.len()
    );
    for mode in modes.iter().take(4) {
        let l = mode.localisation;
        println!(
            "  omega {:.6}, peak site {}, participation {:.2}, length {:.3}",
            mode.omega, l.peak_site, l.participation, l.length
        );
    }

    let dense = LinearChain::new(ChainSpec::uniform(MAX_DENSE_ORDER, 1.0, 1.0)).unwrap();
    let start = Instant::now();
    let all = normal_modes(&dense).unwrap();
    println!("dense modes, order {}: {:.2?}", all.len(), start.elapsed());
    let mut spec = ChainSpec::uniform(MAX_DENSE_ORDER / 2, 1.0, 1.0);
    spec.ground_damping = vec![0.01; MAX_DENSE_ORDER / 2];
    let damped = LinearChain::new(spec).unwrap();
    let start = Instant::now();
    let all = damped_modes(&damped).unwrap();
    println!(
        "damped modes, order {} state space: {:.2?}",
        2 * all.len(),
        start.elapsed()
    );
}
