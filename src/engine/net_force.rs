//! The net force on the particles split by mechanism (seed 001 ch. 8, Figs 8.8–8.16): the gas, each wall's contact
//! forces and each wall's cohesion, summed over all particles and averaged over the steps since the last reading.
//!
//! Seed 001 explains its pressure overshoot on fluidization with this split: at incipient fluidization the fluid
//! force on a cohesive bed exceeds its weight, held down by the distributor's cohesion and the sidewalls' friction.
//! Particle–particle forces cancel in the sum (action and reaction), so what is left is the gas, gravity and the
//! walls. For a flat distributor normal to gravity the up-component of its force is its normal contact force (its
//! friction is horizontal); for a vertical sidewall it is the friction (its normal force is horizontal).
//!
//! Every term is summed in a fixed order (particles ascending, wall slots in list order) from values the step
//! computes anyway, so the tally is the same bits on any thread count, and it never feeds back into the motion.

use super::Vec3;

/// Sums of the net force per mechanism over the steps since the last [`NetForceTally::take_means`].
#[derive(Debug, Clone, PartialEq)]
pub struct NetForceTally {
    /// Steps summed.
    pub steps: u64,
    /// Σ over steps of the gas's force on all particles, N.
    pub fluid_n: Vec3,
    /// Σ over steps of each wall's contact force on all particles (index = wall), N.
    pub wall_contact_n: Vec<Vec3>,
    /// Σ over steps of each wall's cohesion force on all particles (index = wall), N.
    pub wall_cohesion_n: Vec<Vec3>,
}

/// Mean net forces per mechanism over some steps, N.
#[derive(Debug, Clone, PartialEq)]
pub struct NetForceMeans {
    pub fluid_n: Vec3,
    pub wall_contact_n: Vec<Vec3>,
    pub wall_cohesion_n: Vec<Vec3>,
}

impl NetForceTally {
    pub fn new(walls: usize) -> Self {
        NetForceTally {
            steps: 0,
            fluid_n: Vec3::zeros(),
            wall_contact_n: vec![Vec3::zeros(); walls],
            wall_cohesion_n: vec![Vec3::zeros(); walls],
        }
    }

    /// The means since the last call (`None` if no step was summed), and a fresh start.
    pub fn take_means(&mut self) -> Option<NetForceMeans> {
        let sums = std::mem::replace(self, NetForceTally::new(self.wall_contact_n.len()));
        if sums.steps == 0 {
            return None;
        }
        let per_step = 1.0 / sums.steps as f64;
        let mean = |v: Vec<Vec3>| v.into_iter().map(|f| f * per_step).collect();
        Some(NetForceMeans {
            fluid_n: sums.fluid_n * per_step,
            wall_contact_n: mean(sums.wall_contact_n),
            wall_cohesion_n: mean(sums.wall_cohesion_n),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_means_are_the_sums_over_the_steps_and_reading_starts_again() {
        let mut tally = NetForceTally::new(2);
        assert_eq!(tally.take_means(), None, "no step summed yet");
        for k in 1..=4 {
            tally.steps += 1;
            tally.fluid_n += Vec3::new(0.0, k as f64, 0.0);
            tally.wall_contact_n[1] += Vec3::new(0.0, 2.0, 0.0);
            tally.wall_cohesion_n[0] -= Vec3::new(0.0, 0.5, 0.0);
        }
        let means = tally.take_means().expect("four steps");
        assert_eq!(means.fluid_n, Vec3::new(0.0, 2.5, 0.0));
        assert_eq!(means.wall_contact_n, vec![Vec3::zeros(), Vec3::new(0.0, 2.0, 0.0)]);
        assert_eq!(means.wall_cohesion_n, vec![Vec3::new(0.0, -0.5, 0.0), Vec3::zeros()]);
        assert_eq!(tally, NetForceTally::new(2));
    }
}
