//! Cohesion between particles (and walls) at a distance: the run's cohesion model with everything derived from it
//! once (ranges, contact angles, rupture shares, Young–Laplace tables), and the kernel the pair pass calls for one
//! pair or particle–wall slot: the capillary and viscous forces of a liquid bridge, Hamaker's attraction, the square
//! well's crossing impulse.
//!
//! A wall is a partner like a particle: of infinite radius and mass, so the pair's effective radius is the
//! particle's (R* = R_i), its reduced mass the particle's (μ = m_i), and the square well twice as deep (seed 001
//! §6.2.4.2). The kernel reads the pair's cohesion slot (`models::history::CohesionHistory`): the bridge volume,
//! which the liquid inventory (`engine::liquid`) sets when a bridge forms or breaks, and whether the pair is in the
//! well, which it updates itself. What does not live here: the liquid (`engine::liquid`), the pass (`pair_pass`).

use super::Vec3;
use super::models::capillary::{
    MikamiBridge, MikamiReading, bridge_volume_on_contact_m3, lian_rupture_gap_m, viscous_normal_force_n,
    viscous_tangential_coefficient_n_s_per_m,
};
use super::models::capillary_table::CapillaryTable;
use super::models::cohesion_law::{
    BridgeVolume, CapillaryForce, CohesionModel, LiquidBridge, ViscousRadius, square_well_crossing,
};
use super::models::history::CohesionHistory;
use super::models::liquid_transfer::rupture_share_of_i;
use super::particles::{SpeciesId, SpeciesTable};

/// A cohesion model with everything derived from it once per run.
#[derive(Debug, Clone, PartialEq)]
pub struct Cohesion {
    pub model: CohesionModel,
    /// Largest surface gap at which a pair interacts, m: the neighbour list reaches this much further.
    pub range_m: f64,
    /// Largest particle–wall gap at which the model acts (0: not on walls), m.
    pub wall_range_m: f64,
    /// Liquid bridges: the smallest gap the viscous forces see, m.
    pub min_gap_m: f64,
    /// Square well: r_outer/r_inner (a pair is in the well while its centres are closer than this × (R_i + R_j));
    /// infinite for the other models, which do not read it.
    pub well_ratio: f64,
    /// Contact angle per species, rad.
    pub contact_angle_rad: Vec<f64>,
    /// Rupture shares per unordered species pair a ≤ b, row by row of the upper triangle.
    pub rupture: Vec<RuptureTable>,
    /// Liquid bridges: the Young–Laplace force tables in use.
    pub tables: Vec<CapillaryTable>,
    /// Per unordered species pair (indexed as `rupture`): its table in `tables`, or `None` where Mikami's fit
    /// applies (equal radii and both contact angles 0, with `capillary_force: auto`).
    pub pair_tables: Vec<Option<u32>>,
    /// Per particle species a and wall species b (index a × species + b): the sphere–plane table of a bridge to a
    /// wall (`None` where bridges to walls are off or for wall species no wall has).
    pub wall_tables: Vec<Option<u32>>,
    /// The model acts between particles (scenario `cohesion_off.between_particles` switches it off).
    pub between_particles: bool,
    /// Per wall: the model acts on it (empty: on every wall when `wall_range_m` > 0; `cohesion_off.walls`).
    pub wall_on: Vec<bool>,
    n_species: usize,
}

/// How many times the largest bridge two freshly wetted particles can form the neighbour reach of liquid bridges
/// allows for (liquid gathers on particles as bridges break unevenly). A larger bridge breaks at this reach
/// (CHOICE: a reach limit; with V̂ = 0.02 particles it holds bridges of up to 4 times 0.04 R³).
const BRIDGE_VOLUME_ALLOWANCE: f64 = 4.0;

impl Cohesion {
    /// Derives the run's cohesion from `model`, the species and the particles' largest radius. Errors name the
    /// key under `cohesion` (or `species`) and what was expected.
    ///
    /// `wall_species`: the species of the walls (bridges to a wall of one of them get a sphere–plane table where
    /// they need one).
    pub fn new(
        model: CohesionModel,
        species: &SpeciesTable,
        wall_species: &[SpeciesId],
        max_radius_m: f64,
    ) -> Result<Cohesion, (String, String)> {
        let positive = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err((key.to_string(), format!("expected a finite value > 0, got {v}")))
            }
        };
        let n = species.len();
        let contact_angle_rad: Vec<f64> = species.species.iter().map(|s| s.contact_angle_rad).collect();
        let mut cohesion = Cohesion {
            model,
            range_m: 0.0,
            wall_range_m: 0.0,
            min_gap_m: 0.0,
            well_ratio: f64::INFINITY,
            contact_angle_rad,
            rupture: Vec::new(),
            tables: Vec::new(),
            pair_tables: Vec::new(),
            wall_tables: vec![None; n * n],
            between_particles: true,
            wall_on: Vec::new(),
            n_species: n,
        };
        match model {
            CohesionModel::LiquidBridge(b) => {
                positive(
                    "cohesion.liquid_bridge.surface_tension_n_per_m",
                    b.surface_tension_n_per_m,
                )?;
                if !(b.viscosity_pa_s.is_finite() && b.viscosity_pa_s >= 0.0) {
                    return Err((
                        "cohesion.liquid_bridge.viscosity_pa_s".into(),
                        format!("expected a finite value >= 0, got {}", b.viscosity_pa_s),
                    ));
                }
                if !(b.bridges_from_s.is_finite() && b.bridges_from_s >= 0.0) {
                    return Err((
                        "cohesion.liquid_bridge.bridges_from_s".into(),
                        format!("expected a time >= 0 s, got {}", b.bridges_from_s),
                    ));
                }
                let min_radius = species.species.iter().map(|s| s.radius_m).fold(f64::INFINITY, f64::min);
                cohesion.min_gap_m = b.min_gap_m.unwrap_or(0.01 * min_radius);
                positive("cohesion.liquid_bridge.min_gap_m", cohesion.min_gap_m)?;
                let mut largest_liquid = 0.0f64;
                let mut largest_angle = 0.0f64;
                // (The species' liquid and contact angles are validated by the scenario, where their keys live.)
                for s in &species.species {
                    largest_liquid = largest_liquid.max(s.liquid_content * s.radius_m.powi(3));
                    largest_angle = largest_angle.max(s.contact_angle_rad);
                }
                if let Some(spray) = b.spray {
                    if !(spray.max_liquid_content.is_finite() && spray.max_liquid_content > 0.0) {
                        return Err((
                            "cohesion.liquid_bridge.spray.max_liquid_content".into(),
                            format!("expected a finite value > 0, got {}", spray.max_liquid_content),
                        ));
                    }
                    if spray.every_steps == 0 {
                        return Err((
                            "cohesion.liquid_bridge.spray.every_steps".into(),
                            "expected at least 1".into(),
                        ));
                    }
                    if !(spray.start_s.is_finite() && spray.start_s >= 0.0) {
                        return Err((
                            "cohesion.liquid_bridge.spray.start_s".into(),
                            format!("expected a finite value >= 0, got {}", spray.start_s),
                        ));
                    }
                    for s in &species.species {
                        largest_liquid = largest_liquid.max(spray.max_liquid_content * s.radius_m.powi(3));
                    }
                }
                let mut largest_bridge = 2.0 * BRIDGE_VOLUME_ALLOWANCE * largest_liquid;
                if let BridgeVolume::Fixed(v_hat) = b.bridge_volume {
                    if !(v_hat.is_finite() && v_hat > 0.0 && v_hat <= 0.1) {
                        return Err((
                            "cohesion.liquid_bridge.bridge_volume.fixed".into(),
                            format!("expected a bridge volume V/R³ in (0, 0.1] (Mikami's fit), got {v_hat}"),
                        ));
                    }
                    largest_bridge = largest_bridge.max(v_hat * max_radius_m.powi(3));
                }
                cohesion.range_m = lian_rupture_gap_m(largest_bridge, largest_angle, largest_angle);
                cohesion.wall_range_m = if b.walls { cohesion.range_m } else { 0.0 };
                let b_law = b.capillary_force;
                // One table per unordered pair (a ≤ b): j keeps what i does not.
                for (ka, a) in species.species.iter().enumerate() {
                    for b in &species.species[ka..] {
                        // Two species of the same radius and contact angle (e.g. identical beads in two colours)
                        // are mirror images in a bridge: each keeps half, exactly, with no table to compute.
                        cohesion.rupture.push(RuptureTable::new(
                            a.radius_m,
                            b.radius_m,
                            a.contact_angle_rad,
                            b.contact_angle_rad,
                            a.radius_m == b.radius_m && a.contact_angle_rad == b.contact_angle_rad,
                        ));
                        let (ta, tb) = (a.contact_angle_rad, b.contact_angle_rad);
                        // Mikami's fit only where it is settled: equal particles at θ = 0 (B2).
                        let mikami_settled = a.radius_m == b.radius_m && ta == 0.0 && tb == 0.0;
                        let table = match b_law {
                            CapillaryForce::Auto => !mikami_settled,
                            CapillaryForce::YoungLaplace => true,
                            CapillaryForce::MikamiAsPrinted => false,
                        };
                        let table = table.then(|| {
                            cohesion.tables.push(capillary_table(a.radius_m, b.radius_m, ta, tb));
                            (cohesion.tables.len() - 1) as u32
                        });
                        cohesion.pair_tables.push(table);
                    }
                }
                // Bridges to walls: always the sphere–plane table (the wall an infinite sphere, R₂/R₁ = ∞). Mikami's
                // equal-sphere fit read at R* = R_i is within 3 % of it at contact but 67–78 % below it near rupture
                // even at θ = 0 (`young_laplace.rs`), so it is settled for no wall.
                if b.walls {
                    let mut wall_species = wall_species.to_vec();
                    wall_species.sort_by_key(|w| w.index());
                    wall_species.dedup();
                    for (ka, a) in species.species.iter().enumerate() {
                        for &w in &wall_species {
                            let (ta, tw) = (a.contact_angle_rad, species.species[w.index()].contact_angle_rad);
                            cohesion.tables.push(capillary_table(a.radius_m, f64::INFINITY, ta, tw));
                            cohesion.wall_tables[ka * n + w.index()] = Some((cohesion.tables.len() - 1) as u32);
                        }
                    }
                }
            }
            CohesionModel::Hamaker(h) => {
                positive("cohesion.hamaker.constant_j", h.constant_j)?;
                positive("cohesion.hamaker.inner_cutoff_m", h.inner_cutoff_m)?;
                positive("cohesion.hamaker.outer_cutoff_m", h.outer_cutoff_m)?;
                if h.outer_cutoff_m <= h.inner_cutoff_m {
                    return Err((
                        "cohesion.hamaker.outer_cutoff_m".into(),
                        format!(
                            "expected more than inner_cutoff_m ({} m), got {} m",
                            h.inner_cutoff_m, h.outer_cutoff_m
                        ),
                    ));
                }
                cohesion.range_m = h.outer_cutoff_m;
                cohesion.wall_range_m = if h.walls { h.outer_cutoff_m } else { 0.0 };
            }
            CohesionModel::SquareWell(w) => {
                positive("cohesion.square_well.depth_j", w.depth_j)?;
                if !(w.outer_to_inner_radius_ratio.is_finite() && w.outer_to_inner_radius_ratio > 1.0) {
                    return Err((
                        "cohesion.square_well.outer_to_inner_radius_ratio".into(),
                        format!("expected a value > 1, got {}", w.outer_to_inner_radius_ratio),
                    ));
                }
                // The well reaches (ratio − 1)(R_i + R_j) beyond contact; a little more so that a pair just outside
                // is still seen leaving.
                cohesion.well_ratio = w.outer_to_inner_radius_ratio;
                let width = (w.outer_to_inner_radius_ratio - 1.0) * 2.0 * max_radius_m;
                cohesion.range_m = 2.0 * width;
                cohesion.wall_range_m = if w.walls { width } else { 0.0 };
            }
        }
        Ok(cohesion)
    }

    /// The index of the unordered species pair {a, b} in the per-pair tables.
    pub fn pair_index(&self, a: SpeciesId, b: SpeciesId) -> usize {
        let (lo, hi) = (a.index().min(b.index()), a.index().max(b.index()));
        // Row lo of the upper triangle starts after the rows above it: lo·n − lo(lo−1)/2.
        lo * self.n_species - lo * lo.saturating_sub(1) / 2 + (hi - lo)
    }

    /// The share particle i (species `a`) keeps of a breaking bridge of `volume_m3` with a particle of species `b`.
    pub fn rupture_share_of_i(&self, a: SpeciesId, b: SpeciesId, volume_m3: f64) -> f64 {
        let table = &self.rupture[self.pair_index(a, b)];
        let share = table.share_of_i(volume_m3);
        if a.index() <= b.index() { share } else { 1.0 - share }
    }
}

/// The share of a breaking bridge particle i keeps, for one species pair, tabulated over the bridge volume
/// (PHYSICS §2: "precompute as a lookup table"): [`rupture_share_of_i`] at log-spaced V̂ = V/R_i³ from 1e-6 to 1,
/// ten per decade (computed in parallel when the run starts: about 1 s per pair of unlike species, most of it where
/// the parabola pinches off before Lian's gap), interpolated linearly in ln V̂ and held constant beyond the ends.
/// Equal species share 1/2 exactly.
#[derive(Debug, Clone, PartialEq)]
pub struct RuptureTable {
    radius_i_m: f64,
    /// Shares at ln V̂ = LN_LO + k STEP; empty for equal species.
    shares: Vec<f64>,
}

const TABLE_DECADES: (i32, i32) = (-6, 0);
const TABLE_PER_DECADE: usize = 10;

impl RuptureTable {
    fn new(radius_i_m: f64, radius_j_m: f64, angle_i_rad: f64, angle_j_rad: f64, symmetric: bool) -> Self {
        if symmetric {
            return RuptureTable {
                radius_i_m,
                shares: Vec::new(),
            };
        }
        let points = (TABLE_DECADES.1 - TABLE_DECADES.0) as usize * TABLE_PER_DECADE + 1;
        use rayon::prelude::*;
        let raw: Vec<Option<f64>> = (0..points)
            .into_par_iter()
            .map(|k| {
                let volume = Self::volume_at(radius_i_m, k);
                rupture_share_of_i(radius_i_m, radius_j_m, angle_i_rad, angle_j_rad, volume)
            })
            .collect();
        // Where no parabola fits, the nearest node that has one (and 1/2 if none does).
        let shares = (0..points)
            .map(|k| {
                (0..points)
                    .flat_map(|d| [k.checked_sub(d), Some(k + d)])
                    .flatten()
                    .find_map(|m| raw.get(m).copied().flatten())
                    .unwrap_or(0.5)
            })
            .collect();
        RuptureTable { radius_i_m, shares }
    }

    fn ln_step() -> f64 {
        std::f64::consts::LN_10 / TABLE_PER_DECADE as f64
    }

    fn ln_lo() -> f64 {
        TABLE_DECADES.0 as f64 * std::f64::consts::LN_10
    }

    fn volume_at(radius_i_m: f64, k: usize) -> f64 {
        (Self::ln_lo() + k as f64 * Self::ln_step()).exp() * radius_i_m.powi(3)
    }

    /// The fraction of a bridge of `volume_m3` that particle i keeps.
    pub fn share_of_i(&self, volume_m3: f64) -> f64 {
        if self.shares.is_empty() {
            return 0.5;
        }
        let x = ((volume_m3 / self.radius_i_m.powi(3)).ln() - Self::ln_lo()) / Self::ln_step();
        if x.is_nan() || x <= 0.0 {
            return self.shares[0];
        }
        let last = self.shares.len() - 1;
        if x >= last as f64 {
            return self.shares[last];
        }
        let k = x.floor() as usize;
        let t = x - k as f64;
        self.shares[k] * (1.0 - t) + self.shares[k + 1] * t
    }
}

/// What the cohesion model's events have been: bridges formed and broken (`engine::liquid`), square-well crossings
/// (the pair pass). For diagnostics.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CohesionEvents {
    pub bridges_formed: u64,
    pub bridges_ruptured: u64,
    pub well_crossings: u64,
}

/// What a bridge's force and rupture need that stays fixed while its volume does: computed by the liquid inventory
/// when a bridge forms or changes (`engine::liquid`), read by the kernel.
#[derive(Debug, Clone, Copy)]
pub struct BridgeConstants {
    /// The volume these were computed for (NaN: none).
    pub volume_m3: f64,
    pub mikami: MikamiBridge,
    /// The pair's Young–Laplace table (index into `Cohesion::tables`), used instead of `mikami`.
    pub table: Option<u32>,
    pub rupture_gap_m: f64,
    /// The bridge between touching surfaces (most bridges of a packed wet bed): its forces no longer depend on the
    /// gap there, so they are computed once per volume rather than per step ([`Cohesion::force`]).
    pub at_contact: BridgeAtContact,
}

/// A bridge's forces while its surfaces touch, computed by the same functions the kernel calls with the gap held
/// at its floor (so the kernel's result is the same to the bit with or without them).
#[derive(Debug, Clone, Copy)]
pub struct BridgeAtContact {
    /// The radius the viscous coefficient was computed for (NaN: none): R*, or 2R* between particles with
    /// `viscous_radius: as_printed` ([`ViscousRadius`]), m.
    pub viscous_radius_m: f64,
    /// The capillary force at a gap ≤ 0 (the force laws hold the gap at 0), N.
    pub capillary_n: f64,
    /// The viscous tangential coefficient at a gap ≤ `Cohesion::min_gap_m` (held at it), N s/m.
    pub viscous_tangential_n_s_per_m: f64,
}

impl BridgeConstants {
    pub const NONE: BridgeConstants = BridgeConstants {
        volume_m3: f64::NAN,
        mikami: MikamiBridge::ZERO,
        table: None,
        rupture_gap_m: 0.0,
        at_contact: BridgeAtContact {
            viscous_radius_m: f64::NAN,
            capillary_n: 0.0,
            viscous_tangential_n_s_per_m: 0.0,
        },
    };
}

/// One cohesive interaction as the kernel sees it from particle i: a particle pair, or a particle and a wall (an
/// infinite radius and mass). The pair pass forms it with the formulas below for either partner.
#[derive(Debug, Clone, Copy)]
pub struct Bond {
    /// Unit normal from the partner to i.
    pub normal: Vec3,
    /// Surface gap (negative in overlap), m.
    pub gap_m: f64,
    /// Centre distance (to the wall's surface for a wall), m, and the distance below which the pair is inside the
    /// square well: r_outer/r_inner × (R_i + R_j), or × R_i for a wall.
    pub centre_distance_m: f64,
    pub well_distance_m: f64,
    /// R* = R_i R_j/(R_i + R_j), or R_i for a wall.
    pub effective_radius_m: f64,
    /// μ = m_i m_j/(m_i + m_j), or m_i for a wall.
    pub effective_mass_kg: f64,
    /// −(v_i − v_partner)·n: positive while the pair approaches, m/s.
    pub approach_m_per_s: f64,
    /// Velocity of i's surface point minus the partner's, m/s (for the viscous tangential force).
    pub contact_velocity: Vec3,
    /// The square well's depth relative to a particle pair's: 2 for a wall (seed 001 §6.2.4.2).
    pub depth_factor: f64,
    /// The partner is a wall.
    pub wall: bool,
}

/// What the kernel exerts on i: the normal part along `Bond::normal` (positive pushes i away from the partner) and
/// the tangential part (its torque is −R n × F_t on each side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BondForce {
    pub normal_n: f64,
    pub tangential_n: Vec3,
    /// The pair crossed the square well's edge this step.
    pub crossed_well: bool,
}

impl BondForce {
    pub const NONE: BondForce = BondForce {
        normal_n: 0.0,
        tangential_n: Vec3::new(0.0, 0.0, 0.0),
        crossed_well: false,
    };
}

impl Cohesion {
    /// Whether a pair whose record holds `bridge_volume_m3` feels nothing from this model whatever its geometry: a
    /// liquid-bridge model without a bridge ([`Self::force`] returns nothing and changes no state), so the pair pass
    /// skips the bond.
    #[inline]
    pub fn inert_without_bridge(&self, bridge_volume_m3: f64) -> bool {
        matches!(self.model, CohesionModel::LiquidBridge(_)) && bridge_volume_m3 <= 0.0
    }

    /// The cohesion force of one bond at the current positions (velocities at the half step), updating the slot's
    /// square-well state. `bridge`: the constants of the slot's liquid bridge (for its current volume). `dt_s` turns
    /// the square well's crossing impulse into a force acting for one step (the two half kicks of velocity Verlet
    /// deliver exactly F dt).
    #[inline(always)]
    pub fn force(&self, bond: &Bond, state: &mut CohesionHistory, bridge: &BridgeConstants, dt_s: f64) -> BondForce {
        match self.model {
            CohesionModel::LiquidBridge(b) => {
                if state.bridge_volume_m3 <= 0.0 {
                    return BondForce::NONE;
                }
                // Seed 000 eqs 2.16-2.17 (Mikami) or 6.5-6.28 (the Young–Laplace table); 2.19-2.20 (viscous).
                let at_contact = &bridge.at_contact;
                let capillary = if bond.gap_m <= 0.0 && bridge.volume_m3 == state.bridge_volume_m3 {
                    at_contact.capillary_n
                } else {
                    self.capillary_force_n(bridge, state.bridge_volume_m3, bond.gap_m, b.surface_tension_n_per_m)
                };
                let mut normal_n = -capillary;
                let mut tangential_n = Vec3::zeros();
                if b.viscosity_pa_s > 0.0 {
                    let r = match b.viscous_radius {
                        ViscousRadius::AsPrinted if !bond.wall => 2.0 * bond.effective_radius_m,
                        _ => bond.effective_radius_m,
                    };
                    normal_n +=
                        viscous_normal_force_n(r, b.viscosity_pa_s, bond.approach_m_per_s, bond.gap_m, self.min_gap_m);
                    let coefficient = if bond.gap_m <= self.min_gap_m && r == at_contact.viscous_radius_m {
                        at_contact.viscous_tangential_n_s_per_m
                    } else {
                        viscous_tangential_coefficient_n_s_per_m(r, b.viscosity_pa_s, bond.gap_m, self.min_gap_m)
                    };
                    let v = bond.contact_velocity;
                    let tangential_velocity = v - bond.normal * v.dot(&bond.normal);
                    tangential_n = -tangential_velocity * coefficient;
                }
                BondForce {
                    normal_n,
                    tangential_n,
                    crossed_well: false,
                }
            }
            CohesionModel::Hamaker(h) => {
                if bond.gap_m < h.outer_cutoff_m {
                    BondForce {
                        normal_n: -h.law().pair_force_n(bond.effective_radius_m, bond.gap_m),
                        ..BondForce::NONE
                    }
                } else {
                    BondForce::NONE
                }
            }
            CohesionModel::SquareWell(w) => {
                let inside = bond.centre_distance_m < bond.well_distance_m;
                let approach = bond.approach_m_per_s;
                let entering = !state.in_well && inside;
                let leaving = state.in_well && !inside && approach < 0.0;
                if !((entering || leaving) && dt_s > 0.0) {
                    return BondForce::NONE;
                }
                let mu = bond.effective_mass_kg;
                let speed = if entering { approach.abs() } else { approach };
                let (mut after, now_inside) = square_well_crossing(bond.depth_factor * w.depth_j, mu, speed, entering);
                if entering && approach < 0.0 {
                    after = -after;
                }
                state.in_well = now_inside;
                // Impulse P n on i changes the approach speed by −P/μ.
                BondForce {
                    normal_n: mu * (approach - after) / dt_s,
                    tangential_n: Vec3::zeros(),
                    crossed_well: true,
                }
            }
        }
    }

    /// The capillary force of a bridge of `volume_m3` across `gap_m` (Mikami's fit or the pair's Young–Laplace
    /// table, as `bridge` says), N.
    #[inline]
    fn capillary_force_n(
        &self,
        bridge: &BridgeConstants,
        volume_m3: f64,
        gap_m: f64,
        surface_tension_n_per_m: f64,
    ) -> f64 {
        match bridge.table {
            Some(t) => self.tables[t as usize].force_n(volume_m3, gap_m, surface_tension_n_per_m),
            None => bridge.mikami.force_n(gap_m),
        }
    }

    /// `constants` completed with its forces at contact ([`BridgeAtContact`]), the viscous ones for radius
    /// `viscous_radius_m` (the one [`Self::force`] uses for this bond).
    fn with_contact_forces(
        &self,
        mut constants: BridgeConstants,
        viscous_radius_m: f64,
        bridge: LiquidBridge,
    ) -> BridgeConstants {
        constants.at_contact = BridgeAtContact {
            viscous_radius_m,
            capillary_n: self.capillary_force_n(&constants, constants.volume_m3, 0.0, bridge.surface_tension_n_per_m),
            viscous_tangential_n_s_per_m: viscous_tangential_coefficient_n_s_per_m(
                viscous_radius_m,
                bridge.viscosity_pa_s,
                self.min_gap_m,
                self.min_gap_m,
            ),
        };
        constants
    }

    /// Widens the particle–wall range for walls of glued beads up to `bead_radius_m` in radius (particles up to
    /// `max_radius_m`): the square well to a bead is the pair's, reaching (ratio − 1)(R_i + r_b) beyond contact, and
    /// is seen twice as far, as a flat wall's is, so that a particle just outside is still seen leaving. Hamaker's
    /// range is a gap and liquid bridges to beads keep the flat form: neither changes.
    pub fn reach_glued_beads(&mut self, bead_radius_m: f64, max_radius_m: f64) {
        if let CohesionModel::SquareWell(w) = self.model
            && self.wall_range_m > 0.0
            && bead_radius_m > 0.0
        {
            let reach_m = 2.0 * (w.outer_to_inner_radius_ratio - 1.0) * (max_radius_m + bead_radius_m);
            self.wall_range_m = self.wall_range_m.max(reach_m);
        }
    }

    /// The liquid particles i and j (films `liquid_*_m3`, radii `radius_*_m`) give a bridge forming between them,
    /// (from i, from j), m³: their caps (eqs 6.1–6.4) or half a fixed volume each ([`BridgeVolume`]).
    pub fn pair_bridge_take_m3(
        &self,
        liquid_i_m3: f64,
        radius_i_m: f64,
        liquid_j_m3: f64,
        radius_j_m: f64,
    ) -> (f64, f64) {
        match self.model {
            CohesionModel::LiquidBridge(LiquidBridge {
                bridge_volume: BridgeVolume::Fixed(v_hat),
                ..
            }) => {
                let r = 2.0 * radius_i_m * radius_j_m / (radius_i_m + radius_j_m);
                let half = 0.5 * v_hat * r * r * r;
                (half.min(liquid_i_m3), half.min(liquid_j_m3))
            }
            _ => bridge_volume_on_contact_m3(liquid_i_m3, radius_i_m, liquid_j_m3, radius_j_m),
        }
    }

    /// The liquid a particle (film `liquid_m3`, radius `radius_m`) gives a bridge forming to a wall, m³: half its
    /// film (eq 6.1 with the wall a sphere of infinite radius: the cap facing a plane is half the particle) or a fixed
    /// volume.
    pub fn wall_bridge_take_m3(&self, liquid_m3: f64, radius_m: f64) -> f64 {
        match self.model {
            CohesionModel::LiquidBridge(LiquidBridge {
                bridge_volume: BridgeVolume::Fixed(v_hat),
                ..
            }) => (v_hat * radius_m * radius_m * radius_m).min(liquid_m3),
            _ => 0.5 * liquid_m3,
        }
    }

    /// The constants of a bridge of `volume_m3` between particle species `a` and `b` (effective radius `r_star_m`).
    pub fn pair_bridge(&self, a: SpeciesId, b: SpeciesId, r_star_m: f64, volume_m3: f64) -> BridgeConstants {
        let CohesionModel::LiquidBridge(bridge) = self.model else {
            return BridgeConstants::NONE;
        };
        let (ti, tj) = (self.contact_angle_rad[a.index()], self.contact_angle_rad[b.index()]);
        let constants = BridgeConstants {
            volume_m3,
            mikami: MikamiBridge::with_reading(
                r_star_m,
                volume_m3,
                0.5 * (ti + tj),
                bridge.surface_tension_n_per_m,
                match bridge.capillary_force {
                    CapillaryForce::MikamiAsPrinted => MikamiReading::AsPrinted,
                    CapillaryForce::Auto | CapillaryForce::YoungLaplace => MikamiReading::Settled,
                },
            ),
            table: self.pair_tables[self.pair_index(a, b)],
            rupture_gap_m: lian_rupture_gap_m(volume_m3, ti, tj).min(self.range_m),
            at_contact: BridgeConstants::NONE.at_contact,
        };
        let viscous_radius_m = match bridge.viscous_radius {
            ViscousRadius::AsPrinted => 2.0 * r_star_m,
            ViscousRadius::Effective => r_star_m,
        };
        self.with_contact_forces(constants, viscous_radius_m, bridge)
    }

    /// The constants of a bridge of `volume_m3` between a particle of species `a` and radius `radius_m` and a wall of
    /// species `wall` (a plane: R* = R_i).
    pub fn wall_bridge(&self, a: SpeciesId, wall: SpeciesId, radius_m: f64, volume_m3: f64) -> BridgeConstants {
        let CohesionModel::LiquidBridge(bridge) = self.model else {
            return BridgeConstants::NONE;
        };
        let (ti, tw) = (self.contact_angle_rad[a.index()], self.contact_angle_rad[wall.index()]);
        let constants = BridgeConstants {
            volume_m3,
            mikami: MikamiBridge::new(radius_m, volume_m3, 0.5 * (ti + tw), bridge.surface_tension_n_per_m),
            table: self.wall_tables[a.index() * self.n_species + wall.index()],
            rupture_gap_m: lian_rupture_gap_m(volume_m3, ti, tw).min(self.wall_range_m),
            at_contact: BridgeConstants::NONE.at_contact,
        };
        self.with_contact_forces(constants, radius_m, bridge)
    }
}

/// The Young–Laplace force table of one species pair, from the disk cache when it holds it (built and cached
/// otherwise; `capillary_cache.rs`).
fn capillary_table(radius_1_m: f64, radius_2_m: f64, angle_1_rad: f64, angle_2_rad: f64) -> CapillaryTable {
    use super::models::capillary_cache::{Provenance, cache_dir, load_or_build};
    let (table, provenance) = load_or_build(cache_dir().as_deref(), radius_1_m, radius_2_m, angle_1_rad, angle_2_rad);
    match provenance {
        Provenance::Loaded(p) => tracing::debug!("Young–Laplace table read from {}", p.display()),
        Provenance::BuiltAndCached(p) => tracing::info!("Young–Laplace table built and cached in {}", p.display()),
        Provenance::BuiltOnly(why) => tracing::info!("Young–Laplace table built, not cached: {why}"),
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table reproduces the parabolic bridge's share between its nodes (seed 000 Table 5's unequal pair:
    /// R 1.0 / 0.8 mm, θ 0° / 30°): to 1e-3 where the bridge reaches Lian's gap (V̂ ≥ 3e-3 here), to 1e-2 below,
    /// where the share from the pinch-off search itself scatters by a few 1e-3 from one volume to the next.
    #[test]
    fn the_rupture_table_matches_the_parabolic_bridge_between_nodes() {
        let (ri, rj, ti, tj) = (1.0e-3, 0.8e-3, 0.0, 30f64.to_radians());
        let table = RuptureTable::new(ri, rj, ti, tj, false);
        for (v_hat, tolerance) in [
            (3.3e-5, 1e-2),
            (5.5e-4, 1e-2),
            (3.7e-3, 1e-3),
            (7.7e-3, 1e-3),
            (2.9e-2, 1e-3),
            (0.11, 1e-3),
        ] {
            let volume = v_hat * ri * ri * ri;
            let exact = rupture_share_of_i(ri, rj, ti, tj, volume).expect("a bridge");
            let error = (table.share_of_i(volume) - exact).abs();
            assert!(error < tolerance, "V̂ = {v_hat}: table off by {error}");
        }
        // The more wettable particle (θ = 0) keeps more than its even share.
        assert!(table.share_of_i(1e-3 * ri * ri * ri) > 0.5);
        assert_eq!(RuptureTable::new(ri, ri, ti, ti, true).share_of_i(1e-9), 0.5);
    }

    /// Species that differ only in name or colour (seed 000's left/right beads) split a breaking bridge exactly in
    /// half without computing a table (the symmetric bridge needs none); the computed table agrees to the
    /// solver's rounding (to 1e-12: it is symmetric too).
    #[test]
    fn identical_beads_of_two_species_share_a_breaking_bridge_equally() {
        use crate::engine::particles::{Species, SpeciesTable};
        let bead = |name: &str| Species {
            liquid_content: 0.01,
            ..Species::test_bead(name, 1.35e-3, 2000.0)
        };
        let species = SpeciesTable {
            species: vec![bead("left"), bead("right")],
        };
        let model = CohesionModel::LiquidBridge(serde_norway::from_str("surface_tension_n_per_m: 0.02").unwrap());
        let cohesion = Cohesion::new(model, &species, &[], 1.35e-3).expect("valid cohesion");
        let (left, right) = (SpeciesId(0), SpeciesId(1));
        for v_hat in [1e-5, 1e-3, 0.02] {
            let volume = v_hat * 1.35e-3f64.powi(3);
            assert_eq!(cohesion.rupture_share_of_i(left, right, volume), 0.5);
            assert_eq!(cohesion.rupture_share_of_i(right, left, volume), 0.5);
        }
        let (r, t) = (1.35e-3, 0.0);
        let computed = RuptureTable::new(r, r, t, t, false);
        for v_hat in [1e-4, 1e-3, 1e-2, 0.1] {
            let share = computed.share_of_i(v_hat * r * r * r);
            assert!((share - 0.5).abs() < 1e-12, "V̂ = {v_hat}: computed share {share}");
        }
    }

    /// The pair pass skips the bond of a pair the liquid-bridge model leaves alone: exactly the pairs whose bond
    /// gives no force and changes no state, at any gap, approach speed or viscosity; the other models never skip.
    #[test]
    fn only_a_liquid_bridge_without_a_bridge_is_inert() {
        use crate::engine::particles::{Species, SpeciesTable};
        let species = SpeciesTable {
            species: vec![Species::test_bead("bead", 1.35e-3, 2000.0)],
        };
        let bridge = CohesionModel::LiquidBridge(
            serde_norway::from_str("{ surface_tension_n_per_m: 0.02, viscosity_pa_s: 0.001 }").unwrap(),
        );
        let cohesion = Cohesion::new(bridge, &species, &[], 1.35e-3).expect("valid cohesion");
        assert!(cohesion.inert_without_bridge(0.0));
        assert!(!cohesion.inert_without_bridge(1e-12));
        for (gap_m, approach_m_per_s) in [(-1e-5, 0.3), (0.0, -0.2), (2e-5, 1.0), (1e-3, 0.0)] {
            let bond = Bond {
                normal: Vec3::new(0.0, 1.0, 0.0),
                gap_m,
                centre_distance_m: 2.7e-3 + gap_m,
                well_distance_m: 2.8e-3,
                effective_radius_m: 0.675e-3,
                effective_mass_kg: 1e-5,
                approach_m_per_s,
                contact_velocity: Vec3::new(0.1, -approach_m_per_s, 0.0),
                depth_factor: 1.0,
                wall: false,
            };
            let mut state = CohesionHistory {
                bridge_volume_m3: 0.0,
                in_well: false,
            };
            let out = cohesion.force(&bond, &mut state, &BridgeConstants::NONE, 1e-5);
            assert_eq!(out, BondForce::NONE);
            assert!(state.is_empty());
        }
        let hamaker = CohesionModel::Hamaker(
            serde_norway::from_str("{ constant_j: 1.0e-19, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-5 }").unwrap(),
        );
        let cohesion = Cohesion::new(hamaker, &species, &[], 1.35e-3).expect("valid cohesion");
        assert!(!cohesion.inert_without_bridge(0.0));
    }
    /// `viscous_radius: as_printed` (seed 000 eqs 2.19–2.20 with R the particle radius) gives four times the
    /// normal viscous force of the Reynolds reading (R*) between equal particles, and the same against a wall.
    #[test]
    fn viscous_forces_as_printed_use_the_particle_radius_between_particles() {
        use crate::engine::particles::{Species, SpeciesTable};
        use std::f64::consts::PI;
        let species = SpeciesTable {
            species: vec![Species::test_bead("bead", 1.35e-3, 2000.0)],
        };
        let force = |reading: &str, wall: bool| {
            let bridge = CohesionModel::LiquidBridge(
                serde_norway::from_str(&format!(
                    "{{ surface_tension_n_per_m: 0.02, viscosity_pa_s: 0.001, viscous_radius: {reading} }}"
                ))
                .unwrap(),
            );
            let cohesion = Cohesion::new(bridge, &species, &[], 1.35e-3).expect("valid cohesion");
            let r_star = if wall { 1.35e-3 } else { 0.675e-3 };
            let volume_m3 = 1e-3 * 1.35e-3f64.powi(3);
            let constants = cohesion.pair_bridge(SpeciesId(0), SpeciesId(0), r_star, volume_m3);
            let bond = Bond {
                normal: Vec3::new(0.0, 1.0, 0.0),
                gap_m: 5e-5,
                centre_distance_m: 2.75e-3,
                well_distance_m: 2.8e-3,
                effective_radius_m: r_star,
                effective_mass_kg: 1e-5,
                approach_m_per_s: 0.2,
                contact_velocity: Vec3::new(0.1, -0.2, 0.0),
                depth_factor: if wall { 2.0 } else { 1.0 },
                wall,
            };
            let mut state = CohesionHistory {
                bridge_volume_m3: volume_m3,
                in_well: false,
            };
            let capillary = cohesion.force(&bond, &mut state, &constants, 1e-5).normal_n;
            let dry = CohesionModel::LiquidBridge(
                serde_norway::from_str("{ surface_tension_n_per_m: 0.02, viscosity_pa_s: 0.0 }").unwrap(),
            );
            let dry = Cohesion::new(dry, &species, &[], 1.35e-3).expect("valid cohesion");
            capillary - dry.force(&bond, &mut state, &constants, 1e-5).normal_n
        };
        let (effective, printed) = (force("effective", false), force("as_printed", false));
        let reynolds = 6.0 * PI * 0.001 * 0.675e-3f64.powi(2) * 0.2 / 5e-5;
        assert!(
            (effective / reynolds - 1.0).abs() < 1e-12,
            "{effective} against {reynolds}"
        );
        assert!((printed / (4.0 * reynolds) - 1.0).abs() < 1e-12, "{printed}");
        assert_eq!(force("effective", true), force("as_printed", true));
    }

    #[test]
    fn the_touching_bridge_cache_holds_the_viscous_radius_each_reading_uses() {
        use crate::engine::particles::{Species, SpeciesTable};
        let species = SpeciesTable {
            species: vec![Species::test_bead("bead", 1.35e-3, 2000.0)],
        };
        for (reading, radius_factor) in [("effective", 1.0), ("as_printed", 2.0)] {
            let bridge = CohesionModel::LiquidBridge(
                serde_norway::from_str(&format!(
                    "{{ surface_tension_n_per_m: 0.02, viscosity_pa_s: 0.001, viscous_radius: {reading} }}"
                ))
                .unwrap(),
            );
            let cohesion = Cohesion::new(bridge, &species, &[], 1.35e-3).expect("valid cohesion");
            let (r_star, volume_m3) = (0.675e-3, 1e-3 * 1.35e-3f64.powi(3));
            let cached = cohesion.pair_bridge(SpeciesId(0), SpeciesId(0), r_star, volume_m3);
            assert_eq!(cached.at_contact.viscous_radius_m, radius_factor * r_star, "{reading}");
            // The same bridge without the cache: the kernel computes the coefficient itself.
            let mut uncached = cached;
            uncached.at_contact.viscous_radius_m = f64::NAN;
            let bond = Bond {
                normal: Vec3::new(0.0, 1.0, 0.0),
                gap_m: -2e-6,
                centre_distance_m: 2.698e-3,
                well_distance_m: 2.8e-3,
                effective_radius_m: r_star,
                effective_mass_kg: 1e-5,
                approach_m_per_s: 0.2,
                contact_velocity: Vec3::new(0.1, -0.2, 0.05),
                depth_factor: 1.0,
                wall: false,
            };
            let mut state = CohesionHistory {
                bridge_volume_m3: volume_m3,
                in_well: false,
            };
            let with_cache = cohesion.force(&bond, &mut state, &cached, 1e-5);
            let without = cohesion.force(&bond, &mut state, &uncached, 1e-5);
            assert!(with_cache.tangential_n.norm() > 0.0);
            assert_eq!(
                with_cache, without,
                "{reading}: the cache must give the kernel's own bits"
            );
        }
    }
}
