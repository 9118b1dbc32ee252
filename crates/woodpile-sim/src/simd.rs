//! Run-time CPU dispatch: one binary runs on every x86-64 and still uses AVX2 where the CPU
//! has it. The workspace is compiled for the x86-64 baseline (SSE2); the few loops where the
//! time goes (the force loop, the stage sums, the contact scan, the finite check:
//! docs/performance.md, "Where a scene's time goes") are compiled a second time with AVX2
//! and FMA enabled, and [`avx2`] picks the copy at each call.
//!
//! Both copies compute the same bits: every operation is element-wise, Rust never fuses a
//! multiply and an add on its own, and no loop is reassociated. `WOODPILE_SIMD=baseline` forces
//! the baseline copies, so both paths can be run (and compared) on one machine.

use std::sync::OnceLock;

/// Whether the AVX2 copies run: the CPU has AVX2 and FMA, and `WOODPILE_SIMD` is not
/// `baseline`. Decided once per process.
pub fn avx2() -> bool {
    static CHOICE: OnceLock<bool> = OnceLock::new();
    *CHOICE.get_or_init(|| {
        let forced_off = std::env::var("WOODPILE_SIMD").is_ok_and(|v| v == "baseline");
        !forced_off && detected()
    })
}

#[cfg(target_arch = "x86_64")]
fn detected() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

#[cfg(not(target_arch = "x86_64"))]
fn detected() -> bool {
    false
}

/// Defines method `$name` as a dispatcher over two copies of the `#[inline(always)]` method
/// `$body` (same receiver, same arguments): `$avx2`, compiled with AVX2 and FMA and called
/// when [`avx2`] says so, and `$body` itself for the baseline. The receiver is written in
/// brackets, `[&self]` or `[&mut self]`.
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
        ($($arg:ident : $ty:ty),* $(,)?) $(-> $ret:ty)? => $body:ident, $avx2:ident
    ) => {
        $($meta)*
        #[allow(unsafe_code)]
        $vis fn $name($($recv)+, $($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if crate::simd::avx2() {
                // SAFETY: `avx2()` is true only when the CPU has AVX2 and FMA.
                return unsafe { $s.$avx2($($arg),*) };
            }
            $s.$body($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        fn $avx2($($recv)+, $($arg: $ty),*) $(-> $ret)? {
            $s.$body($($arg),*)
        }
    };
}

pub(crate) use dispatched;
