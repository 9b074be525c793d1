//! The legs' speed as the servos measure it: each leg's turn between two of its positions a
//! window apart. Present Velocity, read just after each cycle's new goal, is the position
//! loop's peak, not the leg's mean speed, so the speed is taken from the positions.

/// The window over which a leg's speed is measured from its positions, s.
pub const LEG_SPEED_WINDOW_S: f64 = 0.25;

/// Each leg's latest speed over [`LEG_SPEED_WINDOW_S`], from the samples it is shown.
#[derive(Debug, Clone)]
pub struct LegSpeedMeter {
    /// Per leg, the time and angle the current window started at.
    anchor: Vec<Option<(f64, f64)>>,
    /// Per leg, its speed over the last full window, rad/s.
    speeds: Vec<Option<f64>>,
    window_s: f64,
    start_s: f64,
}

impl LegSpeedMeter {
    /// A meter for `legs` legs, no window measured yet.
    pub fn new(legs: usize) -> LegSpeedMeter {
        LegSpeedMeter::with_window(legs, LEG_SPEED_WINDOW_S, 0.0)
    }

    /// A meter over windows of `window_s`: one stride period (`drive` and `serve --drive`
    /// use the gait's) takes the leg's mean over its whole turn, steady though a servo slows in
    /// stance and catches up in swing, where a shorter window swings with the stride's phase.
    /// Samples before `start_s` (standing, and the gait's run-up, whose speed is not the
    /// leg speed yet) are left out.
    pub fn with_window(legs: usize, window_s: f64, start_s: f64) -> LegSpeedMeter {
        LegSpeedMeter {
            anchor: vec![None; legs],
            speeds: vec![None; legs],
            window_s,
            start_s: start_s.max(0.0),
        }
    }

    /// Takes leg `leg`'s angle `angle_rad` at time `time_s` (one servo's sample: its
    /// `leg`, `time_s` and `leg_angle_rad`); a leg beyond the meter's is ignored.
    pub fn observe(&mut self, leg: usize, time_s: f64, angle_rad: f64) {
        let Some(anchor) = self.anchor.get_mut(leg) else { return };
        if time_s < self.start_s {
            return;
        }
        match *anchor {
            Some((t0, a0)) if time_s - t0 >= self.window_s => {
                self.speeds[leg] = Some((angle_rad - a0) / (time_s - t0));
                *anchor = Some((time_s, angle_rad));
            }
            Some(_) => {}
            None => *anchor = Some((time_s, angle_rad)),
        }
    }

    /// The mean of the legs' latest speeds, rad/s; `None` before any leg's first window.
    pub fn mean(&self) -> Option<f64> {
        let known: Vec<f64> = self.speeds.iter().flatten().copied().collect();
        (!known.is_empty()).then(|| known.iter().sum::<f64>() / known.len() as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two legs turning at 2 pi and pi rad/s, sampled at 50 Hz: no speed before a window has
    /// passed, then each leg's own, and their mean 1.5 pi; a leg the meter does not have is
    /// ignored.
    #[test]
    fn the_meter_takes_each_legs_turn_over_its_window() {
        let mut m = LegSpeedMeter::new(2);
        let pi = std::f64::consts::PI;
        for k in 0..=10 {
            let t = k as f64 * 0.02;
            m.observe(0, t, 2.0 * pi * t);
            m.observe(1, t, pi * t);
            m.observe(5, t, 100.0 * t);
        }
        assert_eq!(m.mean(), None);
        for k in 11..=30 {
            let t = k as f64 * 0.02;
            m.observe(0, t, 2.0 * pi * t);
            m.observe(1, t, pi * t);
        }
        assert!((m.mean().unwrap() - 1.5 * pi).abs() < 1e-9, "{:?}", m.mean());
    }
}
