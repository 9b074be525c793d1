//! A whole walk (docs/model.md §15-§17): the steps from t = 0, recorded at full rate for the
//! step measures and sampled at the trajectory's rate.

use super::super::{Geometry, Trajectory};
use super::{GroupForces, Run, StepPeaks, Walker};

impl Walker {
    /// Walks `n_steps` integration steps from t = 0, recording the full-rate along-slope
    /// position and speed, per-step peaks (steps of `half` = T/2) and samples at `rate_hz`.
    pub(crate) fn run(mut self, n_steps: usize, half: f64, rate_hz: f64) -> Run {
        let legs = self.psi.len();
        let n_gait_steps = ((n_steps as f64 * self.dt) / half).ceil() as usize + 1;
        let mut per_step = vec![StepPeaks::default(); n_gait_steps];
        let mut stalled_by_step: Vec<Vec<usize>> = vec![Vec::new(); n_gait_steps];
        let mut x = Vec::with_capacity(n_steps + 1);
        let mut vx = Vec::with_capacity(n_steps + 1);
        let mut groups: Vec<GroupForces> = Vec::with_capacity(n_steps);
        let samples = ((n_steps as f64 * self.dt) * rate_hz).floor() as usize + 1;
        let mut tr = Trajectory {
            time_s: Vec::with_capacity(samples),
            x_m: Vec::with_capacity(samples),
            z_m: Vec::with_capacity(samples),
            pitch_rad: Vec::with_capacity(samples),
            vx_m_s: Vec::with_capacity(samples),
            vz_m_s: Vec::with_capacity(samples),
            leg_angle_rad: vec![Vec::with_capacity(samples); legs],
            leg_depth_m: vec![Vec::with_capacity(samples); legs],
            leg_force_x_n: vec![Vec::with_capacity(samples); legs],
            leg_force_z_n: vec![Vec::with_capacity(samples); legs],
            leg_torque_n_m: vec![Vec::with_capacity(samples); legs],
        };
        let mut next_sample = 0usize;
        self.unconverged = 0;
        let mut prev = (self.q, self.v, 0.0);
        let mut max_abs_pitch = self.q[2].abs();
        let mut pitch_over_s = None;
        x.push(self.q[0]);
        vx.push(self.v[0]);
        // Sample t = 0 from the settled state (legs as the first step will see them).
        for i in 0..n_steps {
            self.step(true);
            x.push(self.q[0]);
            vx.push(self.v[0]);
            groups.push(self.group_forces());
            let t = (i + 1) as f64 * self.dt;
            max_abs_pitch = max_abs_pitch.max(self.q[2].abs());
            if pitch_over_s.is_none() && self.q[2].abs() > super::super::PITCH_OVER_RAD {
                pitch_over_s = Some(t);
            }
            let k = ((t - 0.5 * self.dt - 0.5 * self.ramp) / half).floor().max(0.0) as usize;
            if let Some(p) = per_step.get_mut(k) {
                for j in 0..legs {
                    let o = self.legs_out[j];
                    p.max_depth = p.max_depth.max(o.depth);
                    // The squared force here, its root once at the end (sqrt is monotonic and
                    // correctly rounded, so the root of the largest is the largest root).
                    p.peak_force = p.peak_force.max(o.force[0].powi(2) + o.force[1].powi(2));
                    p.peak_torque = p.peak_torque.max(o.torque.abs());
                    if self.locked.is_none() {
                        p.peak_lag = p.peak_lag.max(self.command(j, self.time) - self.psi[j]);
                    }
                    if self.stalled[j] {
                        p.stall_s += self.dt;
                        if !stalled_by_step[k].contains(&j) {
                            stalled_by_step[k].push(j);
                        }
                    }
                }
            }
            while next_sample < samples {
                let ts = next_sample as f64 / rate_hz;
                if ts > t + 1e-12 {
                    break;
                }
                let (q0, v0, t0) = prev;
                let f = if t > t0 { ((ts - t0) / (t - t0)).clamp(0.0, 1.0) } else { 1.0 };
                let lerp = |a: f64, b: f64| a + f * (b - a);
                tr.time_s.push(ts);
                tr.x_m.push(lerp(q0[0], self.q[0]));
                tr.z_m.push(lerp(q0[1], self.q[1]));
                tr.pitch_rad.push(lerp(q0[2], self.q[2]));
                tr.vx_m_s.push(lerp(v0[0], self.v[0]));
                tr.vz_m_s.push(lerp(v0[1], self.v[1]));
                for j in 0..legs {
                    let o = self.legs_out[j];
                    tr.leg_angle_rad[j].push(self.psi[j]);
                    tr.leg_depth_m[j].push(o.depth);
                    tr.leg_force_x_n[j].push(o.force[0]);
                    tr.leg_force_z_n[j].push(o.force[1]);
                    tr.leg_torque_n_m[j].push(-o.torque);
                }
                next_sample += 1;
            }
            prev = (self.q, self.v, t);
        }
        for p in &mut per_step {
            p.peak_force = p.peak_force.sqrt();
        }
        let geometry = Geometry {
            hip_x_m: self.hips.clone(),
            tripod: self.tripod.clone(),
            leg_nodes_m: self.nodes.clone(),
            body_length_m: self.body_length,
            hip_height_m: self.hip_height,
        };
        Run {
            x,
            vx,
            trajectory: tr,
            geometry,
            per_step,
            stalled_by_step,
            max_abs_pitch,
            pitch_over_s,
            unconverged_steps: self.unconverged,
            groups,
        }
    }
}
