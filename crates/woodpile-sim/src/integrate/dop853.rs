//! Dormand–Prince 8(5,3): the explicit embedded Runge–Kutta pair of order 8 with a 5th-order
//! error estimate corrected by a 3rd-order one (Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I*, 2nd ed., Section II.10; the coefficients of their code DOP853).
//!
//! 12 stages, the last stage's derivative at the new point reused as the next step's first
//! (first-same-as-last), so 12 right-hand sides per accepted step. Error norm and step
//! controller follow DOP853: err = |h| err5^2 / sqrt(n (err5^2 + 0.01 err3^2)) in the RMS norm
//! scaled by atol + rtol max(|y|, |y_new|), and h_new = h min(10, max(0.2, 0.9 err^{-1/8})).
//!
//! The constants keep the 30 digits published with DOP853, so that they can be checked against
//! the source by eye; the compiler rounds them to f64.
#![allow(clippy::excessive_precision)]

use super::rk::rk_stages;
use super::{Method, StepOutcome, StepSpan, Stepper};
use crate::model::Model;

const STAGES: usize = 12;

const C: [f64; STAGES] = [
    0.0,
    0.526_001_519_587_677_318_785_587_544_488e-1,
    0.789_002_279_381_515_978_178_381_316_732e-1,
    0.118_350_341_907_227_396_726_757_197_510,
    0.281_649_658_092_772_603_273_242_802_490,
    0.333_333_333_333_333_333_333_333_333_333,
    0.25,
    0.307_692_307_692_307_692_307_692_307_692,
    0.651_282_051_282_051_282_051_282_051_282,
    0.6,
    0.857_142_857_142_857_142_857_142_857_142,
    1.0,
];

const A: [&[f64]; STAGES] = [
    &[],
    &[5.260_015_195_876_773_187_855_875_444_88e-2],
    &[
        1.972_505_698_453_789_945_445_953_291_83e-2,
        5.917_517_095_361_369_836_337_859_875_49e-2,
    ],
    &[
        2.958_758_547_680_684_918_168_929_937_75e-2,
        0.0,
        8.876_275_643_042_054_754_506_789_813_24e-2,
    ],
    &[
        2.413_651_341_592_666_855_023_697_986_65e-1,
        0.0,
        -8.845_494_793_282_860_853_448_649_627_17e-1,
        9.248_340_032_617_920_031_157_379_665_43e-1,
    ],
    &[
        3.703_703_703_703_703_703_703_703_703_7e-2,
        0.0,
        0.0,
        1.708_286_087_294_738_712_796_044_821_73e-1,
        1.254_676_875_668_224_250_166_918_141_23e-1,
    ],
    &[
        3.710_937_5e-2,
        0.0,
        0.0,
        1.702_522_110_195_440_393_149_780_602_72e-1,
        6.021_653_898_045_596_068_502_193_972_83e-2,
        -1.757_812_5e-2,
    ],
    &[
        3.709_200_011_850_479_271_087_793_198_36e-2,
        0.0,
        0.0,
        1.703_839_257_122_399_938_102_140_547_05e-1,
        1.072_620_304_463_732_846_518_091_991_68e-1,
        -1.531_943_774_862_440_175_279_361_582_36e-2,
        8.273_789_163_814_022_887_584_737_660_02e-3,
    ],
    &[
        6.241_109_587_160_757_171_144_295_778_12e-1,
        0.0,
        0.0,
        -3.360_892_629_446_941_294_068_571_098_25,
        -8.682_193_468_417_260_068_181_898_914_53e-1,
        2.759_209_969_944_670_830_494_156_007_97e1,
        2.015_406_755_047_789_340_861_867_889_79e1,
        -4.348_988_418_106_995_884_773_662_551_44e1,
    ],
    &[
        4.776_625_364_382_643_658_904_339_085_27e-1,
        0.0,
        0.0,
        -2.488_114_619_971_667_641_926_425_864_68,
        -5.902_908_268_368_429_963_714_464_757_43e-1,
        2.123_005_144_818_119_423_472_889_498_97e1,
        1.527_923_363_288_242_358_325_969_229_38e1,
        -3.328_821_096_898_486_291_944_532_655_87e1,
        -2.033_120_170_850_862_613_582_229_285_93e-2,
    ],
    &[
        -9.371_424_300_859_873_257_170_402_165_8e-1,
        0.0,
        0.0,
        5.186_372_428_844_063_708_300_238_532_09,
        1.091_437_348_996_729_578_185_002_546_54,
        -8.149_787_010_746_926_125_139_972_673_57,
        -1.852_006_565_999_695_986_415_661_807_01e1,
        2.273_948_709_935_050_428_189_700_567_34e1,
        2.493_605_552_679_652_389_870_893_967_62,
        -3.046_764_471_898_219_500_382_366_902_2,
    ],
    &[
        2.273_310_147_516_538_207_923_597_684_49,
        0.0,
        0.0,
        -1.053_449_546_673_725_019_840_666_898_79e1,
        -2.000_872_058_224_862_499_096_757_184_44,
        -1.795_893_186_311_879_891_727_659_505_34e1,
        2.794_888_452_941_996_005_084_998_088_37e1,
        -2.858_998_277_135_023_694_740_655_086_74,
        -8.872_856_933_530_629_544_335_492_892_58,
        1.236_056_717_579_430_306_472_662_015_28e1,
        6.433_927_460_157_635_303_559_704_840_46e-1,
    ],
];

const B: [f64; STAGES] = [
    5.429_373_411_656_876_223_805_357_663_63e-2,
    0.0,
    0.0,
    0.0,
    0.0,
    4.450_312_892_752_408_881_441_139_505_66,
    1.891_517_899_314_500_383_042_815_990_44,
    -5.801_203_960_010_584_781_467_211_422_7,
    3.111_643_669_578_198_944_089_160_623_7e-1,
    -1.521_609_496_625_160_785_561_788_068_05e-1,
    2.013_654_008_040_303_483_747_765_375_01e-1,
    4.471_061_572_777_259_051_768_855_690_43e-2,
];

/// B minus the 3rd-order weights.
const E3: [f64; STAGES] = [
    B[0] - 0.244_094_488_188_976_377_952_755_905_512,
    0.0,
    0.0,
    0.0,
    0.0,
    B[5],
    B[6],
    B[7],
    B[8] - 0.733_846_688_281_611_857_341_361_741_547,
    B[9],
    B[10],
    B[11] - 0.220_588_235_294_117_647_058_823_529_412e-1,
];

/// B minus the 5th-order weights.
const E5: [f64; STAGES] = [
    0.131_200_449_941_948_807_325_010_299_6e-1,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.122_515_644_637_620_444_072_056_975_3e1,
    -0.495_758_949_657_250_191_521_407_995_2,
    0.166_437_718_245_498_653_696_153_041_5e1,
    -0.350_328_848_749_973_681_688_648_729_0,
    0.334_179_118_713_017_479_029_731_884_1,
    0.819_232_064_851_157_124_657_074_261_3e-1,
    -0.223_553_078_638_862_952_588_442_784_5e-1,
];

/// DOP853's tableau, for a driver that brings its own right-hand side: the bench's
/// independent reference of damped chains integrates its own force code with it.
#[derive(Debug, Clone, Copy)]
pub struct Dop853Tableau {
    /// Stage coefficients a_ij, row i holding j < i.
    pub a: &'static [&'static [f64]; STAGES],
    /// The 8th-order weights b.
    pub b: &'static [f64; STAGES],
    /// The nodes c.
    pub c: &'static [f64; STAGES],
    /// b minus the 3rd-order weights.
    pub e3: &'static [f64; STAGES],
    /// b minus the 5th-order weights.
    pub e5: &'static [f64; STAGES],
}

/// The coefficients [`Dop853`] steps with.
pub const DOP853_TABLEAU: Dop853Tableau = Dop853Tableau {
    a: &A,
    b: &B,
    c: &C,
    e3: &E3,
    e5: &E5,
};

/// The adaptive DOP853 stepper with its tolerances and scratch.
#[derive(Debug, Clone)]
pub struct Dop853 {
    rtol: f64,
    atol: f64,
    stages: Vec<f64>,
    scratch: Vec<f64>,
    y_new: Vec<f64>,
    /// f(t, y) at the start of the next step, when known (first-same-as-last).
    fsal_at: Option<f64>,
    evals: u64,
}

impl Dop853 {
    /// A stepper for `model` with relative and absolute tolerances per component.
    pub fn new(model: &Model, rtol: f64, atol: f64) -> Self {
        let len = model.state_len();
        Self {
            rtol,
            atol,
            stages: vec![0.0; STAGES * len],
            scratch: vec![0.0; len],
            y_new: vec![0.0; len],
            fsal_at: None,
            evals: 0,
        }
    }

    fn scale(&self, a: f64, b: f64) -> f64 {
        self.atol + self.rtol * a.abs().max(b.abs())
    }
}

impl Stepper for Dop853 {
    fn name(&self) -> &'static str {
        Method::Dop853.name()
    }

    #[allow(clippy::needless_range_loop)] // one pass over components, reading 12 stage rows
    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        let StepSpan { t, h, window } = span;
        let len = y.len();
        let reuse = self.fsal_at == Some(t);
        rk_stages(
            model,
            t,
            y,
            h,
            (&A, &C),
            &mut self.stages,
            &mut self.scratch,
            !reuse,
            window,
        );
        self.evals += if reuse {
            STAGES as u64 - 1
        } else {
            STAGES as u64
        };

        // Outside the window every stage is zero, so y_new = y there and the error terms are
        // zero: summing only the window's terms, in state order, gives the same sums bit for bit.
        let ranges = window.state_ranges(model);
        self.y_new.copy_from_slice(y);
        let mut err5 = 0.0;
        let mut err3 = 0.0;
        for i in ranges.clone().into_iter().flatten() {
            let mut inc = 0.0;
            let mut e5 = 0.0;
            let mut e3 = 0.0;
            for s in 0..STAGES {
                let k = self.stages[s * len + i];
                inc += B[s] * k;
                e5 += E5[s] * k;
                e3 += E3[s] * k;
            }
            let y_next = y[i] + h * inc;
            self.y_new[i] = y_next;
            let sc = self.scale(y[i], y_next);
            err5 += (e5 / sc) * (e5 / sc);
            err3 += (e3 / sc) * (e3 / sc);
        }
        let denom = err5 + 0.01 * err3;
        let err = if denom > 0.0 {
            h.abs() * err5 / (denom * len as f64).sqrt()
        } else {
            0.0
        };

        if err.is_nan() {
            return StepOutcome::Rejected { h_next: 0.2 * h };
        }
        if err <= 1.0 {
            for range in ranges {
                y[range.clone()].copy_from_slice(&self.y_new[range]);
            }
            // The derivative at the accepted point opens the next step.
            model.rhs_in(t + h, y, &mut self.stages[..len], window);
            self.evals += 1;
            self.fsal_at = Some(t + h);
            let factor = if err == 0.0 {
                10.0
            } else {
                (0.9 * err.powf(-0.125)).clamp(0.2, 10.0)
            };
            StepOutcome::Accepted { h_next: h * factor }
        } else {
            self.fsal_at = if reuse { Some(t) } else { None };
            let factor = (0.9 * err.powf(-0.125)).max(0.2);
            StepOutcome::Rejected { h_next: h * factor }
        }
    }

    fn rhs_evals(&self) -> u64 {
        self.evals
    }

    fn reach(&self) -> usize {
        STAGES + 1
    }

    /// Hairer's starting-step heuristic (HNW I, Section II.4).
    fn initial_step(&mut self, model: &Model, t: f64, y: &[f64], t_end: f64) -> f64 {
        let len = y.len();
        let mut f0 = vec![0.0; len];
        model.rhs(t, y, &mut f0);
        self.evals += 1;
        let rms = |v: &dyn Fn(usize) -> f64| {
            ((0..len).map(|i| v(i) * v(i)).sum::<f64>() / len as f64).sqrt()
        };
        let d0 = rms(&|i| y[i] / self.scale(y[i], y[i]));
        let d1 = rms(&|i| f0[i] / self.scale(y[i], y[i]));
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let y1: Vec<f64> = (0..len).map(|i| y[i] + h0 * f0[i]).collect();
        let mut f1 = vec![0.0; len];
        model.rhs(t + h0, &y1, &mut f1);
        self.evals += 1;
        let d2 = rms(&|i| (f1[i] - f0[i]) / self.scale(y[i], y[i])) / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 8.0)
        };
        (100.0 * h0).min(h1).min(t_end)
    }
}
