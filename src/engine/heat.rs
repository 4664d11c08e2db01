//! Heat transfer's run configuration (seed 000 chapter 5): what the pair pass needs to carry heat through every
//! contact, and what the particles' temperature update needs.
//!
//! Each particle is lumped (one temperature; valid for Biot ≪ 1, §5.1.3) and its energy follows
//! m c_p dT/dt = Σ Q_c (eq. 5.2), Q_c through the solid contact, a liquid bridge and, where the run has it, the gas
//! lens round a contact or narrow gap (`models::gas_lens`): the pair pass sums the conduction through its contacts and walls into the
//! `heat_flow_w` channel (`channels.rs`) in its fixed order, and as soon as a particle's sum is complete the pass
//! advances its temperature by one explicit step, T += dt Q/(m c_p). Every pair's heat leaves one particle as it
//! enters the other, so the particles' total energy Σ m c_p T changes only by what the walls give, to rounding.
//! Temperatures are read at the start of the step (a particle's own is written only once all its contacts are
//! done), so any thread count gives the same bits.

use super::models::PairTable;
use super::models::bridge_conduction::{BridgeLengthTable, bridge_conductance_w_per_k};
use super::models::conduction::{ThermalPair, effective_modulus_pa};
use super::models::gas_lens::GasLens;
use super::particles::{Particles, SpeciesId, SpeciesTable};

/// Everything heat transfer needs that does not change during a run.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatConfig {
    n_species: usize,
    /// The conduction constants per species pair (walls are species), `n × n`.
    pairs: Vec<ThermalPair>,
    /// Per species, J/(kg K) (NaN where a species, e.g. a wall's, states none).
    pub heat_capacity_j_per_kg_k: Vec<f64>,
    /// Per wall: its fixed temperature, K, or `None` (adiabatic: no heat crosses it).
    pub wall_temperature_k: Vec<Option<f64>>,
    /// Per wall: the time from which a heated wall is at its temperature, s (adiabatic before).
    pub wall_heated_from_s: Vec<f64>,
    /// Conduction through liquid bridges (a run with liquid bridges).
    pub bridges: Option<BridgeConduction>,
    /// Conduction through the gas between nearly touching surfaces (`heat.gas.lens_conduction`, a run with gas).
    pub lens: Option<GasLens>,
    /// How far beyond contact the lens reaches (f R_b of the largest particle), m; 0 without the lens.
    pub lens_reach_m: f64,
}

/// Conduction through liquid bridges (seed 000 eqs 7.8–7.11), H_l = k_l V/d²: the liquid's conductivity and the
/// tables of the bridge length d per species pair (`n × n`, d/R of the first species) and per particle–wall species
/// pair (the wall a sphere of infinite radius), built where particles of those species can meet.
#[derive(Debug, Clone, PartialEq)]
pub struct BridgeConduction {
    pub liquid_conductivity_w_per_m_k: f64,
    n_species: usize,
    pairs: Vec<Option<BridgeLengthTable>>,
    walls: Vec<Option<BridgeLengthTable>>,
}

impl BridgeConduction {
    /// Tables for every pair of `particle_species` and for each of them against every species in `wall_species`
    /// (indices into `species`). Errors name the pair whose bridges the parabola cannot describe.
    pub fn new(
        species: &SpeciesTable,
        particle_species: &[usize],
        wall_species: &[usize],
        liquid_conductivity_w_per_m_k: f64,
    ) -> Result<BridgeConduction, String> {
        let n = species.len();
        let mut pairs = vec![None; n * n];
        let mut walls = vec![None; n * n];
        let table = |a: usize, radius_j_m: f64, angle_j_rad: f64| {
            let sa = &species.species[a];
            BridgeLengthTable::new(sa.radius_m, radius_j_m, sa.contact_angle_rad, angle_j_rad).ok_or_else(|| {
                format!(
                    "no parabolic liquid bridge fits species '{}' (contact angle {} rad)",
                    sa.name, sa.contact_angle_rad
                )
            })
        };
        for &a in particle_species {
            for &b in particle_species {
                let sb = &species.species[b];
                pairs[a * n + b] = Some(table(a, sb.radius_m, sb.contact_angle_rad)?);
            }
            for &w in wall_species {
                walls[a * n + w] = Some(table(a, f64::INFINITY, species.species[w].contact_angle_rad)?);
            }
        }
        Ok(BridgeConduction {
            liquid_conductivity_w_per_m_k,
            n_species: n,
            pairs,
            walls,
        })
    }

    /// H_l of a bridge of `volume_m3` between particles of species `a` and `b` at surface gap `gap_m`, W/K.
    #[inline]
    pub fn pair_conductance_w_per_k(&self, a: SpeciesId, b: SpeciesId, volume_m3: f64, gap_m: f64) -> f64 {
        self.conductance_w_per_k(&self.pairs[a.index() * self.n_species + b.index()], volume_m3, gap_m)
    }

    /// H_l of a bridge of `volume_m3` between a particle of species `a` and a wall of species `wall` at gap
    /// `gap_m`, W/K.
    #[inline]
    pub fn wall_conductance_w_per_k(&self, a: SpeciesId, wall: SpeciesId, volume_m3: f64, gap_m: f64) -> f64 {
        self.conductance_w_per_k(&self.walls[a.index() * self.n_species + wall.index()], volume_m3, gap_m)
    }

    /// H_l through `table`'s bridge length (0 without a table).
    #[inline(always)]
    fn conductance_w_per_k(&self, table: &Option<BridgeLengthTable>, volume_m3: f64, gap_m: f64) -> f64 {
        table.as_ref().map_or(0.0, |t| {
            bridge_conductance_w_per_k(
                self.liquid_conductivity_w_per_m_k,
                volume_m3,
                t.length_m(volume_m3, gap_m),
            )
        })
    }

    /// The largest H_l/R_i over the tables' nodes, W/(m K) (for the explicit step's bound).
    fn largest_conductance_per_radius_w_per_m_k(&self) -> f64 {
        self.pairs
            .iter()
            .chain(&self.walls)
            .flatten()
            .map(|t| self.liquid_conductivity_w_per_m_k * t.largest_volume_over_length_squared_per_radius())
            .fold(0.0, f64::max)
    }
}

impl HeatConfig {
    /// The conduction table of `species` under the contact law's moduli (`pair_table`), with the soft-contact
    /// correction where `correct_soft_contacts` and a species states its real modulus, and the walls' conditions.
    pub fn new(
        species: &SpeciesTable,
        pair_table: &PairTable,
        correct_soft_contacts: bool,
        wall_temperature_k: Vec<Option<f64>>,
        wall_heated_from_s: Vec<f64>,
    ) -> HeatConfig {
        let n = species.len();
        let mut pairs = Vec::with_capacity(n * n);
        for (a, sa) in species.species.iter().enumerate() {
            for (b, sb) in species.species.iter().enumerate() {
                let simulated = pair_table
                    .get(SpeciesId(a as u16), SpeciesId(b as u16))
                    .effective_youngs_modulus_pa;
                let softened = sa.real_youngs_modulus_pa.is_some() || sb.real_youngs_modulus_pa.is_some();
                let real = (correct_soft_contacts && softened).then(|| {
                    effective_modulus_pa(
                        sa.real_youngs_modulus_pa.unwrap_or(sa.youngs_modulus_pa),
                        sa.poisson_ratio,
                        sb.real_youngs_modulus_pa.unwrap_or(sb.youngs_modulus_pa),
                        sb.poisson_ratio,
                    )
                });
                pairs.push(ThermalPair::new(
                    sa.thermal_conductivity_w_per_m_k,
                    sb.thermal_conductivity_w_per_m_k,
                    simulated,
                    real,
                ));
            }
        }
        HeatConfig {
            n_species: n,
            pairs,
            heat_capacity_j_per_kg_k: species
                .species
                .iter()
                .map(|s| s.heat_capacity_j_per_kg_k.unwrap_or(f64::NAN))
                .collect(),
            wall_temperature_k,
            wall_heated_from_s,
            bridges: None,
            lens: None,
            lens_reach_m: 0.0,
        }
    }

    /// Conducts through the gas lens `lens` between particles of radii up to `largest_radius_m` and walls.
    pub fn with_lens(mut self, lens: GasLens, largest_radius_m: f64) -> HeatConfig {
        self.lens_reach_m = lens.reach_m(largest_radius_m);
        self.lens = Some(lens);
        self
    }

    /// Each wall's temperature at time `time_s` (`None`: adiabatic then), into `out`.
    pub fn wall_temperatures_at(&self, time_s: f64, out: &mut Vec<Option<f64>>) {
        out.clear();
        out.extend(
            self.wall_temperature_k
                .iter()
                .zip(&self.wall_heated_from_s)
                .map(|(t, &from)| t.filter(|_| time_s >= from)),
        );
    }

    /// The conduction constants of species pair (a, b).
    #[inline(always)]
    pub fn pair(&self, a: SpeciesId, b: SpeciesId) -> &ThermalPair {
        &self.pairs[a.index() * self.n_species + b.index()]
    }

    /// 1/(m c_p) per particle, 1/(J/K).
    pub fn inverse_thermal_mass(&self, p: &Particles) -> Vec<f64> {
        p.mass_kg
            .iter()
            .zip(&p.species)
            .map(|(m, s)| 1.0 / (m * self.heat_capacity_j_per_kg_k[s.index()]))
            .collect()
    }

    /// The largest rate λ = Σ H (1/C_i + 1/C_j) any particle's temperature can relax at, 1/s, bounded from above
    /// for the explicit step's stability (dt λ < 2): twelve partners and a wall, each at the largest overlap the run
    /// tolerates (`max_overlap_fraction` of the radius), against the smallest thermal mass. A scenario whose time
    /// step breaks it is refused.
    pub fn fastest_relaxation_per_s(&self, p: &Particles, max_overlap_fraction: f64) -> f64 {
        let inverse = self.inverse_thermal_mass(p);
        let largest_inverse = inverse.iter().copied().fold(0.0, f64::max);
        let largest_radius = p.max_radius_m();
        let largest_pair = self
            .pairs
            .iter()
            .map(|t| t.conductance_per_radius_w_per_m_k * t.radius_scale.max(1.0))
            .fold(0.0, f64::max);
        // The geometric radius √(R δ) at the tolerated overlap bounds every law's (the linear spring's corrected
        // radius is the real, stiffer material's and smaller).
        let contact_radius = (largest_radius * max_overlap_fraction * largest_radius).sqrt();
        // A liquid bridge to each partner as well.
        let largest_bridge = self
            .bridges
            .as_ref()
            .map_or(0.0, |b| b.largest_conductance_per_radius_w_per_m_k() * largest_radius);
        // And the gas lens.
        let largest_lens = self.lens.map_or(0.0, |l| l.largest_conductance_w_per_k(largest_radius));
        13.0 * (largest_pair * contact_radius + largest_bridge + largest_lens) * 2.0 * largest_inverse
    }
}
