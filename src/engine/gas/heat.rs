//! The gas's energy and its convection with the particles (seed 000 §5.1.2, eqs. 5.5–5.8).
//!
//! The gas temperature is a transported scalar (`transported_scalar.rs`) named `temperature_k`: dividing eq. 5.8 by
//! the gas's heat capacity c_g gives ∂(ερT)/∂t + ∇·(ερuT) = ∇·(ε (k_g/c_g) ∇T) + S/c_g, the scalar equation with
//! Γ = k_g/c_g (CHOICE: ∇·(εk∇T) where the seed writes k∇²(εT); they agree where ε is uniform, and ours passes no
//! heat along a porosity gradient of a gas at one temperature). Walls held at a temperature heat the gas beside them;
//! gas entering carries the inlet's (or jet's) temperature.
//!
//! Each DEM step, under the frozen gas field, particle i at T_i in the cell c that holds its centre receives
//! Q_f = h_gp S_p (T_c − T_i) (eq. 5.5; S_p = 4πR², h_gp from the Nusselt correlation at the cell's porosity and the
//! particle's slip, `models/convection.rs`), added to its heat channel before the pair pass so that its temperature
//! update takes conduction and convection together. The gas's cell receives exactly −Q_f as an explicit source,
//! so particles and gas together conserve energy to rounding (VALIDATION E3). A particle whose centre lies in a
//! blocked cell exchanges nothing (there is no gas there).

use std::f64::consts::PI;

use super::coupled::{GasCoupling, GasScalarId};
use super::transported_scalar::GasScalarSpec;
use crate::engine::Vec3;
use crate::engine::models::convection::NusseltCorrelation;

/// The gas's thermal properties and its convection model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GasThermal {
    pub conductivity_w_per_m_k: f64,
    pub heat_capacity_j_per_kg_k: f64,
    pub nusselt: NusseltCorrelation,
}

/// A coupling's heat: the thermal model and the id of its temperature field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GasHeat {
    pub thermal: GasThermal,
    pub temperature: GasScalarId,
}

impl GasCoupling {
    /// Gives the gas a temperature field (`spec`, named `temperature_k`, whose Γ must be k_g/c_g and whose exchange
    /// explicit) and convection with the particles.
    pub fn attach_heat(&mut self, thermal: GasThermal, spec: GasScalarSpec) -> Result<(), String> {
        let temperature = self.declare_scalar(spec)?;
        self.heat = Some(GasHeat { thermal, temperature });
        Ok(())
    }

    /// The gas temperature per cell, K (`None` without heat).
    pub fn temperature_k(&self) -> Option<&[f64]> {
        self.heat.map(|h| self.scalar(h.temperature).value.as_slice())
    }

    /// Convection between each particle and the gas under the frozen field, for one DEM step: Q_f into particle i
    /// is added to `heat_flow_w[i]`, and −Q_f to its cell's exchange (then the sub-step is closed). Serial, in
    /// particle order, so the gas's sums are the same bits on any thread count.
    pub fn add_convection(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        temperatures_k: &[f64],
        heat_flow_w: &mut [f64],
    ) {
        let Some(heat) = self.heat else {
            return;
        };
        let per_volume_heat_capacity = self.fluid.grid.cell_volume_m3() * heat.thermal.heat_capacity_j_per_kg_k;
        for i in 0..positions_m.len() {
            let Some((c, conductance)) =
                self.convection_conductance(&positions_m[i], &velocities_m_per_s[i], radii_m[i])
            else {
                continue;
            };
            let q = conductance * (self.scalars[heat.temperature.index()].value[c] - temperatures_k[i]);
            heat_flow_w[i] += q;
            self.scalars[heat.temperature.index()]
                .exchange
                .add_transfer(c, -q / per_volume_heat_capacity);
        }
        self.scalars[heat.temperature.index()].exchange.end_sub_step();
    }

    /// The cell holding a particle at `x` (velocity `v`, radius `r`) and its convective conductance h_gp S_p under
    /// the frozen field, W/K: Nu from the correlation at the cell's porosity ε and Re = ε ρ d |u − v|/μ. `None`
    /// without heat or in a blocked cell.
    pub fn convection_conductance(&self, x: &Vec3, v: &Vec3, r: f64) -> Option<(usize, f64)> {
        let thermal = self.heat?.thermal;
        let fluid = &self.fluid;
        let c = fluid.cell_of(x);
        if self.solver.config.blocked.get(c).copied().unwrap_or(false) {
            return None;
        }
        let (rho, mu) = (fluid.gas_density_kg_per_m3, fluid.gas_viscosity_pa_s);
        let prandtl = thermal.heat_capacity_j_per_kg_k * mu / thermal.conductivity_w_per_m_k;
        let porosity = fluid.porosity[c];
        let slip = (fluid.cell_gas_velocity(fluid.cell_indices(c)) - v).norm();
        let diameter = 2.0 * r;
        let reynolds = porosity * rho * diameter * slip / mu;
        let nusselt = thermal.nusselt.nusselt(reynolds, prandtl, porosity);
        let h = nusselt * thermal.conductivity_w_per_m_k / diameter;
        Some((c, h * PI * diameter * diameter))
    }

    /// The gas's thermal energy Σ ε ρ c_g T V over the cells outside blocked ones, J (`None` without heat).
    pub fn thermal_energy_j(&self) -> Option<f64> {
        let heat = self.heat?;
        let config = &self.solver.config;
        let volume = config.grid.cell_volume_m3();
        let t = &self.scalar(heat.temperature).value;
        Some(
            (0..t.len())
                .filter(|&c| !config.blocked.get(c).copied().unwrap_or(false))
                .map(|c| {
                    self.solver.state.porosity[c]
                        * config.density_kg_per_m3
                        * heat.thermal.heat_capacity_j_per_kg_k
                        * t[c]
                        * volume
                })
                .sum(),
        )
    }

    /// The heat the particles' convection has handed the gas since its last step, which the gas takes in at its
    /// next one: c_g V Δt_DEM Σ (gathered transfer), J (`None` without heat).
    pub fn pending_convection_j(&self, dem_dt_s: f64) -> Option<f64> {
        let heat = self.heat?;
        let per_volume = self.solver.config.grid.cell_volume_m3() * heat.thermal.heat_capacity_j_per_kg_k;
        let transfer: f64 = self.scalar(heat.temperature).exchange.transfer_sum.iter().sum();
        Some(per_volume * dem_dt_s * transfer)
    }

    /// The gas's mean temperature weighted by its mass in each cell, Σ ε T / Σ ε over the cells outside blocked
    /// ones, K (`None` without heat).
    pub fn mean_temperature_k(&self) -> Option<f64> {
        let heat = self.heat?;
        let config = &self.solver.config;
        let t = &self.scalar(heat.temperature).value;
        let porosity = &self.solver.state.porosity;
        let (mut sum, mut weight) = (0.0, 0.0);
        for c in (0..t.len()).filter(|&c| !config.blocked.get(c).copied().unwrap_or(false)) {
            sum += porosity[c] * t[c];
            weight += porosity[c];
        }
        Some(sum / weight)
    }
}
