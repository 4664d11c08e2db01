//! A coupled gas–particle simulation: the DEM sub-cycles `dem_steps_per_gas_step` steps under a frozen gas field
//! (seed 001 Fig. 6.6: gas time step = n × particle time step), then the gas takes one step with the porosity of
//! the particles at that moment and, as its momentum source, the particles' drag reaction averaged over the
//! sub-steps (so the momentum the gas receives over a gas step is exactly what the particles lost to drag).

use super::coupling::{PorosityMethod, porosity};
use super::fluid_forces::FluidForces;
use super::simple::{GasConfig, GasSolver, StepReport};
use crate::engine::models::drag::DragLaw;
use crate::engine::{NumericalError, Simulation};

pub struct CoupledSimulation {
    pub dem: Simulation,
    pub gas: GasSolver,
    pub porosity_method: PorosityMethod,
    /// Porosity is not allowed below this (a cell over-filled by the split would otherwise reach 0).
    pub min_porosity: f64,
    pub dem_steps_per_gas_step: u64,
    /// A uniform force per unit volume on the gas besides drag, N/m³ (e.g. in a periodic box, the mean pressure
    /// gradient that carries the particles' weight, without which the mixture would accelerate for ever).
    pub gas_body_force_n_per_m3: [f64; 3],
    pub last_gas_step: Option<StepReport>,
}

impl CoupledSimulation {
    pub fn new(
        mut dem: Simulation,
        gas_config: GasConfig,
        drag: DragLaw,
        porosity_method: PorosityMethod,
        min_porosity: f64,
        dem_steps_per_gas_step: u64,
    ) -> Result<Self, String> {
        if dem_steps_per_gas_step == 0 {
            return Err("dem_steps_per_gas_step: expected at least 1".into());
        }
        let mut gas = GasSolver::new(gas_config)?;
        let grid = gas.config.grid.clone();
        gas.state.porosity = porosity(
            &grid,
            porosity_method,
            &dem.particles.position_m,
            &dem.particles.radius_m,
            min_porosity,
        );
        let mut fluid = FluidForces::new(grid, drag, gas.config.density_kg_per_m3, gas.config.viscosity_pa_s);
        fluid.freeze(&gas.state.velocity_m_per_s, &gas.state.pressure_pa, &gas.state.porosity);
        dem.fluid = Some(fluid);
        Ok(CoupledSimulation {
            dem,
            gas,
            porosity_method,
            min_porosity,
            dem_steps_per_gas_step,
            gas_body_force_n_per_m3: [0.0; 3],
            last_gas_step: None,
        })
    }

    /// One gas step: the DEM sub-cycles, then the gas advances by their total time.
    pub fn advance(&mut self) -> Result<StepReport, NumericalError> {
        self.dem.run_steps(self.dem_steps_per_gas_step)?;
        let grid = self.gas.config.grid.clone();
        let old_porosity = std::mem::replace(
            &mut self.gas.state.porosity,
            porosity(
                &grid,
                self.porosity_method,
                &self.dem.particles.position_m,
                &self.dem.particles.radius_m,
                self.min_porosity,
            ),
        );
        let fluid = self
            .dem
            .fluid
            .as_mut()
            .expect("a coupled simulation keeps its fluid forces");
        let mut source = fluid.mean_reaction();
        for (a, s) in source.iter_mut().enumerate() {
            s.iter_mut().for_each(|v| *v += self.gas_body_force_n_per_m3[a]);
        }
        let dt_gas = self.dem.dt_s * self.dem_steps_per_gas_step as f64;
        let report = self.gas.step(dt_gas, &source, &Default::default(), &old_porosity);
        fluid.freeze(
            &self.gas.state.velocity_m_per_s,
            &self.gas.state.pressure_pa,
            &self.gas.state.porosity,
        );
        self.last_gas_step = Some(report);
        Ok(report)
    }
}
