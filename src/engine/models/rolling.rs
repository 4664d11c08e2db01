//! The optional rolling-resistance slot.
//!
//! Off by default (none of the seeds uses rolling resistance). The one model provided is the constant directional
//! torque (Zhou et al. 1999; LIGGGHTS `rolling_friction cdt`), which opposes the relative rotation with a torque of
//! magnitude μ_r R* F_n.

use serde::{Deserialize, Serialize};

use crate::engine::Vec3;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RollingModel {
    #[default]
    None,
    /// M_r = −μ_r R* F_n ω_rel/|ω_rel|, μ_r from the species pair.
    ConstantDirectionalTorque,
}

impl RollingModel {
    pub fn name(&self) -> &'static str {
        match self {
            RollingModel::None => "none",
            RollingModel::ConstantDirectionalTorque => "constant_directional_torque",
        }
    }

    /// Rolling torque on particle i (j receives the opposite).
    #[inline]
    pub fn torque(
        &self,
        rolling_friction_coefficient: f64,
        effective_radius_m: f64,
        normal_force_n: f64,
        relative_angular_velocity: &Vec3,
    ) -> Vec3 {
        match self {
            RollingModel::None => Vec3::zeros(),
            RollingModel::ConstantDirectionalTorque => {
                let w = relative_angular_velocity.norm();
                if w == 0.0 || normal_force_n <= 0.0 {
                    Vec3::zeros()
                } else {
                    -relative_angular_velocity
                        * (rolling_friction_coefficient * effective_radius_m * normal_force_n / w)
                }
            }
        }
    }
}
