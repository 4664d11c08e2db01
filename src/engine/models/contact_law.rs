//! A contact law = its slots (normal, tangential, optional rolling), chosen by name, and the one kernel that
//! composes them for a single contact.
//!
//! The composition passes values explicitly: the normal slot's force and contact radius go to the tangential and
//! rolling slots. Lever arms and torques are formed by the caller (`pair_pass.rs`), which also owns the geometry.

use serde::{Deserialize, Serialize};

use super::history::ContactHistory;
use super::history::HistoryLayout;
use super::normal::NormalModel;
use super::pair_table::PairMaterial;
use super::rolling::RollingModel;
use super::tangential::TangentialModel;
use crate::engine::Vec3;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactLaw {
    pub normal: NormalModel,
    pub tangential: TangentialModel,
    #[serde(default)]
    pub rolling: RollingModel,
}

/// Geometry and kinematics of one contact, as seen from particle i.
#[derive(Debug, Clone, Copy)]
pub struct ContactKinematics {
    /// Unit normal pointing from the partner (j or the wall) to i.
    pub normal: Vec3,
    pub overlap_m: f64,
    pub effective_radius_m: f64,
    pub effective_mass_kg: f64,
    /// Velocity of i's contact point minus that of the partner's contact point.
    pub contact_velocity: Vec3,
    /// Its normal component `contact_velocity · normal`, negative while approaching. The caller forms it from the
    /// centres' velocities alone (the rotational part of the contact velocity is normal to n), which keeps it off
    /// the chain of dependent operations that sets the force loop's speed.
    pub normal_velocity_m_per_s: f64,
    /// ω_i − ω_j (for a wall, ω_i minus the wall's own rotation).
    pub relative_angular_velocity: Vec3,
}

/// One contact's result: its geometry and what it exerts on particle i (the partner receives the opposite force).
/// The geometry is what a contact's heat or liquid transfer needs beside the force; the pass reads the fields it
/// uses and the compiler drops the others.
#[derive(Debug, Clone, Copy)]
pub struct ContactOutput {
    /// Unit normal from the partner to i.
    pub normal: Vec3,
    /// Overlap δ, m.
    pub overlap_m: f64,
    /// Contact radius a, m: √(R* δ) for the Hertzian normal models, 0 for the linear spring (no contact area).
    pub contact_radius_m: f64,
    /// Normal force on i along `normal`, N.
    pub normal_force_n: f64,
    /// Total contact force on i.
    pub force: Vec3,
    /// Its tangential part, for the torques −R n × F_t.
    pub tangential_force: Vec3,
    /// Rolling-resistance torque on i (the partner receives the opposite).
    pub rolling_torque: Vec3,
}

impl ContactLaw {
    /// Names of the slot models, as stored in checkpoints and results.
    pub fn model_names(&self) -> [&'static str; 3] {
        [self.normal.name(), self.tangential.name(), self.rolling.name()]
    }

    /// The history columns this law reads and writes (the cohesion slot's are the cohesion model's).
    pub fn history_layout(&self) -> HistoryLayout {
        HistoryLayout {
            tangential: true,
            walton_braun: matches!(self.tangential, TangentialModel::WaltonBraun { .. }),
            thornton: matches!(self.normal, NormalModel::Thornton { .. }),
            ..HistoryLayout::NONE
        }
    }

    /// Evaluates one overlapping contact and updates its history.
    #[inline(always)]
    pub fn evaluate(
        &self,
        mat: &PairMaterial,
        k: &ContactKinematics,
        dt_s: f64,
        hist: &mut ContactHistory,
    ) -> ContactOutput {
        let n = k.normal;
        let vn = k.normal_velocity_m_per_s;
        let normal = self.normal.force(
            mat,
            k.effective_radius_m,
            k.effective_mass_kg,
            k.overlap_m,
            vn,
            &mut hist.normal,
        );
        let vt = k.contact_velocity - n * vn;
        let ft = self.tangential.force(mat, &normal, &n, &vt, dt_s, &mut hist.tangential);
        let rolling_torque = self.rolling.torque(
            mat.rolling_friction_coefficient,
            k.effective_radius_m,
            normal.force_n,
            &k.relative_angular_velocity,
        );
        hist.active = true;
        ContactOutput {
            normal: n,
            overlap_m: k.overlap_m,
            contact_radius_m: normal.contact_radius_m,
            normal_force_n: normal.force_n,
            force: n * normal.force_n + ft,
            tangential_force: ft,
            rolling_torque,
        }
    }
}
