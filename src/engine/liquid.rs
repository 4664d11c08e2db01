//! The liquid inventory of a wet run: the liquid each particle carries and the liquid held in bridges, and every
//! event that moves liquid between them — spray onto the bed's surface, bridge formation on contact, the split of a
//! breaking bridge (and, later, evaporation).
//!
//! - A bridge forms when two particles touch and takes the liquid on each one's cap facing the other (seed 000
//!   eqs 6.1–6.4); a bridge to a wall (the wall a sphere of infinite radius) takes half the particle's liquid.
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
use super::models::capillary::bridge_volume_on_contact_m3;
use super::models::cohesion_law::CohesionModel;
use super::neighbor::NeighborList;
use super::particles::Particles;
use super::spray::spray_surface;

/// Per pair and wall slot of the neighbour list: the constants of its bridge for the volume they were computed for
/// (workspace: rebuilt from the state, never checkpointed; cleared whenever the list is rebuilt).
#[derive(Debug, Clone, Default)]
pub struct BridgeCache {
    pub pair: Vec<BridgeConstants>,
    pub wall: Vec<BridgeConstants>,
}

impl BridgeCache {
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
        let bridges = exchange_bridges(cohesion, config, p, list, history, cache, wall_angle_rad);
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

/// Bridge formation and rupture over every pair and wall slot, serially in index order.
fn exchange_bridges(
    cohesion: &Cohesion,
    config: &SimConfig,
    p: &mut Particles,
    list: &NeighborList,
    history: &mut AlignedHistory,
    cache: &mut BridgeCache,
    wall_angle_rad: &[f64],
) -> LiquidEvents {
    cache.fit(list);
    let mut events = LiquidEvents::default();
    let pair_volume = &mut history.pair.cohesion.bridge_volume_m3;
    let wall_volume = &mut history.wall.cohesion.bridge_volume_m3;
    for i in 0..p.len() {
        let (xi, ri, si) = (p.position_m[i], p.radius_m[i], p.species[i]);
        let pairs = if cohesion.between_particles {
            list.pairs_of(i)
        } else {
            0..0
        };
        for k in pairs {
            let j = list.partner[k] as usize;
            // No bridge and no liquid on either particle: nothing can form or rupture (a dry bed's every pair).
            if pair_volume[k] == 0.0 && p.liquid_m3[i] == 0.0 && p.liquid_m3[j] == 0.0 {
                continue;
            }
            let (rj, sj) = (p.radius_m[j], p.species[j]);
            let d = config.domain.separation(&xi, &p.position_m[j]);
            let reach = ri + rj;
            let dist2 = d.norm_squared();
            let mut volume = pair_volume[k];
            // Out of range and carrying nothing: the common case.
            let range = reach + cohesion.range_m;
            if dist2 >= range * range && volume == 0.0 {
                continue;
            }
            // The surface gap (a square root) is needed only near the thresholds: touching for a pair without a
            // bridge, the rupture gap for one with. Elsewhere the squared distance, with a margin far above its
            // rounding, decides the same way ([`SQUARED_DECISION_MARGIN`]).
            if volume == 0.0 && dist2 > reach * reach * (1.0 + SQUARED_DECISION_MARGIN) {
                continue;
            }
            if volume == 0.0 && dist2.sqrt() - reach < 0.0 {
                let (from_i, from_j) = bridge_volume_on_contact_m3(p.liquid_m3[i], ri, p.liquid_m3[j], rj);
                if from_i + from_j > 0.0 {
                    p.liquid_m3[i] -= from_i;
                    p.liquid_m3[j] -= from_j;
                    volume = from_i + from_j;
                    events.bridges_formed += 1;
                }
            }
            let constants = &mut cache.pair[k];
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
                events.bridges_ruptured += 1;
            }
            pair_volume[k] = volume;
        }
        if cohesion.wall_range_m > 0.0 {
            for k in list.walls_of(i) {
                let w = list.wall_partner[k] as usize;
                if !cohesion.wall_on.get(w).copied().unwrap_or(true) || (wall_volume[k] == 0.0 && p.liquid_m3[i] == 0.0)
                {
                    continue;
                }
                let wall = &config.walls[w];
                let gap = wall.proximity(&xi, wall_angle_rad[w]).gap_m - ri;
                let mut volume = wall_volume[k];
                if gap >= cohesion.wall_range_m && volume == 0.0 {
                    continue;
                }
                if volume == 0.0 && gap < 0.0 && p.liquid_m3[i] > 0.0 {
                    // Eq 6.1 with R_j → ∞: the cap facing a plane is half the particle.
                    let taken = 0.5 * p.liquid_m3[i];
                    p.liquid_m3[i] -= taken;
                    volume = taken;
                    events.bridges_formed += 1;
                }
                let constants = &mut cache.wall[k];
                if volume > 0.0 && constants.volume_m3 != volume {
                    *constants = cohesion.wall_bridge(si, wall.species, ri, volume);
                }
                if volume > 0.0 && gap > constants.rupture_gap_m {
                    p.liquid_m3[i] += volume;
                    volume = 0.0;
                    events.bridges_ruptured += 1;
                }
                wall_volume[k] = volume;
            }
        }
    }
    events
}

/// Liquid on the particles and in the bridges, m³.
pub fn total_liquid_m3(liquid_m3: &[f64], history: &AlignedHistory) -> f64 {
    liquid_m3.iter().sum::<f64>()
        + history.pair.cohesion.bridge_volume_m3.iter().sum::<f64>()
        + history.wall.cohesion.bridge_volume_m3.iter().sum::<f64>()
}
