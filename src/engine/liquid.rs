//! The liquid inventory of a wet run: the liquid each particle carries and the liquid held in bridges, and every
//! event that moves liquid between them — spray onto the bed's surface, bridge formation on contact, the split of a
//! breaking bridge (and, later, evaporation).
//!
//! - A bridge forms when two particles touch and takes the liquid on each one's cap facing the other (seed 000
//!   eqs 6.1–6.4); a bridge to a wall (the wall a sphere of infinite radius) takes half the particle's liquid. A
//!   bridge that would hold less than [`SMALLEST_BRIDGE`] of the smaller particle's R³ does not form: the liquid
//!   stays on the films.
//! - It keeps its volume until the gap passes the rupture gap, when the volume goes back to the two particles in the
//!   shares of the parabolic bridge (6.33–6.44); a wall keeps nothing (CHOICE: the film a wall would keep is not
//!   tracked), so all of it returns to the particle.
//! - The particles' liquid and the bridges' volumes always add up to the start plus what was sprayed (changed only
//!   by rounding).
//!
//! The events run once per step, serially over particles in index order (pairs of i, then walls of i), before the
//! pair pass, so their results do not depend on the thread count. The pair pass then only reads the bridge volumes
//! (in the contact records' cohesion slot) and the bridge constants kept here. What does not live here: the forces
//! of bridges (`engine::cohesion`), finding the surface particles (`engine::spray`).

use super::cohesion::{BridgeConstants, Cohesion};
use super::config::SimConfig;
use super::contacts::AlignedHistory;
use super::models::cohesion_law::CohesionModel;
use super::neighbor::NeighborList;
use super::particles::Particles;
use super::spray::spray_surface;

/// The smallest bridge, over the smaller particle's R³: a bridge that would form with less does not form (its
/// particles keep their films), and one that evaporation leaves below it breaks (`engine::drying`). CHOICE: the
/// smallest volume the bridge tables hold (`models::bridge_conduction`), far below the smallest Mikami fitted; his
/// fit extrapolated to vanishing volumes gives a force that grows without bound as ln V̂ → −∞ (eqs 2.16–2.17:
/// F̂ ≈ 2,600 at V̂ = 1e-170 against 2.4 at 1e-3), while a real bridge's force tends to a finite limit. Without
/// the floor, a drying drum's films shrunk step after step formed bridges of 1e-120 m³ (and, once a film under it
/// evaporated at each gas step, bridges of 1e-173 m³ from films split between gas steps by formation after
/// formation), which pulled E6's beads into quarter-radius overlaps.
pub const SMALLEST_BRIDGE: f64 = 1e-6;

/// Per pair and wall slot of the neighbour list: the constants of its bridge for the volume they were computed for,
/// and which slots are near enough to a formation or rupture to be examined every step (workspace: rebuilt from the
/// state, never checkpointed; cleared whenever the list is rebuilt).
#[derive(Debug, Clone, Default)]
pub struct BridgeCache {
    pub pair: Vec<BridgeConstants>,
    pub wall: Vec<BridgeConstants>,
    watch: Watch,
}

/// The slots the liquid inventory examines between two full passes.
///
/// At a full pass every pair and wall slot is examined, and those whose state could change within a move of
/// `margin_m` are listed (`near`): a pair without a bridge whose surface gap is below `margin_m` (it may touch), one
/// with a bridge whose gap is within `margin_m` of its rupture gap, and likewise for wall slots. A pair's gap changes
/// by at most the two particles' displacements and a wall slot's by the particle's (walls that move are always
/// listed), so until some particle may have moved `margin_m / 2` (the simulation's drift bound, a sum of each
/// step's largest displacement) no slot outside the list can form or break a bridge, and examining only the listed
/// ones, in the full pass's order, gives the same events as examining every slot.
#[derive(Debug, Clone, Default)]
struct Watch {
    /// (particle, slot) in the full pass's order; wall slots carry [`WALL_SLOT`].
    near: Vec<(u32, u32)>,
    /// The drift bound at the last full pass; `None` before the first since the list was built.
    drift_bound_at_pass_m: Option<f64>,
}

/// Marks a wall slot in [`Watch::near`].
const WALL_SLOT: u32 = 1 << 31;

impl BridgeCache {
    /// Makes the next liquid step examine every slot (and refresh every bridge's constants): the bridges' volumes
    /// changed outside it (evaporation).
    pub fn forget_watch(&mut self) {
        self.watch.drift_bound_at_pass_m = None;
    }

    /// Sized for `list`, every entry unset, when it is not already.
    fn fit(&mut self, list: &NeighborList) {
        if self.pair.len() != list.partner.len() {
            self.pair.clear();
            self.pair.resize(list.partner.len(), BridgeConstants::NONE);
        }
        if self.wall.len() != list.wall_partner.len() {
            self.wall.clear();
            self.wall.resize(list.wall_partner.len(), BridgeConstants::NONE);
        }
    }
}

/// What moved liquid in one step or more.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LiquidEvents {
    pub bridges_formed: u64,
    pub bridges_ruptured: u64,
    /// Liquid sprayed, m³.
    pub sprayed_m3: f64,
}

impl LiquidEvents {
    pub fn add(&mut self, other: LiquidEvents) {
        self.bridges_formed += other.bridges_formed;
        self.bridges_ruptured += other.bridges_ruptured;
        self.sprayed_m3 += other.sprayed_m3;
    }
}

/// One step of the liquid inventory at time `time_s` (the end of step `step`), for a run with liquid bridges: the
/// spray when it is due, then, from `bridges_from_s` on, bridge formation and rupture at the current positions.
/// Leaves `cache` holding the constants of every standing bridge.
#[allow(clippy::too_many_arguments)]
pub fn step_liquid(
    cohesion: &Cohesion,
    config: &SimConfig,
    p: &mut Particles,
    list: &NeighborList,
    history: &mut AlignedHistory,
    cache: &mut BridgeCache,
    wall_angle_rad: &[f64],
    time_s: f64,
    step: u64,
    dt_s: f64,
    drift_bound_m: f64,
    watch_margin_m: f64,
) -> LiquidEvents {
    let CohesionModel::LiquidBridge(b) = cohesion.model else {
        return LiquidEvents::default();
    };
    let mut events = LiquidEvents::default();
    if let Some(spray) = b.spray
        && dt_s > 0.0
        && time_s >= spray.start_s
        && step.is_multiple_of(spray.every_steps)
    {
        let g = config.gravity.at(time_s);
        events.sprayed_m3 += spray_surface(p, &g, spray.max_liquid_content);
    }
    // Before `bridges_from_s` the particles carry their liquid but touch dry.
    if time_s >= b.bridges_from_s {
        let bridges = exchange_bridges(
            cohesion,
            config,
            p,
            list,
            history,
            cache,
            wall_angle_rad,
            drift_bound_m,
            watch_margin_m,
        );
        events.bridges_formed += bridges.bridges_formed;
        events.bridges_ruptured += bridges.bridges_ruptured;
    }
    events
}

/// Relative margin on a squared centre distance within which [`exchange_bridges`] takes the square root to decide
/// whether a pair touches or its bridge has ruptured. Outside it the squared comparison gives the same answer as the
/// rounded gap: the products' rounding is below 1e-15 relative, and the square root and the subtraction round
/// monotonically towards a threshold that is itself a double. (The decisions, hence the bits, are those of the gap
/// taken for every pair in range.)
const SQUARED_DECISION_MARGIN: f64 = 1e-12;

/// Bridge formation and rupture over every pair and wall slot, serially in index order (pairs of particle i, then
/// its wall slots): over all of them when some particle may have moved `watch_margin_m / 2` since the last full
/// pass (or there has been none since the list was built), otherwise over the slots that pass found near a change
/// ([`Watch`]), with the same events.
#[allow(clippy::too_many_arguments)]
fn exchange_bridges(
    cohesion: &Cohesion,
    config: &SimConfig,
    p: &mut Particles,
    list: &NeighborList,
    history: &mut AlignedHistory,
    cache: &mut BridgeCache,
    wall_angle_rad: &[f64],
    drift_bound_m: f64,
    watch_margin_m: f64,
) -> LiquidEvents {
    cache.fit(list);
    let mut events = LiquidEvents::default();
    let mut ex = Exchange {
        cohesion,
        config,
        p,
        list,
        pair_volume: &mut history.pair.cohesion.bridge_volume_m3,
        wall_volume: &mut history.wall.cohesion.bridge_volume_m3,
        pair_cache: &mut cache.pair,
        wall_cache: &mut cache.wall,
        wall_angle_rad,
        events: &mut events,
    };
    let watch = &mut cache.watch;
    let recent = watch
        .drift_bound_at_pass_m
        .is_some_and(|at| drift_bound_m >= at && 2.0 * (drift_bound_m - at) < watch_margin_m);
    if recent {
        for &(i, slot) in &watch.near {
            if slot & WALL_SLOT == 0 {
                ex.pair(i as usize, slot as usize);
            } else {
                ex.wall(i as usize, (slot & !WALL_SLOT) as usize);
            }
        }
        return events;
    }
    watch.near.clear();
    watch.drift_bound_at_pass_m = Some(drift_bound_m);
    for i in 0..ex.p.len() {
        if cohesion.between_particles {
            for k in list.pairs_of(i) {
                if ex.pair(i, k) < watch_margin_m {
                    watch.near.push((i as u32, k as u32));
                }
            }
        }
        if cohesion.wall_range_m > 0.0 {
            for k in list.walls_of(i) {
                if ex.wall(i, k) < watch_margin_m {
                    watch.near.push((i as u32, k as u32 | WALL_SLOT));
                }
            }
        }
    }
    events
}

/// What the formation and rupture of one slot read and change.
struct Exchange<'a> {
    cohesion: &'a Cohesion,
    config: &'a SimConfig,
    p: &'a mut Particles,
    list: &'a NeighborList,
    pair_volume: &'a mut [f64],
    wall_volume: &'a mut [f64],
    pair_cache: &'a mut [BridgeConstants],
    wall_cache: &'a mut [BridgeConstants],
    wall_angle_rad: &'a [f64],
    events: &'a mut LiquidEvents,
}

impl Exchange<'_> {
    /// Forms or breaks the bridge of pair slot `k` of particle `i` when its state calls for it. Returns how far
    /// its surface gap is from the next change (formation at 0 without a bridge, rupture at the rupture gap with
    /// one), m; negative or zero when it is at one.
    fn pair(&mut self, i: usize, k: usize) -> f64 {
        let (cohesion, p) = (self.cohesion, &mut *self.p);
        let j = self.list.partner[k] as usize;
        let (xi, ri, si) = (p.position_m[i], p.radius_m[i], p.species[i]);
        let (rj, sj) = (p.radius_m[j], p.species[j]);
        let reach = ri + rj;
        let gap_to = |p: &Particles| self.config.domain.separation(&p.position_m[i], &p.position_m[j]).norm() - reach;
        // No bridge and no liquid on either particle: nothing can form or rupture (a dry bed's every pair).
        if self.pair_volume[k] == 0.0 && p.liquid_m3[i] == 0.0 && p.liquid_m3[j] == 0.0 {
            return gap_to(p);
        }
        let d = self.config.domain.separation(&xi, &p.position_m[j]);
        let dist2 = d.norm_squared();
        let mut volume = self.pair_volume[k];
        // Out of range and carrying nothing: the common case.
        let range = reach + cohesion.range_m;
        if dist2 >= range * range && volume == 0.0 {
            return dist2.sqrt() - reach;
        }
        // The surface gap (a square root) is needed only near the thresholds: touching for a pair without a
        // bridge, the rupture gap for one with. Elsewhere the squared distance, with a margin far above its
        // rounding, decides the same way ([`SQUARED_DECISION_MARGIN`]).
        if volume == 0.0 && dist2 > reach * reach * (1.0 + SQUARED_DECISION_MARGIN) {
            return dist2.sqrt() - reach;
        }
        if volume == 0.0 && dist2.sqrt() - reach < 0.0 {
            let (from_i, from_j) = cohesion.pair_bridge_take_m3(p.liquid_m3[i], ri, p.liquid_m3[j], rj);
            if from_i + from_j >= SMALLEST_BRIDGE * ri.min(rj).powi(3) {
                p.liquid_m3[i] -= from_i;
                p.liquid_m3[j] -= from_j;
                volume = from_i + from_j;
                self.events.bridges_formed += 1;
            }
        }
        let constants = &mut self.pair_cache[k];
        if volume > 0.0 && constants.volume_m3 != volume {
            *constants = cohesion.pair_bridge(si, sj, ri * rj / reach, volume);
        }
        let rupture_distance_m = reach + constants.rupture_gap_m;
        if volume > 0.0
            && dist2 >= rupture_distance_m * rupture_distance_m * (1.0 - SQUARED_DECISION_MARGIN)
            && dist2.sqrt() - reach > constants.rupture_gap_m
        {
            let kept_by_i = cohesion.rupture_share_of_i(si, sj, volume) * volume;
            p.liquid_m3[i] += kept_by_i;
            p.liquid_m3[j] += volume - kept_by_i;
            volume = 0.0;
            self.events.bridges_ruptured += 1;
        }
        self.pair_volume[k] = volume;
        let gap = dist2.sqrt() - reach;
        if volume > 0.0 {
            constants.rupture_gap_m - gap
        } else {
            gap
        }
    }

    /// As [`Exchange::pair`] for wall slot `k` of particle `i`; a wall whose surface moves towards particles is
    /// always at 0 from a change.
    fn wall(&mut self, i: usize, k: usize) -> f64 {
        let (cohesion, p) = (self.cohesion, &mut *self.p);
        let w = self.list.wall_partner[k] as usize;
        let wall = &self.config.walls[w];
        // A turning baffle's surface moves towards particles; a drum's slides along itself (its gaps never change).
        let moving = wall.max_lever_m() > 0.0 && wall.angular_velocity_rad_per_s() != 0.0;
        let ri = p.radius_m[i];
        let gap_now = || wall.proximity(&p.position_m[i], self.wall_angle_rad[w]).gap_m - ri;
        if !cohesion.wall_on.get(w).copied().unwrap_or(true) {
            // Never a bridge on this wall.
            return f64::INFINITY;
        }
        if self.wall_volume[k] == 0.0 && p.liquid_m3[i] == 0.0 {
            return if moving { 0.0 } else { gap_now() };
        }
        let gap = gap_now();
        let mut volume = self.wall_volume[k];
        if gap >= cohesion.wall_range_m && volume == 0.0 {
            return if moving { 0.0 } else { gap };
        }
        if volume == 0.0 && gap < 0.0 {
            let taken = cohesion.wall_bridge_take_m3(p.liquid_m3[i], ri);
            if taken >= SMALLEST_BRIDGE * ri.powi(3) {
                p.liquid_m3[i] -= taken;
                volume = taken;
                self.events.bridges_formed += 1;
            }
        }
        let constants = &mut self.wall_cache[k];
        if volume > 0.0 && constants.volume_m3 != volume {
            *constants = cohesion.wall_bridge(p.species[i], wall.species, ri, volume);
        }
        if volume > 0.0 && gap > constants.rupture_gap_m {
            p.liquid_m3[i] += volume;
            volume = 0.0;
            self.events.bridges_ruptured += 1;
        }
        self.wall_volume[k] = volume;
        match (moving, volume > 0.0) {
            (true, _) => 0.0,
            (false, true) => constants.rupture_gap_m - gap,
            (false, false) => gap,
        }
    }
}

/// The liquid each particle holds, m³: its film, half of each bridge to another particle and the whole of each bridge
/// to a wall (the shares a bridge's liquid goes back in when its record is dropped, `AlignedHistory::from_store`).
pub fn held_liquid_m3(liquid_m3: &[f64], history: &AlignedHistory, list: &NeighborList) -> Vec<f64> {
    let mut held = liquid_m3.to_vec();
    for i in 0..held.len() {
        for k in list.pairs_of(i) {
            if history.pair.occupied(k) {
                let volume = history.pair.cohesion.bridge_volume_m3[k];
                held[i] += 0.5 * volume;
                held[list.partner[k] as usize] += volume - 0.5 * volume;
            }
        }
        for k in list.walls_of(i) {
            if history.wall.occupied(k) {
                held[i] += history.wall.cohesion.bridge_volume_m3[k];
            }
        }
    }
    held
}

/// Liquid on the particles and in the bridges, m³.
pub fn total_liquid_m3(liquid_m3: &[f64], history: &AlignedHistory) -> f64 {
    liquid_m3.iter().sum::<f64>()
        + history.pair.cohesion.bridge_volume_m3.iter().sum::<f64>()
        + history.wall.cohesion.bridge_volume_m3.iter().sum::<f64>()
}
