//! The live monitor's view of the servos' torques: each tripod's stance binned as it happens
//! (docs/model.md §19), the stance handed to the inference once it is complete.

use sandslope::servo::GaitSchedule;

/// Accumulates each tripod's current stance into bins.
#[derive(Debug)]
pub(crate) struct StanceBins {
    bins: usize,
    key: [Option<i64>; 2],
    sum: [Vec<f64>; 2],
    count: [Vec<usize>; 2],
}

impl StanceBins {
    pub(crate) fn new(bins: usize) -> StanceBins {
        StanceBins {
            bins,
            key: [None, None],
            sum: [vec![0.0; bins], vec![0.0; bins]],
            count: [vec![0; bins], vec![0; bins]],
        }
    }

    /// Adds one sample; returns a completed stance's profile `(tripod, profile, counts)`.
    #[allow(clippy::type_complexity)]
    pub(crate) fn add(
        &mut self,
        schedule: &GaitSchedule,
        leg: usize,
        angle: f64,
        tau: f64,
    ) -> Option<(usize, Vec<Option<f64>>, Vec<usize>)> {
        let k = schedule.tripods[leg];
        let (stride, since) = schedule.stride_position(leg, angle);
        let half = 0.5 * schedule.period_s;
        let in_stance = since < half && stride >= 1;
        let mut done = None;
        if self.key[k].is_some() && (self.key[k] != Some(stride) || !in_stance) {
            done = Some(self.flush(k));
        }
        if in_stance {
            self.key[k] = Some(stride);
            let b = ((since / half * self.bins as f64) as usize).min(self.bins - 1);
            self.sum[k][b] += tau;
            self.count[k][b] += 1;
        }
        done
    }

    fn flush(&mut self, k: usize) -> (usize, Vec<Option<f64>>, Vec<usize>) {
        let b = self.bins;
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
        (k, profile, counts)
    }
}
