//! The belly's strike on the sand, taken in substeps (docs/model.md §17): the body lands on its
//! belly at the end of every step at up to 0.75 m/s and the sand stops it within about 3 ms, a
//! handful of integration steps, where the scheme's first-order error decided how far the
//! belly ploughed and so where the body came to rest and when the new tripod lifted it
//! (docs/simulate.md, "Why t1 did not converge").

use super::{Walker, BELLY_ELEMENTS};

/// A step in which the belly strikes the sand is taken as this many substeps.
const STRIKE_SUBSTEPS: usize = 8;
/// The belly strikes the sand when an end of it moves into the sand faster than this, m/s
/// (the built-in robot's belly lands at about 0.75 m/s and comes to rest within 3 ms). On the
/// built-in robot and terrain this keeps t1 within 0.69 ms of the quarter step's at 0 to 24
/// degrees for 8% more CPU over the 31-slope sweep; 16 substeps from 0.01 m/s (its bounces
/// land again at 0.04 to 0.06 m/s) give 0.25 ms there for 22% but move the free ensemble's on
/// level sand by 1.10 ms (docs/simulate.md, "Why t1 did not converge").
const STRIKE_SPEED_M_S: f64 = 0.05;

impl Walker {
    /// One time step; `gait`: legs follow the gait (else held). A step in which the belly
    /// strikes the sand ([`Walker::striking`]) is taken as [`STRIKE_SUBSTEPS`] substeps
    /// (docs/model.md §17): the strike stops the body within a few milliseconds, a handful
    /// of steps, and the scheme's first-order error there set where the body came to rest.
    pub(super) fn step(&mut self, gait: bool) {
        if !self.striking() {
            self.substep(gait);
            return;
        }
        let (dt, time, unconverged) = (self.dt, self.time, self.unconverged);
        self.dt = dt / STRIKE_SUBSTEPS as f64;
        for _ in 0..STRIKE_SUBSTEPS {
            self.substep(gait);
        }
        self.dt = dt;
        self.time = time + dt;
        // The step is one step of the walk's count, however many of its substeps did not converge.
        self.unconverged = self.unconverged.min(unconverged + 1);
        self.strike_steps += 1;
    }

    /// Whether the belly strikes the sand in this step: one of its ends is in the sand, or
    /// will be at the step's end at its present rate, moving into it faster than
    /// [`STRIKE_SPEED_M_S`].
    fn striking(&self) -> bool {
        let (sp, cp) = self.q[2].sin_cos();
        [self.belly[0], self.belly[BELLY_ELEMENTS]].iter().any(|p| {
            let height = self.q[1] + sp * p[0] + cp * p[1];
            let rate = self.v[1] + self.v[2] * (cp * p[0] - sp * p[1]);
            rate < -STRIKE_SPEED_M_S && height + self.dt * rate < 0.0
        })
    }
}
