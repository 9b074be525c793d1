//! The live monitor's view of the servos' torques: each tripod's stance binned as it happens
//! (docs/model.md §19), the stance handed to the inference once it is complete, and each leg's
//! current-sensor offset removed online as `infer --servo-log` removes it afterwards
//! (`sandslope::infer::servo::remove_swing_offset`): the median of the leg's swing, here its
//! last complete one (the stance that follows cannot wait for the next swing without the
//! estimate, and a halt on risk, coming half a stride later).

use sandslope::infer::servo::MIN_SWING_SAMPLES;
use sandslope::servo::GaitSchedule;

/// One leg's swings: the one under way and the median of the last complete one.
#[derive(Debug, Default)]
struct LegSwing {
    stride: Option<i64>,
    tau: Vec<f64>,
    median: Option<f64>,
}

impl LegSwing {
    /// Ends the swing under way; its median becomes the leg's offset if it has
    /// [`MIN_SWING_SAMPLES`] samples (a shorter one keeps the last).
    fn finish(&mut self) {
        if self.tau.len() >= MIN_SWING_SAMPLES {
            self.tau.sort_by(f64::total_cmp);
            let n = self.tau.len();
            let m = if n % 2 == 1 { self.tau[n / 2] } else { 0.5 * (self.tau[n / 2 - 1] + self.tau[n / 2]) };
            self.median = Some(m);
        }
        self.tau.clear();
        self.stride = None;
    }
}

/// One complete stance, binned.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Stance {
    /// The tripod.
    pub tripod: usize,
    /// Its stride: 0 is tripod 0's run-up stance, binned from the raw torques.
    pub stride: i64,
    /// Bin means, tripod-major over both tripods (the other tripod's `None`).
    pub profile: Vec<Option<f64>>,
    /// Samples per bin.
    pub counts: Vec<usize>,
}

/// Accumulates each tripod's current stance into bins.
#[derive(Debug)]
pub(crate) struct StanceBins {
    bins: usize,
    /// Whether tripod 0's run-up stance (stride 0) is binned too, raw (no swing before it).
    run_up: bool,
    key: [Option<i64>; 2],
    sum: [Vec<f64>; 2],
    count: [Vec<usize>; 2],
    /// Per leg, when the swing offset is removed.
    swing: Option<Vec<LegSwing>>,
}

impl StanceBins {
    /// `bins` per stance; with `swing_offset`, each of the `legs` has its last swing's median
    /// torque taken off its stance samples (a stance before any complete swing is not binned,
    /// but for the run-up stance with `run_up`, binned raw).
    pub(crate) fn new(bins: usize, legs: usize, swing_offset: bool, run_up: bool) -> StanceBins {
        StanceBins {
            swing: swing_offset.then(|| (0..legs).map(|_| LegSwing::default()).collect()),
            bins,
            run_up,
            key: [None, None],
            sum: [vec![0.0; bins], vec![0.0; bins]],
            count: [vec![0; bins], vec![0; bins]],
        }
    }

    /// Adds one sample at gait time `time`; returns a completed stance. The run-up stance
    /// takes samples from the gait's start only (standing at the start angle, tripod 0 is at
    /// its stance's first angle, where the simulated walks spend no time).
    pub(crate) fn add(
        &mut self,
        schedule: &GaitSchedule,
        leg: usize,
        time: f64,
        angle: f64,
        tau: f64,
    ) -> Option<Stance> {
        let k = schedule.tripods[leg];
        let (stride, since) = schedule.stride_position(leg, angle);
        let half = 0.5 * schedule.period_s;
        let run_up = self.run_up && stride == 0 && k == 0 && time >= 0.0;
        let in_stance = since < half && (stride >= 1 || run_up);
        let raw = tau;
        let tau = match self.swing.as_mut().and_then(|sw| sw.get_mut(leg)) {
            None => Some(tau),
            Some(sw) => {
                let in_swing = stride >= 0 && since >= half && tau.is_finite();
                if sw.stride.is_some() && (sw.stride != Some(stride) || !in_swing) {
                    sw.finish();
                }
                if in_swing {
                    sw.stride = Some(stride);
                    sw.tau.push(tau);
                }
                if run_up {
                    Some(raw)
                } else {
                    sw.median.map(|m| tau - m)
                }
            }
        };
        let mut done = None;
        if self.key[k].is_some() && (self.key[k] != Some(stride) || !in_stance) {
            done = Some(self.flush(k));
        }
        if in_stance {
            self.key[k] = Some(stride);
            if let Some(tau) = tau {
                let b = ((since / half * self.bins as f64) as usize).min(self.bins - 1);
                self.sum[k][b] += tau;
                self.count[k][b] += 1;
            }
        }
        done
    }

    fn flush(&mut self, k: usize) -> Stance {
        let b = self.bins;
        let stride = self.key[k].unwrap_or(0);
        let mut profile = vec![None; 2 * b];
        let mut counts = vec![0; 2 * b];
        for i in 0..b {
            let c = self.count[k][i];
            counts[k * b + i] = c;
            profile[k * b + i] = (c > 0).then(|| self.sum[k][i] / c as f64);
        }
        self.key[k] = None;
        self.sum[k] = vec![0.0; b];
        self.count[k] = vec![0; b];
        Stance { tripod: k, stride, profile, counts }
    }
}
