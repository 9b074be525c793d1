//! What tests read from a walker: its energy, state, rest steps and merged legs.

use super::Walker;

impl Walker {
    /// Total mechanical energy, J: kinetic plus gravity's potential (tests).
    #[cfg(test)]
    pub(crate) fn energy(&self) -> f64 {
        let kinetic = 0.5 * self.mass * (self.v[0].powi(2) + self.v[1].powi(2))
            + 0.5 * self.inertia * self.v[2].powi(2);
        kinetic - self.mass * (self.gx * self.q[0] + self.gz * self.q[1])
    }

    /// Current state `(x, z, pitch)` and rates (tests).
    #[cfg(test)]
    pub(crate) fn state(&self) -> ([f64; 3], [f64; 3]) {
        (self.q, self.v)
    }

    /// Runs `steps` integration steps with the legs held (tests).
    #[cfg(test)]
    pub(crate) fn hold(&mut self, steps: usize) {
        for _ in 0..steps {
            self.step(false);
        }
    }

    /// The same walker placing every leg, coincident or not (tests).
    #[cfg(test)]
    pub(crate) fn placing_every_leg(self) -> Walker {
        Walker { merge_coincident: false, ..self }
    }

    /// How many steps so far ended at rest by the active-set step (tests).
    #[cfg(test)]
    pub(crate) fn rest_steps(&self) -> usize {
        self.rest_steps
    }

    /// How many steps so far were taken as substeps because the belly struck the sand (tests).
    #[cfg(test)]
    pub(crate) fn strike_steps(&self) -> usize {
        self.strike_steps
    }

    /// How many legs the last step let another leg's contacts stand for (tests).
    #[cfg(test)]
    pub(crate) fn coincident_legs(&self) -> usize {
        self.twin.iter().enumerate().filter(|&(j, &t)| t != j).count()
    }

    /// Deepest leg point below the surface now, m (tests).
    #[cfg(test)]
    pub(crate) fn leg_depth(&self) -> f64 {
        self.legs_out.iter().map(|o| o.depth).fold(0.0, f64::max)
    }

    /// Walks `steps` gait steps from the current state and returns the motors' work over
    /// them, J: the sum over steps and legs of the sand's torque resisting the leg (what the
    /// massless leg's motor gives) times the leg's rate times the step (tests).
    pub(crate) fn walk_with_work(&mut self, steps: usize) -> f64 {
        let before = self.motor_work;
        for _ in 0..steps {
            self.step(true);
        }
        self.motor_work - before
    }
}
