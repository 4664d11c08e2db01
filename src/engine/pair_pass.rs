//! The pair pass: every force between two particles or a particle and a wall — the contact law and, in a cohesive
//! run, the cohesion model's forces at a distance — and every scalar channel's flow (`engine::channels`) on every
//! particle, accumulated in one fixed order whatever the thread count.
//!
//! A wall is a partner like a particle, of infinite radius and mass with its own motion: each slot of the neighbour
//! list (pair or wall) runs the same kernels, the contact law's (`models::contact_law`) while the pair overlaps and
//! the cohesion model's (`engine::cohesion`) while it is in range or carries a state. A slot gives its force and
//! the torques on both particles (`PairResult`) and its channel flows into i (`ScalarFlows`, j receiving them by the
//! channel's rule); the channels are summed beside the forces in the same order. A dry run that records no channels compiles to the contact loop alone (the narrow
//! [`Pass`]); cohesion and channels are the wide pass's, each checked per slot at run time.
//!
//! The order for particle p is: first its contacts as the *second* particle of a pair (ascending first particle),
//! then as the first particle (ascending partner), then its walls (ascending wall index). On one thread the pair loop
//! scatters directly (f_i += F, f_j −= F), which produces exactly that order; on several threads each thread runs
//! that same loop over contiguous ranges of particles, with the few pairs that cross a range boundary
//! computed first and merged in the same order (see `sweep.rs`). Both paths run the same per-contact kernel, so
//! one and N threads give bit-identical forces.
//!
//! The second half kick of velocity Verlet is fused into this pass: a particle's force is complete when its own
//! iteration ends (its contacts as second particle came earlier), and no later pair reads its velocity, so it is
//! kicked right there instead of in another sweep over memory.

use super::Vec3;
use super::channels::{ChannelGroups, ChannelsMut, ScalarFlows};
use super::cohesion::{Bond, BridgeConstants, Cohesion};
use super::contacts::{AlignedHistory, ColumnsMut};
use super::geometry::{Wall, turns};
use super::heat::HeatConfig;
use super::heat_ledger::FixedPointSum;
use super::integrate::{InverseInertia, half_kick_one};
use super::liquid::BridgeCache;
use super::models::history::{CohesionHistory, HistoryLayout, StaticLayout};
use super::models::{ContactKinematics, ContactLaw, PairTable};
use super::neighbor::NeighborList;
use super::particles::{ParticleId, Particles, SpeciesId};
use super::range_plan::RangePlan;
use super::simulation::SimConfig;
use super::team::Team;

mod motion;
mod sweep;
mod wall_slot;

use motion::{Cells, Motion, Plain};

/// What the pass knows at compile time: the contact law's history columns (Walton-Braun's, Thornton's) and whether
/// it is the wide pass. A dry run without channels compiles to the contact loop alone; the contact history loads and
/// stores only the columns its law uses.
pub trait PassKind: StaticLayout {
    /// The wide pass: the cohesion model's forces and the scalar channels, each where the run has them (checked
    /// once per slot at run time; the narrow pass has neither in its code).
    const WIDE: bool;
    /// The pass may carry heat: the wide pass (where the run has heat), or the heat pass, which is the narrow one
    /// plus conduction and the heat channel alone (a dry run with heat transfer: through the wide pass it cost
    /// 1.27× the same run without heat, `docs/performance.md`).
    const HEAT: bool;
}

/// The pass kinds: `WB` Walton-Braun history, `TH` Thornton history, `WIDE` cohesion forces and channels, `HEAT`
/// (with `WIDE` false) conduction only.
pub struct Pass<const WB: bool, const TH: bool, const WIDE: bool, const HEAT: bool>;

impl<const WB: bool, const TH: bool, const WIDE: bool, const HEAT: bool> StaticLayout for Pass<WB, TH, WIDE, HEAT> {
    const LAYOUT: HistoryLayout = HistoryLayout {
        tangential: true,
        walton_braun: WB,
        thornton: TH,
        // The other slots (cohesion, duration) are read and written field by field where the run has them, never
        // loaded whole.
        ..HistoryLayout::NONE
    };
}

impl<const WB: bool, const TH: bool, const WIDE: bool, const HEAT: bool> PassKind for Pass<WB, TH, WIDE, HEAT> {
    const WIDE: bool = WIDE;
    const HEAT: bool = WIDE || HEAT;
}

/// Per-slot results of cross-range pairs (multi-threaded path only).
#[derive(Debug, Default, Clone)]
pub struct PairBuffers {
    force_on_i: Vec<Vec3>,
    torque_on_i: Vec<Vec3>,
    torque_on_j: Vec<Vec3>,
    /// The channels' flows into i (empty when the run records no channels).
    scalars_on_i: Vec<ScalarFlows>,
    /// The pair exerted a force (it touched, or a cohesion force acted).
    acted: Vec<bool>,
}

impl PairBuffers {
    pub fn heap_bytes(&self) -> usize {
        (self.force_on_i.capacity() + self.torque_on_i.capacity() + self.torque_on_j.capacity())
            * std::mem::size_of::<Vec3>()
            + self.scalars_on_i.capacity() * std::mem::size_of::<ScalarFlows>()
            + self.acted.capacity()
    }
}

/// The largest overlap found, relative to the smaller radius, and where.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorstOverlap {
    pub ratio: f64,
    pub overlap_m: f64,
    pub particle: u32,
    /// Particle index, or `u32::MAX - wall` for a wall.
    pub partner: u32,
}

impl WorstOverlap {
    const NONE: WorstOverlap = WorstOverlap {
        ratio: 0.0,
        overlap_m: 0.0,
        particle: 0,
        partner: 0,
    };

    #[inline]
    fn note(&mut self, overlap_m: f64, smaller_radius_m: f64, particle: usize, partner: u32) {
        // Multiply first: the division happens only for a new worst, not for every contact.
        if overlap_m <= self.ratio * smaller_radius_m {
            return;
        }
        let ratio = overlap_m / smaller_radius_m;
        if ratio > self.ratio {
            *self = WorstOverlap {
                ratio,
                overlap_m,
                particle: particle as u32,
                partner,
            };
        }
    }

    /// Converts particle indices recorded relative to a range starting at `lo` into global ones (`walls` = how
    /// many walls, whose partner codes are left as they are).
    fn shift_particles(&mut self, lo: usize, walls: usize) {
        if self.ratio > 0.0 {
            self.particle += lo as u32;
            if self.partner < u32::MAX - walls as u32 {
                self.partner += lo as u32;
            }
        }
    }

    fn max(self, other: WorstOverlap) -> WorstOverlap {
        // Ties resolve to the lower particle index so the report does not depend on the thread count.
        if other.ratio > self.ratio || (other.ratio == self.ratio && other.particle < self.particle) {
            other
        } else {
            self
        }
    }

    /// The partner as a message names it: the wall's name, or the particle's id (`ids` by index).
    pub fn partner_name(&self, walls: &[Wall], ids: &[ParticleId]) -> String {
        if self.partner >= u32::MAX - walls.len() as u32 {
            format!("wall '{}'", walls[(u32::MAX - self.partner) as usize].name)
        } else {
            format!("particle {}", ids[self.partner as usize].0)
        }
    }
}

/// The second half kick, applied to each particle as soon as its force is complete.
#[derive(Debug, Clone, Copy)]
pub struct HalfKick {
    pub gravity: Vec3,
    pub dt_s: f64,
    /// Also apply the next step's first half kick and drift to the particle (same gravity: both are at the end
    /// time of this step), saving the next step a sweep over the particle arrays. The state is then between
    /// steps; `Simulation` does this only when it runs the next step right after.
    pub fuse_next_drift: bool,
}

/// Everything one contact evaluation needs that does not change during the pass.
///
/// Per-particle properties are held as slices, and each loop works on its own copy of the context: a slice reached
/// through `&Particles` would be reloaded (pointer and length) after every store to the force arrays, which the
/// compiler cannot prove do not alias it (measured: 2.5 % fewer instructions on one thread, 7 % in the range loop).
#[derive(Clone, Copy)]
struct Context<'a> {
    config: &'a SimConfig,
    law: &'a ContactLaw,
    table: &'a PairTable,
    radius_m: &'a [f64],
    mass_kg: &'a [f64],
    species: &'a [SpeciesId],
    inv_mass_per_kg: &'a [f64],
    inv_inertia_per_kg_m2: &'a [f64],
    /// (sine, cosine) of each wall's turn angle this step.
    wall_turn: &'a [(f64, f64)],
    dt_s: f64,
    kick: Option<HalfKick>,
    /// The force and torque arrays are all zero on entry (the previous pass fused the next drift).
    accumulators_zeroed: bool,
    /// The cohesion model, in a run that has one.
    cohesion: Option<&'a Cohesion>,
    /// The constants of the standing liquid bridges, per slot of the whole list.
    bridges: &'a BridgeCache,
    /// The run records scalar channels (`engine::channels`), of any group.
    channels: bool,
    /// The run records the contact statistics (their channels and the contacts' durations).
    statistics: bool,
    /// Heat transfer: the conduction table and wall temperatures (the run then records the heat channel).
    heat: Option<&'a HeatConfig>,
    /// 1/(m c_p) per particle (heat transfer only).
    inv_thermal_mass_per_j_k: &'a [f64],
    /// Each wall's temperature this step, `None` while adiabatic (heat transfer only).
    wall_temperature_k: &'a [Option<f64>],
}

/// Result of one particle–particle slot: force on i, torques on i and j. (Its channel flows into i go to an
/// out-parameter, which the narrow pass never writes: a larger result kept the hot loop's registers busier.)
#[derive(Clone, Copy)]
struct PairResult {
    force: Vec3,
    torque_i: Vec3,
    torque_j: Vec3,
}

/// What the pair loop of particle i reads of i, loaded once per particle rather than once per candidate.
#[derive(Clone, Copy)]
struct Body {
    x: Vec3,
    v: Vec3,
    w: Vec3,
    radius_m: f64,
    mass_kg: f64,
    species: SpeciesId,
}

impl<'a> Context<'a> {
    /// The context of a pass over `p` (whose per-particle properties it holds; positions and velocities are read
    /// through a [`Motion`]).
    #[allow(clippy::too_many_arguments)]
    fn new(
        config: &'a SimConfig,
        p: &'a Particles,
        inverse: &'a InverseInertia,
        wall_turn: &'a [(f64, f64)],
        dt_s: f64,
        kick: Option<HalfKick>,
        accumulators_zeroed: bool,
        cohesion: Option<&'a Cohesion>,
        bridges: &'a BridgeCache,
        channels: ChannelGroups,
        wall_temperature_k: &'a [Option<f64>],
    ) -> Self {
        Context {
            config,
            law: &config.contact_law,
            table: &config.pair_table,
            radius_m: &p.radius_m,
            mass_kg: &p.mass_kg,
            species: &p.species,
            inv_mass_per_kg: &inverse.inv_mass_per_kg,
            inv_inertia_per_kg_m2: &inverse.inv_inertia_per_kg_m2,
            wall_turn,
            dt_s,
            kick,
            accumulators_zeroed,
            cohesion,
            bridges,
            channels: channels != ChannelGroups::NONE,
            statistics: channels.statistics,
            heat: config.heat.as_ref().filter(|_| channels.heat),
            inv_thermal_mass_per_j_k: &inverse.inv_thermal_mass_per_j_k,
            wall_temperature_k,
        }
    }

    /// Where the run records channels and slot `k` (touching until now) separates: the contact's duration, taken
    /// out of its slot, as the flows of an ended contact (`wall`: to a wall). `None` otherwise.
    #[inline(always)]
    fn contact_ended<P: PassKind>(&self, hist: &mut ColumnsMut, k: usize, wall: bool) -> Option<ScalarFlows> {
        if !(P::WIDE && self.statistics && hist.touching[k]) {
            return None;
        }
        let duration_s = std::mem::replace(&mut hist.duration.duration_s[k], 0.0);
        Some(if wall {
            ScalarFlows {
                wall_contacts_ended: 1.0,
                wall_contact_time_ended_s: duration_s,
                ..ScalarFlows::ZERO
            }
        } else {
            ScalarFlows {
                contacts_ended: 1.0,
                contact_time_ended_s: duration_s,
                ..ScalarFlows::ZERO
            }
        })
    }

    /// Where the run records channels: slot `k` touches for one more step.
    #[inline(always)]
    fn contact_lasts<P: PassKind>(&self, hist: &mut ColumnsMut, k: usize) {
        if P::WIDE && self.statistics {
            hist.duration.duration_s[k] += self.dt_s;
        }
    }

    #[inline(always)]
    fn body(&self, i: usize, vel: &impl Motion) -> Body {
        Body {
            x: vel.x(i),
            v: vel.v(i),
            w: vel.w(i),
            radius_m: self.radius_m[i],
            mass_kg: self.mass_kg[i],
            species: self.species[i],
        }
    }

    /// Evaluates the pair (i, j) in local history slot `k` (slot `slot` of the whole list): the contact law if it
    /// overlaps (otherwise the slot's contact history is released), and the cohesion model if one acts. `bi` is
    /// [`Context::body`] of i. `None`: no force.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn pair<P: PassKind>(
        &self,
        i: usize,
        bi: &Body,
        j: usize,
        vel: &impl Motion,
        hist: &mut ColumnsMut,
        k: usize,
        slot: usize,
        worst: &mut WorstOverlap,
        crossings: &mut u64,
        flows: &mut ScalarFlows,
    ) -> Option<PairResult> {
        let d = self.config.domain.separation(&bi.x, &vel.x(j));
        let dist2 = d.norm_squared();
        let (ri, rj) = (bi.radius_m, self.radius_m[j]);
        let reach = ri + rj;
        let cohesion = if P::WIDE {
            self.cohesion.filter(|c| c.between_particles)
        } else {
            None
        };
        if dist2 >= reach * reach {
            if let Some(ended) = self.contact_ended::<P>(hist, k, false) {
                *flows = ended;
            }
            hist.release_as::<P>(k);
            if P::HEAT
                && let Some(lens) = self.heat.and_then(|h| h.lens.as_ref())
            {
                // Apart, the gas between the surfaces still conducts while the lens reaches across.
                let lens_reach = reach + lens.reach_m(if ri > rj { ri } else { rj });
                if dist2 < lens_reach * lens_reach {
                    flows.heat_flow_w += lens.pair_conductance_w_per_k(ri, rj, dist2.sqrt()) * (vel.t(j) - vel.t(i));
                }
            }
            // Apart: the cohesion model alone, while in range or carrying a bridge or well.
            let c = cohesion?;
            if c.inert_without_bridge(hist.cohesion.bridge_volume_m3[k]) {
                return None;
            }
            let range = reach + c.range_m;
            if dist2 >= range * range && cohesion_state(hist, k).is_empty() {
                return None;
            }
            let dist = dist2.sqrt();
            let bond = self.pair_bond(c, bi, j, vel, d, dist, reach, hist, k, slot, crossings);
            if P::HEAT {
                flows.heat_flow_w += self.bridge_heat_flow_w(i, bi, j, vel, hist, k, dist - reach);
            }
            return Some(bond);
        }
        let dist = dist2.sqrt();
        let inv_dist = 1.0 / dist;
        let n = d * inv_dist;
        let dv = bi.v - vel.v(j);
        let overlap = reach - dist;
        // Not `f64::min`: radii are never NaN, and its NaN handling costs five instructions per contact.
        worst.note(overlap, if ri < rj { ri } else { rj }, i, j as u32);
        let (wi, wj) = (bi.w, vel.w(j));
        let (mi, mj) = (bi.mass_kg, self.mass_kg[j]);
        // R* = r_i r_j/(r_i + r_j) and m* = m_i m_j/(m_i + m_j) from one division: divisions share a unit with
        // the square roots of the contact's critical path.
        let mass_sum = mi + mj;
        let inv_reach_mass_sum = 1.0 / (reach * mass_sum);
        let kin = ContactKinematics {
            normal: n,
            overlap_m: overlap,
            effective_radius_m: ri * rj * (mass_sum * inv_reach_mass_sum),
            effective_mass_kg: mi * mj * (reach * inv_reach_mass_sum),
            contact_velocity: dv - (wi * ri + wj * rj).cross(&n),
            normal_velocity_m_per_s: dv.dot(&d) * inv_dist,
            relative_angular_velocity: wi - wj,
        };
        let mat = self.table.get(bi.species, self.species[j]);
        let mut h = hist.load_as::<P>(k);
        let out = self.law.evaluate(mat, &kin, self.dt_s, &mut h);
        hist.save_as::<P>(k, &h);
        self.contact_lasts::<P>(hist, k);
        if P::HEAT
            && let Some(heat) = self.heat
        {
            // Q = H (T_j − T_i) into i (seed 000 eq. 5.3); j receives the opposite. With the gas lens, the gas
            // round the contact conducts beside it.
            let mut conductance = heat.pair(bi.species, self.species[j]).conductance_w_per_k(
                &self.law.normal,
                &out,
                kin.effective_radius_m,
            );
            if let Some(lens) = &heat.lens {
                conductance += lens.pair_conductance_w_per_k(ri, rj, dist);
            }
            flows.heat_flow_w = conductance * (vel.t(j) - vel.t(i));
        }
        let nxft = n.cross(&out.tangential_force);
        let contact = PairResult {
            force: out.force,
            torque_i: -(nxft * ri) + out.rolling_torque,
            torque_j: -(nxft * rj) - out.rolling_torque,
        };
        match cohesion {
            None => Some(contact),
            Some(c) if c.inert_without_bridge(hist.cohesion.bridge_volume_m3[k]) => Some(contact),
            Some(c) => {
                let bond = self.pair_bond(c, bi, j, vel, d, dist, reach, hist, k, slot, crossings);
                if P::HEAT {
                    flows.heat_flow_w += self.bridge_heat_flow_w(i, bi, j, vel, hist, k, dist - reach);
                }
                Some(PairResult {
                    force: contact.force + bond.force,
                    torque_i: contact.torque_i + bond.torque_i,
                    torque_j: contact.torque_j + bond.torque_j,
                })
            }
        }
    }

    /// Conduction through the liquid bridge of local pair slot `k` at surface gap `gap_m`, if the run conducts
    /// through bridges and the slot holds one: H_l (T_j − T_i) into i (seed 000 eq. 7.8), W.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn bridge_heat_flow_w(
        &self,
        i: usize,
        bi: &Body,
        j: usize,
        vel: &impl Motion,
        hist: &ColumnsMut,
        k: usize,
        gap_m: f64,
    ) -> f64 {
        let Some(bridges) = self.heat.and_then(|h| h.bridges.as_ref()) else {
            return 0.0;
        };
        let volume_m3 = hist.cohesion.bridge_volume_m3[k];
        if volume_m3 > 0.0 {
            bridges.pair_conductance_w_per_k(bi.species, self.species[j], volume_m3, gap_m) * (vel.t(j) - vel.t(i))
        } else {
            0.0
        }
    }

    /// The cohesion force of the pair (i, j) in local slot `k`, with the pair's geometry formed as seed 000 and
    /// seed 001 write it (n = d/|d|, R* = R_i R_j/(R_i + R_j), μ = m_i m_j/(m_i + m_j)).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn pair_bond(
        &self,
        c: &Cohesion,
        bi: &Body,
        j: usize,
        vel: &impl Motion,
        d: Vec3,
        dist: f64,
        reach: f64,
        hist: &mut ColumnsMut,
        k: usize,
        slot: usize,
        crossings: &mut u64,
    ) -> PairResult {
        let (ri, rj) = (bi.radius_m, self.radius_m[j]);
        let (mi, mj) = (bi.mass_kg, self.mass_kg[j]);
        let normal = d / dist;
        let u = bi.v - vel.v(j);
        let bond = Bond {
            normal,
            gap_m: dist - reach,
            centre_distance_m: dist,
            well_distance_m: c.well_ratio * reach,
            effective_radius_m: ri * rj / reach,
            effective_mass_kg: mi * mj / (mi + mj),
            approach_m_per_s: -u.dot(&normal),
            contact_velocity: u - (bi.w * ri + vel.w(j) * rj).cross(&normal),
            depth_factor: 1.0,
            wall: false,
        };
        let mut state = cohesion_state(hist, k);
        let bridge = self.bridges.pair.get(slot).unwrap_or(&BridgeConstants::NONE);
        let out = c.force(&bond, &mut state, bridge, self.dt_s);
        hist.cohesion.in_well[k] = state.in_well;
        *crossings += u64::from(out.crossed_well);
        let nxft = normal.cross(&out.tangential_n);
        PairResult {
            force: normal * out.normal_n + out.tangential_n,
            torque_i: -(nxft * ri),
            torque_j: -(nxft * rj),
        }
    }

    /// Completes particle i once all its pair contributions are in (f, t): its walls, then [`Context::finish`],
    /// storing the new motion. `wall_ids` are i's walls, whose history is in `walls` from `first_wall_slot` on (slot
    /// `first_wall_slot_global` of the whole list). Adds the walls' flows to i's channels and, with heat transfer,
    /// advances i's temperature by the step's conduction. Returns the final (f, t).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn complete<P: PassKind>(
        &self,
        i: usize,
        mut f: Vec3,
        mut t: Vec3,
        motion: &Cells,
        wall_ids: &[u16],
        walls: &mut ColumnsMut,
        first_wall_slot: usize,
        first_wall_slot_global: usize,
        channels: &mut ChannelsMut,
        tally: &mut Tally,
    ) -> (Vec3, Vec3) {
        let (xi, vi, wi) = (motion.x(i), motion.v(i), motion.w(i));
        let ti = if P::HEAT && self.heat.is_some() {
            motion.t(i)
        } else {
            0.0
        };
        let flows = self.walls::<P>(
            i,
            xi,
            vi,
            wi,
            ti,
            wall_ids,
            walls,
            first_wall_slot,
            first_wall_slot_global,
            &mut f,
            &mut t,
            &mut tally.worst,
            &mut tally.well_crossings,
        );
        if P::WIDE && self.channels {
            channels.add(i, &flows);
        } else if P::HEAT && self.heat.is_some() {
            channels.heat_flow_w[i] += flows.heat_flow_w;
        }
        if P::HEAT && self.heat.is_some() {
            // All of i's conduction is in: one explicit step of m c_p dT/dt = Q (seed 000 eq. 5.2), the channel
            // left zero for the next step. The pass that only computes the initial forces (no kick) moves nothing.
            let heat_flow_w = std::mem::replace(&mut channels.heat_flow_w[i], 0.0);
            if self.kick.is_some() {
                motion.set_t(i, ti + self.dt_s * heat_flow_w * self.inv_thermal_mass_per_j_k[i]);
                // The walls' share, for the energy ledger (`engine::heat_ledger`).
                tally.wall_heat_flow_w.add(flows.heat_flow_w);
            }
        }
        let (x_new, v_new, w_new, d2) = self.finish(i, &mut f, &mut t, xi, vi, wi);
        tally.velocity_sum += (v_new.x + v_new.y + v_new.z) + (w_new.x + w_new.y + w_new.z);
        tally.max_displacement2 = tally.max_displacement2.max(d2);
        motion.set(i, x_new, v_new, w_new);
        if self.kick.is_some_and(|k| k.fuse_next_drift) {
            // The next step's pass accumulates into these arrays: leave them zero (see `compute_pair_forces`).
            (Vec3::zeros(), Vec3::zeros())
        } else {
            (f, t)
        }
    }

    /// Finishes particle i once its force and torque are complete: pseudo-2-D projection, the half kick, and when
    /// fusing, the next step's half kick and drift. Returns (x, v, ω) to store and the square of that drift's
    /// displacement (0 when not drifting), from which the simulation bounds how far any particle has moved since the
    /// neighbour list was built.
    #[inline(always)]
    fn finish(&self, i: usize, f: &mut Vec3, t: &mut Vec3, x: Vec3, v: Vec3, w: Vec3) -> (Vec3, Vec3, Vec3, f64) {
        if self.config.pseudo_2d {
            f.z = 0.0;
            t.x = 0.0;
            t.y = 0.0;
        }
        let Some(k) = self.kick else {
            return (x, v, w, 0.0);
        };
        let half_dt = 0.5 * k.dt_s;
        let g_half_dt = k.gravity * half_dt;
        let (inv_m, inv_i) = (self.inv_mass_per_kg[i], self.inv_inertia_per_kg_m2[i]);
        let (mut x, mut v, mut w) = (x, v, w);
        half_kick_one(&mut v, &mut w, f, t, inv_m, inv_i, &g_half_dt, half_dt);
        if self.config.pseudo_2d {
            v.z = 0.0;
            w.x = 0.0;
            w.y = 0.0;
        }
        if !k.fuse_next_drift {
            return (x, v, w, 0.0);
        }
        // Exactly what `integrate::kick_drift` does for the next step, one particle at a time.
        half_kick_one(&mut v, &mut w, f, t, inv_m, inv_i, &g_half_dt, half_dt);
        if self.config.pseudo_2d {
            v.z = 0.0;
            w.x = 0.0;
            w.y = 0.0;
        }
        let dx = v * k.dt_s;
        x += dx;
        self.config.domain.wrap(&mut x);
        (x, v, w, dx.norm_squared())
    }
}

/// The cohesion slot of local slot `k` (the view must have the cohesion columns).
#[inline(always)]
fn cohesion_state(hist: &ColumnsMut, k: usize) -> CohesionHistory {
    CohesionHistory {
        bridge_volume_m3: hist.cohesion.bridge_volume_m3[k],
        in_well: hist.cohesion.in_well[k],
    }
}

/// What a loop over particles accumulates besides forces.
#[derive(Debug, Clone, Copy)]
struct Tally {
    worst: WorstOverlap,
    /// A NaN or infinity in any kicked velocity propagates into this sum; the culprit is looked for only then.
    velocity_sum: f64,
    max_displacement2: f64,
    /// Square-well crossings.
    well_crossings: u64,
    /// Heat flowing from the walls into the kicked particles, W (order-independent: the same bits on any threads).
    wall_heat_flow_w: FixedPointSum,
}

impl Tally {
    /// Adds what a later loop over other particles found.
    fn merge(&mut self, later: Tally) {
        self.worst = self.worst.max(later.worst);
        self.velocity_sum += later.velocity_sum;
        self.max_displacement2 = self.max_displacement2.max(later.max_displacement2);
        self.well_crossings += later.well_crossings;
        self.wall_heat_flow_w.merge(later.wall_heat_flow_w);
    }
}

impl Default for Tally {
    fn default() -> Self {
        Tally {
            worst: WorstOverlap::NONE,
            velocity_sum: 0.0,
            max_displacement2: 0.0,
            well_crossings: 0,
            wall_heat_flow_w: FixedPointSum::default(),
        }
    }
}

/// A vector is finite when the sum of its components is (a NaN or infinity anywhere propagates).
#[inline(always)]
fn finite(v: &Vec3) -> bool {
    (v.x + v.y + v.z).is_finite()
}

/// The first index (offset by `base`) whose velocity or angular velocity is not finite, looked for only when
/// `sum` (of all their components) is not finite.
fn first_non_finite(sum: f64, v: &[Vec3], w: &[Vec3], base: usize) -> Option<usize> {
    if sum.is_finite() {
        return None;
    }
    v.iter()
        .zip(w)
        .position(|(v, w)| !(finite(v) && finite(w)))
        .map(|k| base + k)
}

/// What the force pass reports.
#[derive(Debug, Clone, Copy)]
pub struct ForcePass {
    pub worst_overlap: WorstOverlap,
    /// First particle whose kicked velocity or angular velocity is not finite.
    pub non_finite: Option<usize>,
    /// With a fused drift: the largest squared displacement of a particle in that drift (0 without one).
    pub max_displacement2_m2: f64,
    /// Square-well crossings in this pass.
    pub well_crossings: u64,
    /// With heat transfer and a kick: the heat flowing from the walls into the particles this step, W.
    pub wall_heat_flow_w: f64,
}

/// Computes the forces and torques of every pair and wall slot into `p.force_n` and `p.torque_n_m` (adding onto
/// what they hold, e.g. the gas's forces) and, with `kick`, applies the second half kick to every particle.
/// `cohesion`: the cohesion model when it acts this step, with `bridges` the constants of the standing bridges.
/// Where the run records channels (`p.channels` not empty) the pass adds into them and times the contacts; with heat
/// transfer it conducts heat through every contact and into the walls at `wall_temperature_k` (this step's), and
/// advances each particle's temperature.
///
/// The force and torque arrays are the accumulators of the pass. When the kick fuses the next step's drift, the
/// totals are consumed at once and the arrays are left zero instead, so that the next pass (told so by
/// `accumulators_zeroed`) need not clear them: a sweep over 48 bytes per particle saved per step. The totals are
/// stored by every pass that does not fuse, which is the last step of every `Simulation::run_steps`.
#[allow(clippy::too_many_arguments)]
pub fn compute_pair_forces(
    config: &SimConfig,
    p: &mut Particles,
    inverse: &InverseInertia,
    wall_angle: &[f64],
    dt_s: f64,
    list: &NeighborList,
    history: &mut AlignedHistory,
    buffers: &mut PairBuffers,
    plan: &RangePlan,
    team: &Team,
    kick: Option<HalfKick>,
    accumulators_zeroed: bool,
    cohesion: Option<&Cohesion>,
    bridges: &BridgeCache,
    wall_temperature_k: &[Option<f64>],
) -> ForcePass {
    let mut force = std::mem::take(&mut p.force_n);
    let mut torque = std::mem::take(&mut p.torque_n_m);
    let mut position = std::mem::take(&mut p.position_m);
    let mut velocity = std::mem::take(&mut p.velocity_m_per_s);
    let mut omega = std::mem::take(&mut p.angular_velocity_rad_per_s);
    let mut temperature = std::mem::take(&mut p.temperature_k);
    let mut channels = std::mem::take(&mut p.channels);
    let channels_on = channels.is_on();
    let wall_turn = turns(wall_angle);
    let ctx = Context::new(
        config,
        p,
        inverse,
        &wall_turn,
        dt_s,
        kick,
        accumulators_zeroed,
        cohesion,
        bridges,
        channels.groups(),
        wall_temperature_k,
    );
    // One instantiation per pass kind: the layout decides which history fields exist, and knowing it at compile
    // time lets the kernels' unused fields vanish from the loop; a dry run has no cohesion code in it.
    let layout = config.contact_law.history_layout();
    macro_rules! run {
        ($wb:literal, $th:literal, $co:literal) => {
            run!($wb, $th, $co, false)
        };
        ($wb:literal, $th:literal, $co:literal, $heat:literal) => {
            if team.size() == 1 || plan.bounds.len() <= 2 {
                sweep::serial::<Pass<$wb, $th, $co, $heat>>(
                    &ctx,
                    list,
                    history,
                    &mut force,
                    &mut torque,
                    &mut position,
                    &mut velocity,
                    &mut omega,
                    &mut temperature,
                    &mut channels,
                )
            } else {
                sweep::parallel::<Pass<$wb, $th, $co, $heat>>(
                    &ctx,
                    list,
                    history,
                    buffers,
                    &mut force,
                    &mut torque,
                    &mut position,
                    &mut velocity,
                    &mut omega,
                    &mut temperature,
                    &mut channels,
                    plan,
                    team,
                )
            }
        };
    }
    // A run whose only channel is heat, with a contact law without Walton-Braun's or Thornton's history (the kiln,
    // the drums), takes the heat pass; any other run with heat the wide one.
    let groups = channels.groups();
    let heat_only = groups.heat && !groups.statistics && cohesion.is_none();
    let wide = cohesion.is_some() || channels_on;
    let pass = match (layout.walton_braun, layout.thornton, wide) {
        (false, false, true) if heat_only => run!(false, false, false, true),
        (false, false, false) => run!(false, false, false),
        (true, false, false) => run!(true, false, false),
        (false, true, false) => run!(false, true, false),
        (true, true, false) => run!(true, true, false),
        (false, false, true) => run!(false, false, true),
        (true, false, true) => run!(true, false, true),
        (false, true, true) => run!(false, true, true),
        (true, true, true) => run!(true, true, true),
    };
    p.force_n = force;
    p.torque_n_m = torque;
    p.position_m = position;
    p.velocity_m_per_s = velocity;
    p.angular_velocity_rad_per_s = omega;
    p.temperature_k = temperature;
    p.channels = channels;
    pass
}

/// Adds each wall's contact force and cohesion force on all particles to `contact_n` and `cohesion_n` (index = wall),
/// exactly as the next pair pass will compute them: same positions, velocities and history, the same kernels, with
/// the history left untouched. For the net-force split ([`super::net_force`]); call it right before that pass.
/// Particles are summed in ascending order, so the sums do not depend on the thread count.
#[allow(clippy::too_many_arguments)]
pub fn add_wall_forces(
    config: &SimConfig,
    p: &Particles,
    inverse: &InverseInertia,
    wall_angle: &[f64],
    dt_s: f64,
    list: &NeighborList,
    history: &AlignedHistory,
    cohesion: Option<&Cohesion>,
    bridges: &BridgeCache,
    contact_n: &mut [Vec3],
    cohesion_n: &mut [Vec3],
) {
    // (Channels off: this pass only reads the forces, and leaves the history and the channels untouched.)
    let wall_turn = turns(wall_angle);
    let ctx = Context::new(
        config,
        p,
        inverse,
        &wall_turn,
        dt_s,
        None,
        false,
        cohesion,
        bridges,
        ChannelGroups::NONE,
        &[],
    );
    let motion = Plain {
        x: &p.position_m,
        v: &p.velocity_m_per_s,
        w: &p.angular_velocity_rad_per_s,
        t: &p.temperature_k,
    };
    let mut scratch = history.wall.clone();
    let layout = config.contact_law.history_layout();
    macro_rules! run {
        ($wb:literal, $th:literal, $co:literal) => {{
            let mut walls = scratch.view();
            let (mut worst, mut crossings) = (WorstOverlap::NONE, 0);
            for i in 0..p.len() {
                for k in list.walls_of(i) {
                    let wall = list.wall_partner[k];
                    let (contact, bond, _) = ctx.wall_slot::<Pass<$wb, $th, $co, false>>(
                        i,
                        motion.x(i),
                        motion.v(i),
                        motion.w(i),
                        0.0,
                        wall,
                        &mut walls,
                        k,
                        k,
                        &mut worst,
                        &mut crossings,
                    );
                    if let Some((force, _)) = contact {
                        contact_n[wall as usize] += force;
                    }
                    if let Some((force, _)) = bond {
                        cohesion_n[wall as usize] += force;
                    }
                }
            }
        }};
    }
    match (layout.walton_braun, layout.thornton, cohesion.is_some()) {
        (false, false, false) => run!(false, false, false),
        (true, false, false) => run!(true, false, false),
        (false, true, false) => run!(false, true, false),
        (true, true, false) => run!(true, true, false),
        (false, false, true) => run!(false, false, true),
        (true, false, true) => run!(true, false, true),
        (false, true, true) => run!(false, true, true),
        (true, true, true) => run!(true, true, true),
    }
}
