//! The sand's force on the body by group, each step (issue 59, item 2): the belly and each
//! tripod, so that what holds the body at touchdown can be read from a walk
//! ([`super::super::phase1`]).

use super::super::body::BELLY;
use super::Walker;

/// The sand's summed force on the belly and on each tripod's legs this step, `[x, z]` in the
/// slope frame, N.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct GroupForces {
    /// On the belly.
    pub belly: [f64; 2],
    /// On tripod 0's and tripod 1's legs.
    pub tripod: [[f64; 2]; 2],
    /// The along-slope speed of the belly's midpoint at the step's end, m/s: the body's slide
    /// over the sand without its rocking (docs/model.md §18, "Phase 1"). The point lies `h`
    /// below the centre of mass on the body's normal, so at pitch phi it moves at
    /// `v_x + h cos(phi) dphi/dt`; the centre's speed when the pitch is locked.
    pub slide_m_s: f64,
}

impl Walker {
    /// The solved forces of this step summed by group (coincident legs' contacts already carry
    /// their group's weight, docs/model.md §17, so the sum over contacts is the whole group's).
    pub(crate) fn group_forces(&self) -> GroupForces {
        let mut g = GroupForces::default();
        for (c, f) in self.contacts.iter().zip(&self.forces) {
            let slot = if c.leg == BELLY { &mut g.belly } else { &mut g.tripod[self.tripod[c.leg].min(1)] };
            slot[0] += f[0];
            slot[1] += f[1];
        }
        g.slide_m_s = self.v[0] + self.v[2] * self.hip_height * self.q[2].cos();
        g
    }
}
