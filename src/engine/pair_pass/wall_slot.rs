//! The wall slots of the pair pass: a particle's walls in ascending order, each slot the contact law against a
//! partner of infinite mass moving with its wall (of infinite radius, or a glued bead's: `Wall::contact_radius_m`),
//! the wall's cohesion where the run has one, and the heat a heated wall conducts into the particle (contact and gas
//! lens). Part of `Context`, whose pair kernels are in the parent module; [`Context::complete`] calls
//! [`Context::walls`] once a particle's pair forces are in.

use super::super::Vec3;
use super::super::channels::ScalarFlows;
use super::super::cohesion::{Bond, BridgeConstants};
use super::super::contacts::ColumnsMut;
use super::super::models::ContactKinematics;
use super::super::models::cohesion_law::CohesionModel;
use super::{Context, PassKind, WorstOverlap, cohesion_state};

/// Result of one wall slot: the contact's (force, torque) on i while it overlaps, the cohesion model's while it acts,
/// and the slot's flows into i's channels.
type WallSlotResult = (Option<(Vec3, Vec3)>, Option<(Vec3, Vec3)>, ScalarFlows);

impl Context<'_> {
    /// Conduction through the gas lens between particle i (temperature `ti`) and wall `w` at surface gap `gap_m`
    /// (negative in overlap), if the run has the lens and the wall is heated: H (T_w − T_i) into i, W. A glued bead
    /// is a sphere of its own radius for the lens, as for the contact.
    #[inline(always)]
    pub(super) fn wall_lens_heat_flow_w(&self, i: usize, w: u16, gap_m: f64, ti: f64) -> f64 {
        if let Some(lens) = self.heat.and_then(|h| h.lens.as_ref())
            && let Some(wall_temperature_k) = self.wall_temperature_k[w as usize]
        {
            let ri = self.radius_m[i];
            let conductance = match self.config.walls[w as usize].bead_radius_m() {
                Some(rb) => lens.pair_conductance_w_per_k(ri, rb, ri + rb + gap_m),
                None => lens.wall_conductance_w_per_k(ri, gap_m),
            };
            conductance * (wall_temperature_k - ti)
        } else {
            0.0
        }
    }

    /// Adds the wall contacts and wall cohesion of particle i (velocity `vi`, angular velocity `wi`) to (f, t), in
    /// ascending wall order; `hist` holds exactly i's wall slots, the first of which is slot `first_slot_global` of
    /// the whole list. Returns the walls' flows into i's channels (zero unless the run records them).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn walls<P: PassKind>(
        &self,
        i: usize,
        x: Vec3,
        vi: Vec3,
        wi: Vec3,
        ti: f64,
        wall_ids: &[u16],
        hist: &mut ColumnsMut,
        first_slot: usize,
        first_slot_global: usize,
        f: &mut Vec3,
        t: &mut Vec3,
        worst: &mut WorstOverlap,
        crossings: &mut u64,
    ) -> ScalarFlows {
        if !P::WIDE {
            // The narrow pass's wall loop, written out: the contact part of [`Context::wall_slot`] with the force
            // added in place. The same loop through `wall_slot` (which also serves cohesion and channels) made the
            // dry benchmark 4-7 % slower, although every wide branch is a compile-time `false` there
            // (`docs/performance.md`); the two must compute the same contact (tests/engine_reference.rs pins it).
            let ri = self.radius_m[i];
            let mut heat_flow_w = 0.0;
            for (offset, &w) in wall_ids.iter().enumerate() {
                let k = first_slot + offset;
                let wall = &self.config.walls[w as usize];
                let prox = wall.proximity_turned(&x, self.wall_turn[w as usize]);
                let overlap = ri - prox.gap_m;
                if overlap <= 0.0 {
                    hist.release_as::<P>(k);
                    if P::HEAT {
                        heat_flow_w += self.wall_lens_heat_flow_w(i, w, -overlap, ti);
                    }
                    continue;
                }
                worst.note(overlap, ri, i, u32::MAX - w as u32);
                let n = prox.normal;
                let contact_radius_m = wall.contact_radius_m(ri);
                let kin = ContactKinematics {
                    normal: n,
                    overlap_m: overlap,
                    effective_radius_m: contact_radius_m,
                    effective_mass_kg: self.mass_kg[i],
                    contact_velocity: vi - (wi * ri).cross(&n) - prox.wall_velocity,
                    normal_velocity_m_per_s: (vi - prox.wall_velocity).dot(&n),
                    relative_angular_velocity: wi - prox.wall_angular_velocity,
                };
                let mat = self.table.get(self.species[i], wall.species);
                let mut h = hist.load_as::<P>(k);
                let out = self.law.evaluate(mat, &kin, self.dt_s, &mut h);
                hist.save_as::<P>(k, &h);
                *f += out.force;
                *t += -(n.cross(&out.tangential_force) * ri) + out.rolling_torque;
                if P::HEAT
                    && let Some(heat) = self.heat
                    && let Some(wall_temperature_k) = self.wall_temperature_k[w as usize]
                {
                    // As in `wall_slot`.
                    let conductance = heat.pair(self.species[i], wall.species).conductance_w_per_k(
                        &self.law.normal,
                        &out,
                        contact_radius_m,
                    );
                    heat_flow_w += conductance * (wall_temperature_k - ti);
                    heat_flow_w += self.wall_lens_heat_flow_w(i, w, -overlap, ti);
                }
            }
            return ScalarFlows {
                heat_flow_w,
                ..ScalarFlows::ZERO
            };
        }
        let mut flows = ScalarFlows::ZERO;
        let mut touches_a_wall = false;
        for (offset, &w) in wall_ids.iter().enumerate() {
            let (contact, bond, slot_flows) = self.wall_slot::<P>(
                i,
                x,
                vi,
                wi,
                ti,
                w,
                hist,
                first_slot + offset,
                first_slot_global + offset,
                worst,
                crossings,
            );
            if let Some((force, torque)) = contact {
                *f += force;
                *t += torque;
                touches_a_wall = true;
            }
            if P::WIDE {
                if let Some((force, torque)) = bond {
                    *f += force;
                    *t += torque;
                }
                flows.add(&slot_flows);
            }
        }
        if P::WIDE && self.statistics && touches_a_wall {
            flows.wall_contact_time_s += self.dt_s;
        }
        flows
    }

    /// One wall slot of particle i (local slot `k`, slot `slot` of the whole list): the contact law's force and
    /// torque on i while it overlaps the wall (otherwise the contact history is released), and the cohesion model's
    /// while it acts, the wall a partner of infinite radius and mass (R* = R_i, μ = m_i, a square well twice as
    /// deep: seed 001 §6.2.4.2). A glued bead is a glued particle (μ = m_i): the contact law, Hamaker's force and
    /// the square well take the pair's R*, centre distance and depth; a liquid bridge to it keeps the sphere–plane
    /// form of its tables. Third: the flows of a contact that ended here (where the run records channels).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn wall_slot<P: PassKind>(
        &self,
        i: usize,
        x: Vec3,
        vi: Vec3,
        wi: Vec3,
        ti: f64,
        w: u16,
        hist: &mut ColumnsMut,
        k: usize,
        slot: usize,
        worst: &mut WorstOverlap,
        crossings: &mut u64,
    ) -> WallSlotResult {
        let ri = self.radius_m[i];
        let wall = &self.config.walls[w as usize];
        let prox = wall.proximity_turned(&x, self.wall_turn[w as usize]);
        let overlap = ri - prox.gap_m;
        let mut flows = ScalarFlows::ZERO;
        let contact = if overlap <= 0.0 {
            if let Some(ended) = self.contact_ended::<P>(hist, k, true) {
                flows = ended;
            }
            hist.release_as::<P>(k);
            if P::HEAT {
                flows.heat_flow_w += self.wall_lens_heat_flow_w(i, w, -overlap, ti);
            }
            None
        } else {
            worst.note(overlap, ri, i, u32::MAX - w as u32);
            let n = prox.normal;
            let contact_radius_m = wall.contact_radius_m(ri);
            let kin = ContactKinematics {
                normal: n,
                overlap_m: overlap,
                effective_radius_m: contact_radius_m,
                effective_mass_kg: self.mass_kg[i],
                contact_velocity: vi - (wi * ri).cross(&n) - prox.wall_velocity,
                normal_velocity_m_per_s: (vi - prox.wall_velocity).dot(&n),
                relative_angular_velocity: wi - prox.wall_angular_velocity,
            };
            let mat = self.table.get(self.species[i], wall.species);
            let mut h = hist.load_as::<P>(k);
            let out = self.law.evaluate(mat, &kin, self.dt_s, &mut h);
            hist.save_as::<P>(k, &h);
            self.contact_lasts::<P>(hist, k);
            if P::HEAT
                && let Some(heat) = self.heat
                && let Some(wall_temperature_k) = self.wall_temperature_k[w as usize]
            {
                // The wall an infinite particle at its own temperature (seed 000 §5.1.2.1); adiabatic walls pass
                // nothing.
                let conductance = heat.pair(self.species[i], wall.species).conductance_w_per_k(
                    &self.law.normal,
                    &out,
                    contact_radius_m,
                );
                flows.heat_flow_w = conductance * (wall_temperature_k - ti);
                flows.heat_flow_w += self.wall_lens_heat_flow_w(i, w, -overlap, ti);
            }
            Some((out.force, -(n.cross(&out.tangential_force) * ri) + out.rolling_torque))
        };
        if !P::WIDE {
            return (contact, None, flows);
        }
        let Some(c) = self
            .cohesion
            .filter(|c| c.wall_range_m > 0.0 && c.wall_on.get(w as usize).copied().unwrap_or(true))
        else {
            return (contact, None, flows);
        };
        let gap = prox.gap_m - ri;
        let mut state = cohesion_state(hist, k);
        if (gap >= c.wall_range_m && state.is_empty()) || c.inert_without_bridge(state.bridge_volume_m3) {
            return (contact, None, flows);
        }
        let n = prox.normal;
        // A bead as the pair's partner sphere (radius r_b), or the wall as an infinite one.
        let (centre_distance_m, partner_radius_m, effective_radius_m, depth_factor) = match wall
            .bead_radius_m()
            .filter(|_| !matches!(c.model, CohesionModel::LiquidBridge(_)))
        {
            Some(r_b) => (prox.gap_m + r_b, ri + r_b, ri * r_b / (ri + r_b), 1.0),
            None => (prox.gap_m, ri, ri, 2.0),
        };
        let bond = Bond {
            normal: n,
            gap_m: gap,
            centre_distance_m,
            well_distance_m: c.well_ratio * partner_radius_m,
            effective_radius_m,
            effective_mass_kg: self.mass_kg[i],
            approach_m_per_s: -(vi - prox.wall_velocity).dot(&n),
            contact_velocity: vi - prox.wall_velocity - (wi * ri).cross(&n),
            depth_factor,
            wall: true,
        };
        let bridge = self.bridges.wall.get(slot).unwrap_or(&BridgeConstants::NONE);
        let out = c.force(&bond, &mut state, bridge, self.dt_s);
        hist.cohesion.in_well[k] = state.in_well;
        if P::HEAT
            && state.bridge_volume_m3 > 0.0
            && let Some(bridges) = self.heat.and_then(|h| h.bridges.as_ref())
            && let Some(wall_temperature_k) = self.wall_temperature_k[w as usize]
        {
            // A bridge to a heated wall conducts like one to a particle at the wall's temperature (eq. 7.8).
            flows.heat_flow_w +=
                bridges.wall_conductance_w_per_k(self.species[i], wall.species, state.bridge_volume_m3, gap)
                    * (wall_temperature_k - ti);
        }
        *crossings += u64::from(out.crossed_well);
        let force = n * out.normal_n + out.tangential_n;
        (contact, Some((force, -(n.cross(&out.tangential_n) * ri))), flows)
    }
}
