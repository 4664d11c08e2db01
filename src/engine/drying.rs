//! Drying (seed 000 chapter 7): the liquid on the particles and in their bridges evaporates into the gas at the
//! Hertz–Knudsen rate (eq. 7.2, `models::evaporation`), the vapour is carried by the gas (eq. 7.5, a transported
//! scalar, as a mass fraction w so that ρ_g w is the vapour's mass concentration: `PHYSICS.md` §5), and the latent
//! heat leaves the evaporating particle (eq. 7.12).
//!
//! **When.** Once per gas step, right after it, over the gas step's Δt (the DEM sub-steps in between only move the
//! particles and conduct heat). **How.** Implicitly: with α = 1 a 3 mm wet particle at 25 °C evaporates about
//! 1e-4 kg/s, which saturates its gas cell in tens of µs and would cool the particle by thousands of kelvin per
//! millisecond taken explicitly. So per particle i in gas cell c (by its centre; none in a blocked cell), with its
//! Hertz–Knudsen conductance a_i = α π d_i² √(M/(2πRT_i)) and the slope p′ of p_sat at its temperature, the
//! rate ṁ_i = a_i (p_sat(T_i) + p′ ΔT_i − p_v,c) with ΔT_i = −ṁ_i H Δt/(m_i c_p,i) (backward Euler in the
//! particle's temperature, p_sat linearised) and p_v,c = ρ_g w_c R T_g,c/M at the end of the step is linear in
//! w_c: ṁ_i = e_i − f_i ρ_g w_c, e_i = a_i p_sat/D_i, f_i = a_i R T_g,c/(M D_i), D_i = 1 + a_i p′ H Δt/(m_i c_p,i).
//! The vapour's step takes Σ_i (e_i − f_i ρ_g w_c)/V_c as its exchange with the particles (implicit in w), in the
//! conservative form; each particle then evaporates exactly ṁ_i Δt at the new w and cools by ṁ_i H Δt/(m c_p).
//! A particle cannot give more than it holds: one whose ṁ_i Δt exceeds its liquid, or would leave less than
//! [`SMALLEST_BRIDGE`] R³ of it, gives all of it (a dry one gives nothing) as a fixed source, and the vapour's step is solved again; the set of such particles only grows,
//! so this ends (in practice after a few solves). A particle colder than the vapour's dew point condenses
//! (ṁ < 0) onto its film, as eq. 7.1 allows.
//!
//! **A bridge's surface.** Eq. 7.2 counts a wet particle's whole surface π d². CHOICE: a particle is wet while it
//! holds any liquid, as its own film or as its share of a bridge (half a pair bridge, all of a wall bridge), and
//! its evaporation draws on that pool in proportion: its film and its shares of its bridges lose the same
//! fraction. A bridge thus evaporates through the surfaces of the particles it joins, never through a meniscus
//! area of its own (the parabolic profile's free surface is not computed), and a bed whose liquid sits in bridges
//! dries as fast per particle as one whose liquid is film, while a particle holds any. A bridge dried below
//! [`SMALLEST_BRIDGE`] breaks, its remnant going back to its particles' films.
//!
//! **What is left out** (CHOICE, as the seed): the liquid's own heat capacity (the particle stays lumped with its
//! solid's), the vapour's enthalpy carried into the gas (the gas's energy equation sees no evaporation), and the
//! vapour's effect on the gas's density (it stays ρ_g). D_g (eq. 7.6) is taken at the gas's mass-weighted mean
//! temperature of each step and at p = p0 (the gas is incompressible: its absolute pressure is one atmosphere).
//!
//! **Ledger.** Liquid on particles + in bridges + vapour in the gas + vapour gone out − vapour come in = the
//! start's liquid and vapour + liquid sprayed, at any time, to the vapour solve's residual ([`DryingLedger`]);
//! the particles' and the gas's sensible heat + H × (vapour made) change only by conduction from the walls and
//! what the gas carries through its boundary.

use super::contacts::AlignedHistory;
use super::gas::coupled::{GasCoupling, GasScalarId};
use super::gas::{GasScalarSpec, ScalarExchange};
use super::liquid::{SMALLEST_BRIDGE, total_liquid_m3};
use super::models::evaporation::{
    GAS_CONSTANT_J_PER_MOL_K, NORMAL_ATMOSPHERE_PA, hertz_knudsen_conductance_kg_per_s_pa, saturation_pressure_pa,
    saturation_pressure_slope_pa_per_k, vapour_diffusivity_m2_per_s,
};
use super::neighbor::NeighborList;
use super::particles::Particles;

/// The vapour's name among the gas's transported scalars (its checkpoint dataset `gas/vapour_mass_fraction`).
pub const VAPOUR_FIELD: &str = "vapour_mass_fraction";

/// Relative residual the vapour's linear solves reach: the ledger closes to about this (times the steps).
pub const VAPOUR_SOLVE_TOLERANCE: f64 = 1e-14;

/// Solves of one drying step before it gives up (the capped set grows by at least one particle per solve, and in
/// practice settles within a few).
const MAX_SOLVES: usize = 64;

/// The drying model's constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DryingConfig {
    /// α of eq. 7.2.
    pub evaporation_coefficient: f64,
    /// H of eq. 7.12, J/kg.
    pub latent_heat_j_per_kg: f64,
    /// ρ_l, kg/m³: converts the liquid's volumes (m³, as bridges and films hold them) to mass.
    pub liquid_density_kg_per_m3: f64,
    /// M of eqs. 7.2 and 7.5, kg/mol.
    pub molar_mass_kg_per_mol: f64,
}

/// The drying step's running totals, part of the state (checkpointed), all in kg.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DryingLedger {
    /// Liquid on the particles and in the bridges when the run started.
    pub initial_liquid_kg: f64,
    /// Vapour in the gas when the run started.
    pub initial_vapour_kg: f64,
    /// Liquid sprayed since.
    pub sprayed_kg: f64,
    /// Liquid evaporated since (condensation counts negative).
    pub evaporated_kg: f64,
    /// Vapour carried into the gas through its boundary (inlets, jets).
    pub vapour_in_kg: f64,
    /// Vapour carried out of the gas through its boundary (outlets).
    pub vapour_out_kg: f64,
}

/// A gas's drying: the model, its vapour field and the ledger.
#[derive(Debug, Clone, PartialEq)]
pub struct GasDrying {
    pub config: DryingConfig,
    /// The vapour mass fraction w, kg/kg (a scalar with [`super::gas::ScalarExchange::Evaporation`]).
    pub vapour: GasScalarId,
    pub ledger: DryingLedger,
}

/// What one drying step did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DryingStep {
    /// Liquid evaporated (negative: condensed), kg.
    pub evaporated_kg: f64,
    /// Vapour solves taken.
    pub solves: usize,
    /// Particles that gave all their liquid.
    pub dried_out: usize,
    /// Linear iterations over the solves.
    pub linear_iterations: u64,
    /// Bridges that dried below [`SMALLEST_BRIDGE`] and broke.
    pub bridges_dried: usize,
}

/// One particle's rate, linear in its cell's vapour mass fraction: ṁ = e − f ρ w, kg/s (positive: evaporation).
#[derive(Debug, Clone, Copy)]
struct Rate {
    cell: usize,
    e_kg_per_s: f64,
    /// f ρ, kg/s per unit of w.
    f_rho_kg_per_s: f64,
    /// The most it can evaporate over the step, kg/s (its liquid over Δt).
    available_kg_per_s: f64,
    /// [`SMALLEST_BRIDGE`] R³ of liquid over Δt, kg/s: evaporating to less than that left dries it out.
    floor_kg_per_s: f64,
    /// Set once it evaporates `available_kg_per_s` whatever w is.
    fixed: Option<f64>,
}

impl Rate {
    fn at(&self, w: f64) -> f64 {
        self.fixed.unwrap_or(self.e_kg_per_s - self.f_rho_kg_per_s * w)
    }
}

/// Particle i's thermal mass m_i c_p,i (J/K), which the latent heat of what evaporates cools.
#[inline]
fn thermal_mass_j_per_k(p: &Particles, heat_capacity_j_per_kg_k: &[f64], i: usize) -> f64 {
    p.mass_kg[i] * heat_capacity_j_per_kg_k[p.species[i].index()]
}

/// The liquid each particle holds, m³: its film plus half of each of its pair bridges and all of each wall bridge.
fn liquid_pools_m3(p: &Particles, list: &NeighborList, history: &AlignedHistory) -> Vec<f64> {
    let mut pool = p.liquid_m3.clone();
    let (pairs, walls) = (
        &history.pair.cohesion.bridge_volume_m3,
        &history.wall.cohesion.bridge_volume_m3,
    );
    for i in 0..p.len() {
        for k in list.pairs_of(i) {
            let v = pairs[k];
            if v > 0.0 {
                pool[i] += 0.5 * v;
                pool[list.partner[k] as usize] += 0.5 * v;
            }
        }
        for k in list.walls_of(i) {
            pool[i] += walls[k];
        }
    }
    pool
}

/// The liquid of the particles and bridges, kg.
pub fn liquid_kg(config: &DryingConfig, liquid_m3: &[f64], history: &AlignedHistory) -> f64 {
    total_liquid_m3(liquid_m3, history) * config.liquid_density_kg_per_m3
}

/// One drying step over the gas step of `dt_s` that `gas` has just taken (see the module documentation).
/// `heat_capacity_j_per_kg_k` is per species. Changes the particles' films and temperatures, the bridges'
/// volumes, the vapour field and the ledger; the bridges' cached constants must then be refreshed (their volumes
/// changed). Errors name the failed solve.
pub fn dry(
    gas: &mut GasCoupling,
    p: &mut Particles,
    heat_capacity_j_per_kg_k: &[f64],
    list: &NeighborList,
    history: &mut AlignedHistory,
    dt_s: f64,
) -> Result<DryingStep, String> {
    let Some(drying) = gas.drying.clone() else {
        return Ok(DryingStep::default());
    };
    let config = drying.config;
    let (old_porosity, mass_flow) = gas
        .step_flows
        .take()
        .ok_or("the drying step needs the gas step's flows")?;
    let temperature = gas
        .temperature_k()
        .ok_or("drying needs the gas's temperature")?
        .to_vec();
    let grid = gas.solver.config.grid.clone();
    let volume = grid.cell_volume_m3();
    let rho = gas.solver.config.density_kg_per_m3;
    let molar_mass = config.molar_mass_kg_per_mol;
    let latent = config.latent_heat_j_per_kg;
    // D_g at the gas's mean temperature, p = p0.
    let mean_t = gas.mean_temperature_k().expect("a gas with a temperature");
    gas.scalar_mut(drying.vapour).spec.diffusion_kg_per_m_s =
        rho * vapour_diffusivity_m2_per_s(mean_t, NORMAL_ATMOSPHERE_PA);

    let pool_m3 = liquid_pools_m3(p, list, history);
    let blocked = &gas.solver.config.blocked;
    let mut rates: Vec<Option<Rate>> = Vec::with_capacity(p.len());
    for (i, &pool_i_m3) in pool_m3.iter().enumerate() {
        let c = gas.fluid.cell_of(&p.position_m[i]);
        if blocked.get(c).copied().unwrap_or(false) {
            rates.push(None);
            continue;
        }
        let t = p.temperature_k[i];
        let a =
            hertz_knudsen_conductance_kg_per_s_pa(config.evaporation_coefficient, 2.0 * p.radius_m[i], t, molar_mass);
        let thermal_mass = thermal_mass_j_per_k(p, heat_capacity_j_per_kg_k, i);
        let d = 1.0 + a * saturation_pressure_slope_pa_per_k(t) * latent * dt_s / thermal_mass;
        let pressure_per_density = GAS_CONSTANT_J_PER_MOL_K * temperature[c] / molar_mass;
        rates.push(Some(Rate {
            cell: c,
            e_kg_per_s: a * saturation_pressure_pa(t) / d,
            f_rho_kg_per_s: a * pressure_per_density * rho / d,
            available_kg_per_s: pool_i_m3 * config.liquid_density_kg_per_m3 / dt_s,
            floor_kg_per_s: SMALLEST_BRIDGE * p.radius_m[i].powi(3) * config.liquid_density_kg_per_m3 / dt_s,
            fixed: None,
        }));
    }

    let cells = grid.cells();
    let vapour = gas.scalar(drying.vapour);
    let boundary_value = vapour.boundary_values(&gas.solver);
    let mut step = DryingStep::default();
    let (w, flows) = loop {
        let (mut k, mut kw, mut source) = (vec![0.0; cells], vec![0.0; cells], vec![0.0; cells]);
        for r in rates.iter().flatten() {
            match r.fixed {
                Some(m) => source[r.cell] += m / volume,
                None => {
                    k[r.cell] += r.f_rho_kg_per_s / volume;
                    kw[r.cell] += r.e_kg_per_s / volume;
                }
            }
        }
        let equation = vapour.equation(
            &gas.solver,
            &old_porosity,
            &mass_flow,
            &boundary_value,
            &k,
            &kw,
            &source,
            true,
        );
        let (w, report) = vapour.solve(
            &equation,
            dt_s,
            VAPOUR_SOLVE_TOLERANCE,
            gas.solver.config.max_linear_iterations,
        )?;
        step.solves += 1;
        step.linear_iterations += report.iterations as u64;
        let mut changed = false;
        for r in rates.iter_mut().flatten() {
            let rate = r.at(w[r.cell]);
            // More than it holds, or so much that less than the floor would be left: it dries out.
            if r.fixed.is_none() && rate > 0.0 && rate > r.available_kg_per_s - r.floor_kg_per_s {
                r.fixed = Some(r.available_kg_per_s);
                changed = true;
            }
        }
        if !changed {
            let flows = equation.boundary_flows(&w);
            break (w, flows);
        }
        if step.solves >= MAX_SOLVES {
            return Err(format!(
                "drying: the particles that run dry within the step were still changing after {MAX_SOLVES} vapour \
                 solves"
            ));
        }
    };

    // Each particle's share: the fraction of its pool it evaporates (0 when it condenses), its temperature.
    let mut fraction = vec![0.0; p.len()];
    for (i, rate) in rates.iter().enumerate() {
        let Some(r) = rate else { continue };
        let m_kg = r.at(w[r.cell]) * dt_s;
        if r.fixed.is_some() {
            step.dried_out += usize::from(r.available_kg_per_s > 0.0);
            fraction[i] = if r.available_kg_per_s > 0.0 { 1.0 } else { 0.0 };
        } else if m_kg > 0.0 {
            fraction[i] = (m_kg / (pool_m3[i] * config.liquid_density_kg_per_m3)).min(1.0);
        } else {
            p.liquid_m3[i] -= m_kg / config.liquid_density_kg_per_m3;
        }
        step.evaporated_kg += m_kg;
        let thermal_mass = thermal_mass_j_per_k(p, heat_capacity_j_per_kg_k, i);
        p.temperature_k[i] -= m_kg * latent / thermal_mass;
    }
    for (liquid, &f) in p.liquid_m3.iter_mut().zip(&fraction) {
        if f > 0.0 {
            *liquid = if f >= 1.0 { 0.0 } else { *liquid * (1.0 - f) };
        }
    }
    let (pairs, walls) = (
        &mut history.pair.cohesion.bridge_volume_m3,
        &mut history.wall.cohesion.bridge_volume_m3,
    );
    for i in 0..p.len() {
        for k in list.pairs_of(i) {
            let j = list.partner[k] as usize;
            let (fi, fj) = (fraction[i], fraction[j]);
            if pairs[k] > 0.0 && (fi > 0.0 || fj > 0.0) {
                let left = if fi >= 1.0 && fj >= 1.0 {
                    0.0
                } else {
                    pairs[k] * (1.0 - 0.5 * (fi + fj))
                };
                if left < SMALLEST_BRIDGE * p.radius_m[i].min(p.radius_m[j]).powi(3) {
                    // Broken: its remnant goes back to the two films in halves.
                    p.liquid_m3[i] += 0.5 * left;
                    p.liquid_m3[j] += 0.5 * left;
                    pairs[k] = 0.0;
                    step.bridges_dried += 1;
                } else {
                    pairs[k] = left;
                }
            }
        }
        if fraction[i] > 0.0 {
            for k in list.walls_of(i) {
                if walls[k] == 0.0 {
                    continue;
                }
                let left = if fraction[i] >= 1.0 {
                    0.0
                } else {
                    walls[k] * (1.0 - fraction[i])
                };
                if left < SMALLEST_BRIDGE * p.radius_m[i].powi(3) {
                    p.liquid_m3[i] += left;
                    walls[k] = 0.0;
                    step.bridges_dried += 1;
                } else {
                    walls[k] = left;
                }
            }
        }
    }
    // Films left below the floor (a bridge's remnant, or a film shrunk with its pool) evaporate now, into the
    // particle's cell, with their latent heat: a film must not decay towards zero and form a vanishing bridge.
    let mut w = w;
    let porosity = &gas.solver.state.porosity;
    for (i, rate) in rates.iter().enumerate() {
        let Some(r) = rate else { continue };
        let film = p.liquid_m3[i];
        if film > 0.0 && film < SMALLEST_BRIDGE * p.radius_m[i].powi(3) {
            let m_kg = film * config.liquid_density_kg_per_m3;
            p.liquid_m3[i] = 0.0;
            w[r.cell] += m_kg / (porosity[r.cell] * rho * volume);
            let thermal_mass = thermal_mass_j_per_k(p, heat_capacity_j_per_kg_k, i);
            p.temperature_k[i] -= m_kg * latent / thermal_mass;
            step.evaporated_kg += m_kg;
        }
    }
    let vapour = gas.scalar_mut(drying.vapour);
    vapour.value = w;
    let ledger = &mut gas.drying.as_mut().expect("checked above").ledger;
    ledger.evaporated_kg += step.evaporated_kg;
    ledger.vapour_in_kg += flows.in_per_s * dt_s;
    ledger.vapour_out_kg += flows.out_per_s * dt_s;
    Ok(step)
}

impl GasCoupling {
    /// Gives the gas a vapour field (`spec`, named [`VAPOUR_FIELD`], with [`ScalarExchange::Evaporation`]) and the
    /// drying model; the gas must already carry a temperature. The ledger starts empty:
    /// [`crate::engine::Simulation::start_drying_ledger`] records the start's liquid and vapour.
    pub fn attach_drying(&mut self, config: DryingConfig, spec: GasScalarSpec) -> Result<(), String> {
        if self.heat.is_none() {
            return Err("drying needs the gas's temperature".into());
        }
        if spec.exchange != ScalarExchange::Evaporation || spec.name != VAPOUR_FIELD {
            return Err(format!(
                "the vapour field must be {VAPOUR_FIELD} with the evaporation exchange"
            ));
        }
        let vapour = self.declare_scalar(spec)?;
        self.drying = Some(GasDrying {
            config,
            vapour,
            ledger: DryingLedger::default(),
        });
        Ok(())
    }

    /// The vapour in the gas, kg: Σ ε ρ_g w V over the cells outside blocked ones (`None` without drying).
    pub fn vapour_kg(&self) -> Option<f64> {
        let drying = self.drying.as_ref()?;
        let config = &self.solver.config;
        let w = &self.scalar(drying.vapour).value;
        let volume = config.grid.cell_volume_m3();
        Some(
            (0..w.len())
                .filter(|&c| !config.blocked.get(c).copied().unwrap_or(false))
                .map(|c| self.solver.state.porosity[c] * config.density_kg_per_m3 * w[c] * volume)
                .sum(),
        )
    }

    /// The gas's mean relative humidity p_v/p_sat(T_g), weighted by its mass in each cell (`None` without drying).
    pub fn mean_relative_humidity(&self) -> Option<f64> {
        let drying = self.drying.as_ref()?;
        let t = self.temperature_k()?;
        let config = &self.solver.config;
        let w = &self.scalar(drying.vapour).value;
        let porosity = &self.solver.state.porosity;
        let (mut sum, mut weight) = (0.0, 0.0);
        for c in (0..w.len()).filter(|&c| !config.blocked.get(c).copied().unwrap_or(false)) {
            let p_v =
                config.density_kg_per_m3 * w[c] * GAS_CONSTANT_J_PER_MOL_K * t[c] / drying.config.molar_mass_kg_per_mol;
            sum += porosity[c] * p_v / saturation_pressure_pa(t[c]);
            weight += porosity[c];
        }
        Some(sum / weight)
    }
}
