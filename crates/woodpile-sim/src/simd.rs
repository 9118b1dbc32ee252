//! Run-time CPU dispatch: one binary runs on every x86-64 and still uses the widest vectors
//! the CPU has. The workspace is compiled for the x86-64 baseline (SSE2); the few loops where
//! the time goes (the force loop, the stage sums, the contact scans: docs/performance.md,
//! "Where a scene's time goes") are compiled twice more, with AVX2 and FMA and with AVX-512,
//! and [`tier`] picks the copy at each call; the finite check has an AVX2 copy, which the
//! AVX-512 tier runs too.
//!
//! Every copy computes the same bits: every operation is element-wise, Rust never fuses a
//! multiply and an add on its own, and no loop is reassociated. [`cap`] caps the copy taken,
//! so every path can be run (and compared) on one machine: the command line and the Python
//! module call it with their `WOODPILE_SIMD` (`woodpile_scene::environment`); the simulator
//! reads no environment itself.

use std::sync::OnceLock;

/// Which copy of the hot loops runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Tier {
    /// The x86-64 baseline (SSE2): every x86-64, and every other architecture.
    Baseline,
    /// AVX2 and FMA (x86-64-v3).
    Avx2,
    /// AVX-512 (x86-64-v4) of the Ice Lake generation or later: 512-bit stage sums, masked
    /// loop tails (docs/performance.md, "Work against precision, standard scene").
    Avx512,
}

/// The cap [`cap`] set, if any.
static CAP: OnceLock<Tier> = OnceLock::new();

/// Caps the copy this process runs at `tier`, as an edge asks (`WOODPILE_SIMD`). Call it
/// before the first run: the tier is decided once per process, at its first use.
pub fn cap(tier: Tier) {
    // A second cap, or one after the first run, cannot change the copy a run began with.
    let _ = CAP.set(tier);
}

impl Tier {
    /// The tier a cap's name asks for: `baseline` or `avx2` (any other name caps nothing).
    pub fn cap_named(name: &str) -> Option<Tier> {
        match name {
            "baseline" => Some(Tier::Baseline),
            "avx2" => Some(Tier::Avx2),
            _ => None,
        }
    }
}

/// The copy of the hot loops this process runs: the best the CPU has, under the [`cap`].
/// Decided once per process.
pub fn tier() -> Tier {
    static CHOICE: OnceLock<Tier> = OnceLock::new();
    *CHOICE.get_or_init(|| detected().min(CAP.get().copied().unwrap_or(Tier::Avx512)))
}

/// The best tier the CPU runs. AVX-512 needs x86-64-v4's features and, as the marker of the
/// Ice Lake generation or later, `avx512vbmi2`: the first generation (Skylake-SP, Cascade
/// Lake) lowers its clock for 512-bit arithmetic, which would eat what the wider vectors gain,
/// so it takes the AVX2 copy.
#[cfg(target_arch = "x86_64")]
fn detected() -> Tier {
    use std::arch::is_x86_feature_detected as has;
    let avx2 = has!("avx2") && has!("fma");
    let avx512 = has!("avx512f")
        && has!("avx512vl")
        && has!("avx512dq")
        && has!("avx512bw")
        && has!("avx512cd")
        && has!("avx512vbmi2")
        && has!("bmi1")
        && has!("bmi2")
        && has!("lzcnt");
    match (avx2, avx512) {
        (true, true) => Tier::Avx512,
        (true, false) => Tier::Avx2,
        (false, _) => Tier::Baseline,
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detected() -> Tier {
    Tier::Baseline
}

/// Defines method `$name` as a dispatcher over three copies of the `#[inline(always)]` method
/// `$body` (same receiver, same arguments): `$avx512` and `$avx2`, compiled with those
/// features and called when [`tier`] says so, and `$body` itself for the baseline. The
/// receiver is written in brackets, `[&self]` or `[&mut self]`.
macro_rules! dispatched {
    (
        $(#[$meta:meta])*
        $vis:vis fn $name:ident [&mut $s:ident] $($rest:tt)*
    ) => {
        crate::simd::dispatched!(@emit [$(#[$meta])*] $vis $name [&mut $s] $s $($rest)*);
    };
    (
        $(#[$meta:meta])*
        $vis:vis fn $name:ident [& $s:ident] $($rest:tt)*
    ) => {
        crate::simd::dispatched!(@emit [$(#[$meta])*] $vis $name [&$s] $s $($rest)*);
    };
    (
        @emit [$($meta:tt)*] $vis:vis $name:ident [$($recv:tt)+] $s:ident
        ($($arg:ident : $ty:ty),* $(,)?) $(-> $ret:ty)? => $body:ident, $avx2:ident, $avx512:ident
    ) => {
        $($meta)*
        #[allow(unsafe_code)]
        $vis fn $name($($recv)+, $($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            match crate::simd::tier() {
                // SAFETY: `tier()` names a tier only when the CPU has its features.
                crate::simd::Tier::Avx512 => return unsafe { $s.$avx512($($arg),*) },
                // SAFETY: as above.
                crate::simd::Tier::Avx2 => return unsafe { $s.$avx2($($arg),*) },
                crate::simd::Tier::Baseline => {}
            }
            $s.$body($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        fn $avx2($($recv)+, $($arg: $ty),*) $(-> $ret)? {
            $s.$body($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(
            enable = "avx2,fma,bmi1,bmi2,lzcnt,avx512f,avx512vl,avx512dq,avx512bw,avx512cd,avx512vbmi2"
        )]
        fn $avx512($($recv)+, $($arg: $ty),*) $(-> $ret)? {
            $s.$body($($arg),*)
        }
    };
}

pub(crate) use dispatched;
