//! The cohesion slot: one optional model of the forces particles exert on each other at a distance, beside the
//! contact law. Liquid bridges (seed 000 §2.1.1–2.1.2, ch. 6), Hamaker van der Waals and the square well (seed 001
//! §6.2.4). The pass that applies them, with the per-pair state they carry, is `engine::cohesion`.

use serde::{Deserialize, Serialize};

use super::cohesion::{Hamaker, SquareWell};

/// A cohesion model, chosen by name in the scenario's `cohesion:` key.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum CohesionModel {
    /// Pendular liquid bridges: Mikami's capillary force, the viscous forces of the liquid, the bridge volume taken
    /// from both particles on contact and shared back on rupture. The liquid each particle carries at the start and
    /// its contact angle are species properties (`liquid_content`, `contact_angle_deg`).
    LiquidBridge(LiquidBridge),
    /// Hamaker van der Waals attraction with an inner cutoff (seed 001 eqs 6.34–6.37).
    Hamaker(HamakerCohesion),
    /// Square well applied as impulses when a pair crosses the well's edge (seed 001 §6.2.4.2).
    SquareWell(SquareWellCohesion),
}

/// Liquid bridge parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LiquidBridge {
    /// Surface tension γ of the liquid, N/m (water: 0.072).
    pub surface_tension_n_per_m: f64,
    /// Dynamic viscosity μ of the liquid, Pa s (water: 1e-3); 0 leaves out the viscous forces (2.19–2.20).
    #[serde(default)]
    pub viscosity_pa_s: f64,
    /// Smallest gap the viscous forces see (surface roughness), m: they use max(S, this). Default 1 % of the
    /// smallest particle radius.
    #[serde(default)]
    pub min_gap_m: Option<f64>,
    /// Liquid sprayed onto the bed's free surface (seed 000 §6.3.2); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spray: Option<Spray>,
    /// Which capillary force law bridges use (default `auto`).
    #[serde(default, skip_serializing_if = "CapillaryForce::is_auto")]
    pub capillary_force: CapillaryForce,
    /// Bridges between particles and walls too (default false: seed 000 leaves them out to avoid size effects). A
    /// wall bridge takes half the particle's liquid on contact (eq 6.1 with the wall as a sphere of infinite
    /// radius), pulls with Mikami's force at R = 2R_i (a plane is a sphere of R* = R_i) at the mean of the
    /// particle's and the wall's contact angles, and on rupture returns all of its liquid to the particle (the
    /// wall is dry: CHOICE, the film a wall would keep is not tracked).
    #[serde(default, skip_serializing_if = "is_false")]
    pub walls: bool,
    /// Time from which bridges form, s (default 0). Before it the particles carry their liquid but touch dry, so a
    /// bed can settle dry and be wetted in place: wet and dry runs of one seed then start from the same packing.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bridges_from_s: f64,
    /// How much liquid a new bridge takes from its particles (default `caps`, seed 000 eqs 6.1–6.4).
    #[serde(default, skip_serializing_if = "BridgeVolume::is_caps")]
    pub bridge_volume: BridgeVolume,
    /// The radius in the viscous forces (seed 000 eqs 2.19–2.20; default `effective`).
    #[serde(default, skip_serializing_if = "ViscousRadius::is_effective")]
    pub viscous_radius: ViscousRadius,
}

/// How much liquid a bridge takes when it forms. Either way the liquid moves from the particles' films into the
/// bridge and back on rupture, so the liquid is conserved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BridgeVolume {
    /// Each particle gives the liquid on its cap facing the other (seed 000 eqs 6.1–6.4; a wall bridge takes half
    /// the particle's liquid). With seed 000's V̂ ≤ 0.02 per particle a bridge holds V/R³ ≈ 1e-3. Default.
    #[default]
    Caps,
    /// A bridge of V̂ = V/R³, R = 2R* the pair's equal-sphere radius (R between equal particles), half from each
    /// particle; to a wall, V̂ R_i³ from the particle. A particle holding less than its share gives all it has, so
    /// give the particles enough liquid (a bead with n bridges needs V̂ ≥ n V̂_bridge/2). V̂ in (0, 0.1], the range
    /// of Mikami's fit. Issue 41's "larger bridges" reading (the common fixed-volume bridge of wet DEM studies).
    Fixed(f64),
}

impl BridgeVolume {
    fn is_caps(&self) -> bool {
        *self == BridgeVolume::Caps
    }
}

/// The radius R of the liquid's viscous forces between two particles, F_n = 6πμR² v_n/S and F_t = (8/15 ln(R/S) +
/// 0.9588) 6πμR v_t (seed 000 eqs 2.19–2.20 with 2h = S the surface gap).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ViscousRadius {
    /// R* = R_i R_j/(R_i + R_j): Reynolds lubrication between two spheres (R/2 for equal ones), and R_i against a
    /// wall. Default.
    #[default]
    Effective,
    /// The particle radius as the seed prints it, R = 2R* between particles (four times the normal force of
    /// `effective` for equal spheres); R_i against a wall, where the printed formula is already Reynolds'. A
    /// reading to compare against (issue 41).
    AsPrinted,
}

impl ViscousRadius {
    fn is_effective(&self) -> bool {
        *self == ViscousRadius::Effective
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// The capillary force law of liquid bridges.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CapillaryForce {
    /// Mikami's fit (seed 000 eqs 2.16–2.17) between particles of equal radius with contact angle 0, where it is
    /// settled against the exact bridge (within 5 %, VALIDATION B2); the Young–Laplace table (eqs 6.5–6.28) for
    /// every other pair (unequal radii or contact angles, or θ > 0, where Mikami's θ² term as printed is 15–160 %
    /// above the exact bridge and with its sign flipped still 12–46 % off). Bridges to walls always use the
    /// sphere–plane table (Mikami's fit read at R* = R_i is 67–78 % below it near rupture).
    #[default]
    Auto,
    /// The Young–Laplace table for every pair.
    YoungLaplace,
    /// Mikami's fit for every pair, read as seed 000 prints it under eq 2.17: F̂ = F/(2πRγ) and 2ĥ the surface gap
    /// over R, so F = 2πRγ F̂(S/(2R)) with R = 2R* (twice the settled reading's force, over twice its range; see
    /// `capillary.rs`). A reading to compare against (issue 41), not the settled law. Bridges to walls keep the
    /// sphere–plane table.
    MikamiAsPrinted,
}

impl CapillaryForce {
    fn is_auto(&self) -> bool {
        *self == CapillaryForce::Auto
    }
}

/// Spray from above (seed 000 §6.3.2): at every spray step the particles on the bed's free surface get their liquid
/// raised to `max_liquid_content`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Spray {
    /// The liquid a sprayed particle is brought up to, as V̂ = V/R³ (seed 000: 0.02).
    pub max_liquid_content: f64,
    /// Spray every this many steps (seed 000: every step; default 1).
    #[serde(default = "one")]
    pub every_steps: u64,
    /// Spraying starts at this time, s (default 0).
    #[serde(default)]
    pub start_s: f64,
}

fn one() -> u64 {
    1
}

/// Hamaker parameters; the force acts between surfaces closer than `outer_cutoff_m`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HamakerCohesion {
    /// Hamaker constant A, J.
    pub constant_j: f64,
    /// Inner cutoff H_cut, m (seed 001: 4e-10 m).
    pub inner_cutoff_m: f64,
    /// Gap beyond which the attraction is left out, m. Seed 001 names no outer cutoff; the force there is
    /// (H_cut/H)² of its largest value (1.6e-11 at H = 0.1 mm).
    pub outer_cutoff_m: f64,
    /// Also between particles and walls (eq 6.36: twice the sphere–sphere value). Default true.
    #[serde(default = "yes")]
    pub walls: bool,
}

/// Square-well parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SquareWellCohesion {
    /// Well depth D, J.
    pub depth_j: f64,
    /// r_outer / r_inner (seed 001's beds: 1.01): a pair is in the well while its centres are closer than
    /// ratio × (R_i + R_j).
    pub outer_to_inner_radius_ratio: f64,
    /// Also between particles and walls, with the depth doubled and the wall's mass infinite (seed 001 §6.2.4.2).
    /// Default true.
    #[serde(default = "yes")]
    pub walls: bool,
}

fn yes() -> bool {
    true
}

impl HamakerCohesion {
    pub fn law(&self) -> Hamaker {
        Hamaker {
            constant_j: self.constant_j,
            cutoff_m: self.inner_cutoff_m,
        }
    }
}

impl SquareWellCohesion {
    pub fn well(&self) -> SquareWell {
        SquareWell {
            depth_j: self.depth_j,
            outer_to_inner_radius_ratio: self.outer_to_inner_radius_ratio,
        }
    }
}

impl CohesionModel {
    pub fn name(&self) -> &'static str {
        match self {
            CohesionModel::LiquidBridge(_) => "liquid_bridge",
            CohesionModel::Hamaker(_) => "hamaker",
            CohesionModel::SquareWell(_) => "square_well",
        }
    }

    /// Whether the model acts between particles and walls. Liquid bridges do not by default (seed 000 leaves them out to
    /// avoid wall effects in small beds).
    pub fn acts_on_walls(&self) -> bool {
        match self {
            CohesionModel::LiquidBridge(b) => b.walls,
            CohesionModel::Hamaker(h) => h.walls,
            CohesionModel::SquareWell(w) => w.walls,
        }
    }
}

/// Square-well crossing impulse on the pair's relative normal motion (seed 001 eqs 3.6–3.11 with the reduced mass
/// μ in place of m/2, so that a wall, of infinite mass, has μ = m_i): the change of the relative normal speed
/// `approach_m_per_s` (= −(v_i − v_j)·n with n from j to i: positive while approaching) when the pair crosses the
/// well's edge. `entering`: the pair arrives from outside and gains 2D/μ of squared speed (3.6); otherwise it is
/// leaving and either escapes, losing 2D/μ (3.8), or is captured and reflected (3.10). Returns the new approach
/// speed and whether the pair is now inside the well (entered or captured).
pub fn square_well_crossing(depth_j: f64, reduced_mass_kg: f64, approach_m_per_s: f64, entering: bool) -> (f64, bool) {
    let energy = 2.0 * depth_j / reduced_mass_kg;
    if entering {
        ((approach_m_per_s * approach_m_per_s + energy).sqrt(), true)
    } else {
        let left = approach_m_per_s * approach_m_per_s - energy;
        if left > 0.0 {
            // Escaping: still separating (negative approach speed), slower.
            (-left.sqrt(), false)
        } else {
            // Captured: the separation speed reverses.
            (-approach_m_per_s, true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crossing conserves the pair's relative normal energy plus the well: entering gains D, escaping loses D,
    /// capture keeps it (seed 001 §3).
    #[test]
    fn square_well_crossings_balance_energy() {
        let (depth, mu) = (1e-10, 1e-6);
        let (v, inside) = square_well_crossing(depth, mu, 0.01, true);
        assert!(inside);
        assert!((0.5 * mu * (v * v - 0.01 * 0.01) / depth - 1.0).abs() < 1e-9);
        let (v_out, inside) = square_well_crossing(depth, mu, -0.05, false);
        assert!(!inside && v_out < 0.0);
        assert!((0.5 * mu * (0.05 * 0.05 - v_out * v_out) / depth - 1.0).abs() < 1e-9);
        // Below the escape speed √(2D/μ) ≈ 0.0141 m/s the pair is captured and turns round.
        let (v_back, inside) = square_well_crossing(depth, mu, -0.01, false);
        assert!(inside);
        assert_eq!(v_back, 0.01);
    }
}
