//! The gas coupled to the particles. The DEM sub-cycles `dem_steps_per_gas_step` steps under a frozen gas field
//! (seed 001 Fig. 6.6: gas time step = n × particle time step), then the gas takes one step with the porosity of
//! the particles at that moment and, as its momentum source, the particles' drag reaction averaged over the
//! sub-steps (CHOICE: averaged rather than the last sub-step's, so the momentum the gas receives over a gas step is
//! exactly what the particles lost to drag over it).
//!
//! After the momentum and pressure solve, each transported scalar (none unless declared with
//! [`GasCoupling::declare_scalar`]) takes the same step with the new mass flows and porosity and its particle
//! exchange averaged over the same sub-steps ([`super::transported_scalar`]).
//!
//! A [`GasCoupling`] lives inside a [`crate::engine::Simulation`], which calls [`GasCoupling::advance`] after every
//! `dem_steps_per_gas_step`-th step; its state ([`GasSnapshot`]) is part of the checkpoint.

use super::coupling::{PorosityMethod, porosity};
use super::exchange_accumulator::ExchangeAccumulator;
use super::field::{FieldLocation, GasField, GasFieldView};
use super::fluid_forces::{DragCoupling, DragVelocities, FluidForces};
use super::grid::{Boundary, side};
use super::held_drag::HeldDragSnapshot;
use super::simple::{GasConfig, GasSolver};
use super::transported_scalar::{GasScalarSpec, TransportedScalar};
use crate::engine::Vec3;
use crate::engine::models::drag::DragLaw;

/// How many times a failed gas step is retried with halved under-relaxation.
pub const GAS_STEP_RETRIES: u32 = 2;

/// A gas step that ends with a mass imbalance above this many times its tolerance has failed.
pub const RETRY_IMBALANCE_FACTOR: f64 = 100.0;

/// How the last gas step went (kept in the checkpoint so a resumed run reports the same series).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GasStepStats {
    pub outer_iterations: u64,
    pub linear_iterations: u64,
    pub mass_imbalance: f64,
    pub converged: bool,
}

/// Everything of the gas a checkpoint needs: the solver state, and the reaction accumulated by the DEM sub-steps
/// since the last gas step (the frozen field itself is the solver state, frozen again on restore).
#[derive(Debug, Clone, PartialEq)]
pub struct GasSnapshot {
    pub pressure_pa: Vec<f64>,
    pub velocity_m_per_s: [Vec<f64>; 3],
    pub porosity: Vec<f64>,
    pub time_s: f64,
    pub reaction_n_per_m3: [Vec<f64>; 3],
    pub beta_sum: [Vec<f64>; 3],
    pub beta_velocity_sum: [Vec<f64>; 3],
    pub reaction_steps: u32,
    pub last: GasStepStats,
    /// Under drag held over the gas step, within a gas step: what evaluates the held values again
    /// (`held_drag.rs`); `None` otherwise.
    pub held_drag: Option<HeldDragSnapshot>,
    /// The transported scalars in their declaration order; empty when none is declared (the checkpoint then has
    /// nothing more to hold).
    pub scalars: Vec<GasScalarSnapshot>,
    /// The drying ledger of a gas with drying (its vapour is among `scalars`).
    pub drying: Option<crate::engine::drying::DryingLedger>,
}

/// A transported scalar's checkpointed state: its field and the exchange accumulated since the last gas step.
#[derive(Debug, Clone, PartialEq)]
pub struct GasScalarSnapshot {
    /// The spec's name (`temperature_k`): a restore matches scalars by it.
    pub name: String,
    pub unit: String,
    /// φ at the cell centres.
    pub value: Vec<f64>,
    pub exchange: ExchangeAccumulator,
}

impl GasSnapshot {
    /// Every field of the state with its name and unit: those of [`GasField::ALL`], then the transported scalars.
    pub fn fields(&self) -> impl Iterator<Item = GasFieldView<'_>> {
        GasField::ALL
            .into_iter()
            .map(|f| f.view(&self.pressure_pa, &self.velocity_m_per_s, &self.porosity))
            .chain(self.scalars.iter().map(|s| GasFieldView {
                name: &s.name,
                unit: &s.unit,
                location: FieldLocation::Cells,
                values: &s.value,
            }))
    }
}

/// Names a transported scalar of a [`GasCoupling`] (its place in declaration order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GasScalarId(usize);

impl GasScalarId {
    pub(crate) fn index(self) -> usize {
        self.0
    }
}

pub struct GasCoupling {
    pub solver: GasSolver,
    pub fluid: FluidForces,
    pub porosity_method: PorosityMethod,
    /// Porosity is not allowed below this (a cell over-filled by the split would otherwise reach 0).
    pub min_porosity: f64,
    pub dem_steps_per_gas_step: u64,
    pub drag_coupling: DragCoupling,
    /// A uniform force per unit volume on the gas besides drag, N/m³ (e.g. in a periodic box, the mean pressure
    /// gradient that carries the particles' weight, without which the mixture would accelerate for ever).
    pub gas_body_force_n_per_m3: [f64; 3],
    pub last: GasStepStats,
    /// Wall time spent in the gas's linear solvers (not checkpointed; for profiles), s.
    pub linear_solve_s: f64,
    /// The transported scalars, in declaration order.
    pub(crate) scalars: Vec<TransportedScalar>,
    /// The gas's energy and its convection with the particles (`heat.rs`); `None`: no temperature.
    pub heat: Option<super::heat::GasHeat>,
    /// Evaporation and the vapour it carries (`engine::drying`); `None`: nothing evaporates.
    pub drying: Option<crate::engine::drying::GasDrying>,
    /// With drying, the porosity before and the mass flows of the gas step just taken, for the drying step that
    /// follows it (workspace).
    pub(crate) step_flows: Option<(Vec<f64>, [Vec<f64>; 3])>,
    /// The temperature's budget (K·kg) over the gas steps since the simulation last took it for its energy
    /// ledger (workspace: taken after every gas step).
    pub(crate) heat_budget: super::transported_scalar::ScalarBudget,
}

impl GasCoupling {
    /// The gas at rest (or at its boundary velocities) around particles at `positions_m`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gas_config: GasConfig,
        drag: DragLaw,
        drag_velocities: DragVelocities,
        porosity_method: PorosityMethod,
        min_porosity: f64,
        dem_steps_per_gas_step: u64,
        positions_m: &[Vec3],
        radii_m: &[f64],
    ) -> Result<Self, String> {
        if dem_steps_per_gas_step == 0 {
            return Err("dem_steps_per_gas_step: expected at least 1".into());
        }
        let mut solver = GasSolver::new(gas_config)?;
        let grid = solver.config.grid.clone();
        solver.state.porosity = porosity(&grid, porosity_method, positions_m, radii_m, min_porosity);
        let mut fluid = FluidForces::new(
            grid,
            drag,
            solver.config.density_kg_per_m3,
            solver.config.viscosity_pa_s,
        );
        fluid.drag_velocities = drag_velocities;
        fluid.blocked.clone_from(&solver.config.blocked);
        fluid.freeze(
            &solver.interstitial_velocity_m_per_s(),
            &solver.state.pressure_pa,
            &solver.state.porosity,
        );
        Ok(GasCoupling {
            solver,
            fluid,
            porosity_method,
            min_porosity,
            dem_steps_per_gas_step,
            drag_coupling: DragCoupling::Explicit,
            gas_body_force_n_per_m3: [0.0; 3],
            last: GasStepStats::default(),
            linear_solve_s: 0.0,
            scalars: Vec::new(),
            heat: None,
            drying: None,
            step_flows: None,
            heat_budget: Default::default(),
        })
    }

    /// Adds a scalar carried by the gas from now on, at its initial value everywhere. Names must be unique.
    pub fn declare_scalar(&mut self, spec: GasScalarSpec) -> Result<GasScalarId, String> {
        if self.scalars.iter().any(|s| s.spec.name == spec.name) {
            return Err(format!("transported scalar {}: declared twice", spec.name));
        }
        self.scalars.push(TransportedScalar::new(spec, &self.solver)?);
        Ok(GasScalarId(self.scalars.len() - 1))
    }

    /// The transported scalars, in declaration order.
    pub fn scalars(&self) -> &[TransportedScalar] {
        &self.scalars
    }

    pub fn scalar(&self, id: GasScalarId) -> &TransportedScalar {
        &self.scalars[id.0]
    }

    /// The scalar `id`, to set its field or add to its exchange accumulator.
    pub fn scalar_mut(&mut self, id: GasScalarId) -> &mut TransportedScalar {
        &mut self.scalars[id.0]
    }

    /// The scalar named `name`.
    pub fn scalar_named(&self, name: &str) -> Option<GasScalarId> {
        self.scalars.iter().position(|s| s.spec.name == name).map(GasScalarId)
    }

    /// One gas step of `dt_s` after the DEM sub-steps: new porosity from `positions_m`, the mean drag reaction as
    /// the momentum source, then the new field is frozen for the next sub-steps. Returns an error naming the
    /// quantity if the gas field stops being finite.
    pub fn advance(&mut self, dt_s: f64, positions_m: &[Vec3], radii_m: &[f64]) -> Result<GasStepStats, String> {
        let grid = &self.solver.config.grid;
        let new_porosity = porosity(grid, self.porosity_method, positions_m, radii_m, self.min_porosity);
        let old_porosity = std::mem::replace(&mut self.solver.state.porosity, new_porosity);
        self.fluid.settle_held_reaction();
        let (mut source, sink) = match self.drag_coupling {
            DragCoupling::Explicit => (self.fluid.mean_reaction(), Default::default()),
            DragCoupling::SemiImplicit => {
                let (beta, beta_v) = self.fluid.mean_exchange();
                (beta_v, beta)
            }
        };
        for (a, s) in source.iter_mut().enumerate() {
            s.iter_mut().for_each(|v| *v += self.gas_body_force_n_per_m3[a]);
        }
        // A step that fails (its field stops being finite, or it ends with a mass imbalance above
        // RETRY_IMBALANCE_FACTOR × the tolerance) is taken again from the same start with halved under-relaxation
        // and twice the outer iterations, up to GAS_STEP_RETRIES times (the same inputs give the same retries:
        // restarts stay exact). A step that merely stops short of a tight tolerance is kept. Iteration counts add
        // up over the attempts.
        let start = (
            self.solver.state.velocity_m_per_s.clone(),
            self.solver.state.pressure_pa.clone(),
            self.solver.state.time_s,
        );
        let configured = self.solver.config.clone();
        let (mut outer_iterations, mut linear_iterations) = (0, 0);
        let mut report = None;
        for attempt in 0..=GAS_STEP_RETRIES {
            if attempt > 0 {
                let damping = 0.5f64.powi(attempt as i32);
                let config = &mut self.solver.config;
                config.relax_velocity = configured.relax_velocity * damping;
                config.relax_pressure = configured.relax_pressure * damping;
                config.max_outer_iterations = configured.max_outer_iterations << attempt;
                let state = &mut self.solver.state;
                state.velocity_m_per_s.clone_from(&start.0);
                state.pressure_pa.clone_from(&start.1);
                state.time_s = start.2;
                tracing::debug!(
                    time_s = start.2,
                    attempt,
                    "gas step did not converge; retrying with under-relaxation x{damping}"
                );
            }
            let r = self.solver.step(dt_s, &source, &sink, &old_porosity);
            self.linear_solve_s += r.linear_solve_s;
            outer_iterations += r.outer_iterations as u64;
            linear_iterations += (r.momentum.iterations + r.pressure.iterations) as u64;
            report = Some(r);
            let failed = self.non_finite().is_some()
                || (!r.converged && r.mass_imbalance > RETRY_IMBALANCE_FACTOR * configured.mass_tolerance);
            if !failed {
                break;
            }
        }
        self.solver.config = configured;
        let report = report.expect("at least one attempt");
        if let Some(what) = self.non_finite() {
            return Err(what);
        }
        if !self.scalars.is_empty() {
            let mass_flow = self.solver.mass_flow_kg_per_s();
            let temperature = self.heat.map(|h| h.temperature.index());
            for (k, scalar) in self.scalars.iter_mut().enumerate() {
                if scalar.spec.exchange == super::transported_scalar::ScalarExchange::Evaporation {
                    // Stepped by the drying step, with the particles.
                    continue;
                }
                let t = std::time::Instant::now();
                let (r, budget) = scalar.step(&self.solver, &old_porosity, &mass_flow, dt_s)?;
                self.linear_solve_s += t.elapsed().as_secs_f64();
                linear_iterations += r.iterations as u64;
                if temperature == Some(k) {
                    self.heat_budget.add(budget);
                }
            }
            if self.drying.is_some() {
                self.step_flows = Some((old_porosity, mass_flow));
            }
        }
        let state = &self.solver.state;
        self.fluid.freeze(
            &self.solver.interstitial_velocity_m_per_s(),
            &state.pressure_pa,
            &state.porosity,
        );
        self.last = GasStepStats {
            outer_iterations,
            linear_iterations,
            mass_imbalance: report.mass_imbalance,
            converged: report.converged,
        };
        Ok(self.last)
    }

    /// Names the first non-finite field of the gas solver's state, if any.
    fn non_finite(&self) -> Option<String> {
        self.solver.state.fields().find_map(|field| {
            let k = field.values.iter().position(|v| !v.is_finite())?;
            let at = match field.location {
                FieldLocation::Cells => "cell",
                FieldLocation::Faces { .. } => "face",
            };
            Some(format!("gas {} of {at} {k} is not finite", field.name))
        })
    }

    pub fn snapshot(&self) -> GasSnapshot {
        let s = &self.solver.state;
        GasSnapshot {
            pressure_pa: s.pressure_pa.clone(),
            velocity_m_per_s: s.velocity_m_per_s.clone(),
            porosity: s.porosity.clone(),
            time_s: s.time_s,
            reaction_n_per_m3: std::array::from_fn(|a| self.fluid.momentum_exchange[a].transfer_sum.clone()),
            beta_sum: std::array::from_fn(|a| self.fluid.momentum_exchange[a].coefficient_sum.clone()),
            beta_velocity_sum: std::array::from_fn(|a| self.fluid.momentum_exchange[a].coefficient_value_sum.clone()),
            reaction_steps: self.fluid.steps(),
            last: self.last,
            held_drag: self.fluid.held_snapshot(),
            scalars: self
                .scalars
                .iter()
                .map(|s| GasScalarSnapshot {
                    name: s.spec.name.to_string(),
                    unit: s.spec.unit.to_string(),
                    value: s.value.clone(),
                    exchange: s.exchange.clone(),
                })
                .collect(),
            drying: self.drying.as_ref().map(|d| d.ledger),
        }
    }

    /// Puts a checkpointed gas state back (the grid must match: checked by the checkpoint reader's shapes and
    /// here against the solver's; the transported scalars must be those declared, by name and in order). `radii_m`
    /// are the particles' (held drag is evaluated again from the checkpoint's positions and velocities).
    pub fn restore(&mut self, snap: &GasSnapshot, radii_m: &[f64]) -> Result<(), String> {
        let grid = &self.solver.config.grid;
        let declared: Vec<&str> = self.scalars.iter().map(|s| s.spec.name).collect();
        let stored: Vec<&str> = snap.scalars.iter().map(|s| s.name.as_str()).collect();
        if declared != stored {
            return Err(format!(
                "the checkpoint's gas carries the scalars {stored:?}, the scenario's {declared:?}"
            ));
        }
        for field in snap.fields() {
            let expected = field.location.len(grid);
            if field.values.len() != expected {
                return Err(format!(
                    "the checkpoint's gas {} has {} values, the scenario's grid {expected}",
                    field.name,
                    field.values.len()
                ));
            }
        }
        for a in 0..3 {
            let n = grid.faces(a);
            if snap.reaction_n_per_m3[a].len() != n
                || snap.beta_sum[a].len() != n
                || snap.beta_velocity_sum[a].len() != n
            {
                return Err(format!(
                    "the checkpoint's gas drag sums have {} faces along axis {a}, the scenario's grid {n}",
                    snap.reaction_n_per_m3[a].len(),
                ));
            }
        }
        for (scalar, stored) in self.scalars.iter_mut().zip(&snap.scalars) {
            if stored.unit != scalar.spec.unit {
                return Err(format!(
                    "the checkpoint's gas scalar {} is in {}, the scenario's in {}",
                    stored.name, stored.unit, scalar.spec.unit
                ));
            }
            let e = &stored.exchange;
            scalar
                .exchange
                .restore(&e.coefficient_sum, &e.coefficient_value_sum, &e.transfer_sum, e.steps)
                .map_err(|err| format!("the checkpoint's gas scalar {}: {err}", stored.name))?;
            scalar.value.clone_from(&stored.value);
        }
        let s = &mut self.solver.state;
        s.pressure_pa.clone_from(&snap.pressure_pa);
        s.velocity_m_per_s.clone_from(&snap.velocity_m_per_s);
        s.porosity.clone_from(&snap.porosity);
        s.time_s = snap.time_s;
        let u = self.solver.interstitial_velocity_m_per_s();
        let s = &self.solver.state;
        self.fluid.freeze(&u, &s.pressure_pa, &s.porosity);
        for (a, exchange) in self.fluid.momentum_exchange.iter_mut().enumerate() {
            exchange.restore(
                &snap.beta_sum[a],
                &snap.beta_velocity_sum[a],
                &snap.reaction_n_per_m3[a],
                snap.reaction_steps,
            )?;
        }
        match (self.fluid.drag_update, &snap.held_drag) {
            (super::held_drag::DragUpdate::EveryGasStep, Some(held)) => self.fluid.restore_held(held, radii_m)?,
            (super::held_drag::DragUpdate::EveryGasStep, None) if snap.reaction_steps > 0 => {
                return Err(format!(
                    "the checkpoint lies {} DEM steps into a gas step but holds no held drag; the scenario holds \
                     drag over the gas step (gas.drag_update: every_gas_step): was it written with every_dem_step?",
                    snap.reaction_steps
                ));
            }
            (super::held_drag::DragUpdate::EveryDemStep, Some(_)) => {
                return Err(
                    "the checkpoint holds drag held over a gas step; the scenario evaluates it every DEM \
                            step (gas.drag_update: every_dem_step)"
                        .into(),
                );
            }
            _ => {}
        }
        match (self.drying.as_mut(), &snap.drying) {
            (Some(drying), Some(ledger)) => drying.ledger = *ledger,
            (None, None) => {}
            (Some(_), None) => return Err("the scenario dries but the checkpoint's gas holds no drying ledger".into()),
            (None, Some(_)) => {
                return Err("the checkpoint's gas holds a drying ledger but the scenario does not dry".into());
            }
        }
        self.last = snap.last;
        Ok(())
    }

    /// The axis and side of the first inlet (the bed's vertical and its bottom): a side with uniform inflow, or
    /// else the side of the first jet (seed 001's distributor: jets through a wall).
    pub fn inlet_side(&self) -> Option<(usize, bool)> {
        let grid = &self.solver.config.grid;
        (0..grid.axes())
            .flat_map(|a| [(a, false), (a, true)])
            .find(|&(a, high)| matches!(grid.boundary[side(a, high)], Boundary::Inlet { .. }))
            .or_else(|| {
                self.solver.config.inlet_faces.first().map(|f| {
                    let along = super::simple::face_index(grid, f.axis, f.face)[f.axis];
                    (f.axis, along == grid.n[f.axis])
                })
            })
    }

    /// The superficial velocity U of the inlet side at full inflow (no ramp or level factor): the inflow through
    /// its faces, jets at their own velocity, over the side's area (seed 001 eq 6.41, U_s = Σ A_jet V_jet / A_b), m/s.
    pub fn superficial_inflow_m_per_s(&self) -> Option<f64> {
        let (axis, high) = self.inlet_side()?;
        let grid = &self.solver.config.grid;
        let uniform = match grid.boundary[side(axis, high)] {
            Boundary::Inlet { velocity_m_per_s } => velocity_m_per_s[axis].abs(),
            _ => 0.0,
        };
        let dims = grid.face_dims(axis);
        let along = if high { grid.n[axis] } else { 0 };
        let mut faces = vec![uniform; grid.faces(axis)];
        for f in self.solver.config.inlet_faces.iter().filter(|f| f.axis == axis) {
            faces[f.face] = f.velocity_m_per_s.abs();
        }
        let (mut sum, mut count) = (0.0, 0usize);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let idx = [i, j, k];
                    if idx[axis] == along {
                        sum += faces[grid.face(axis, idx)];
                        count += 1;
                    }
                }
            }
        }
        (count > 0).then(|| sum / count as f64)
    }

    /// Mean pressure of the layer of cells `layer` along `axis`, Pa.
    pub fn layer_pressure_pa(&self, axis: usize, layer: usize) -> f64 {
        let grid = &self.solver.config.grid;
        let p = &self.solver.state.pressure_pa;
        let (mut sum, mut count) = (0.0, 0usize);
        for k in 0..grid.n[2] {
            for j in 0..grid.n[1] {
                for i in 0..grid.n[0] {
                    let idx = [i, j, k];
                    let blocked = &self.solver.config.blocked;
                    if idx[axis] == layer && (blocked.is_empty() || !blocked[grid.cell(idx)]) {
                        sum += p[grid.cell(idx)];
                        count += 1;
                    }
                }
            }
        }
        sum / count.max(1) as f64
    }

    /// p(inlet) − p(h_m): the pressure drop from the inlet face to height `h_m` above it, Pa; `None` without an
    /// inlet. Pressures are layer means at cell centres, linear in between; below the first centre the line through
    /// the first two is extended to the inlet face (the bed starts there), and above the last centre the pressure
    /// is constant (the zero-gradient outlet).
    pub fn pressure_drop_to_pa(&self, h_m: f64) -> Option<f64> {
        let (axis, high) = self.inlet_side()?;
        let grid = &self.solver.config.grid;
        let n = grid.n[axis];
        let layer = |k: usize| self.layer_pressure_pa(axis, if high { n - 1 - k } else { k });
        let at = |s: f64| -> f64 {
            // s: position in layer-centre units (layer k's centre at s = k).
            if n == 1 {
                return layer(0);
            }
            let s = s.min((n - 1) as f64);
            let k = (s.floor().max(0.0) as usize).min(n - 2);
            let w = s - k as f64;
            (1.0 - w) * layer(k) + w * layer(k + 1)
        };
        let inlet = at(-0.5);
        Some(inlet - at(h_m / grid.h_m[axis] - 0.5))
    }

    /// Seed 001's pressure drop (notes §4.1): the pressure at the first computational node, the centre of the layer
    /// of cells at the inlet, minus that of the layer at the outlet, Pa; `None` without an inlet. Unlike
    /// [`Self::column_pressure_drop_pa`] it leaves out the inlet half-cell and the particles in it.
    pub fn first_node_pressure_drop_pa(&self) -> Option<f64> {
        let (axis, high) = self.inlet_side()?;
        let n = self.solver.config.grid.n[axis];
        let (first, last) = if high { (n - 1, 0) } else { (0, n - 1) };
        Some(self.layer_pressure_pa(axis, first) - self.layer_pressure_pa(axis, last))
    }

    /// The area of the inlet side (all its faces, blocked or not), m²; `None` without an inlet.
    pub fn inlet_side_area_m2(&self) -> Option<f64> {
        let (axis, _) = self.inlet_side()?;
        let grid = &self.solver.config.grid;
        Some(grid.face_area_m2(axis) * (grid.cells() / grid.n[axis]) as f64)
    }

    /// Where the first node lies: the axis normal to the inlet side, the node's coordinate along it, m, and whether
    /// the inlet is the high side (then "above the node" means a smaller coordinate); `None` without an inlet.
    pub fn first_node_plane(&self) -> Option<(usize, f64, bool)> {
        let (axis, high) = self.inlet_side()?;
        let grid = &self.solver.config.grid;
        let h = grid.h_m[axis];
        let lo = grid.origin_m[axis];
        let node = if high {
            lo + (grid.n[axis] as f64 - 0.5) * h
        } else {
            lo + 0.5 * h
        };
        Some((axis, node, high))
    }

    /// Pressure drop across the whole column, from the layer at the inlet to the layer at the far end, Pa.
    pub fn column_pressure_drop_pa(&self) -> Option<f64> {
        let (axis, _) = self.inlet_side()?;
        let grid = &self.solver.config.grid;
        self.pressure_drop_to_pa(grid.n[axis] as f64 * grid.h_m[axis])
    }
}
