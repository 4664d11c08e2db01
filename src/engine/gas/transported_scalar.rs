//! Scalars carried by the gas (its temperature, a vapour concentration), each declared by name and unit with its
//! diffusivity and the values the boundaries give it ([`GasScalarSpec`]), and held as a field with its particle
//! exchange accumulator ([`TransportedScalar`]). A gas step moves each one with the step's new mass flows and
//! porosity ([`TransportedScalar::step`], through [`super::scalar::ScalarEquation`]):
//! - gas entering through an inlet side carries the inlet value, through a jet the jet's value;
//! - gas leaving through an outlet carries the cell's value (zero gradient), and so does gas flowing back in;
//! - a wall passes no flux, or holds the scalar at a value when the spec says so;
//! - blocked cells are outside the gas: nothing crosses their faces, they keep their value (CHOICE: adiabatic;
//!   conduction through a kiln wall is a model of its own);
//! - the particles exchange K (φ_p − φ) per unit volume, implicitly from the means of the accumulator's coefficients
//!   ([`ScalarExchange::Implicit`]), or explicitly as the mean of what the particles actually gave under the frozen
//!   field ([`ScalarExchange::Explicit`]: the gas receives exactly what the particles lost, so the two together
//!   conserve the scalar to rounding).
//!
//! What fills the accumulator (gas–particle convection, evaporation) is the coupling's (`super::heat`).

use super::exchange_accumulator::ExchangeAccumulator;
use super::grid::{Boundary, side};
use super::linsolve::SolveReport;
use super::scalar::ScalarEquation;
use super::simple::{GasSolver, face_index};

/// The relative residual a scalar's step is solved to at most, against the step's change (`ScalarEquation::step`;
/// tighter when `gas.solver.linear_tolerance` is): the energy ledger closes only as well as the gas temperature's
/// solve, and solved to the pressure–velocity solve's 1e-8 of the temperature itself a heated drum drifted 1e-7 of
/// its energy in 0.06 s, always the same way (tests/drying.rs). The scalar solves are a small part of a gas step.
pub const SCALAR_SOLVE_TOLERANCE: f64 = 1e-12;

/// How the gas takes the particles' exchange.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarExchange {
    /// Σk (φ_p − φ) with φ at the end of the gas step (unconditionally stable; the gas's and the particles' shares
    /// differ by how much φ moved over the step).
    Implicit,
    /// The mean transfer the particles computed under the frozen field, as an explicit source (exactly the
    /// opposite of what the particles received; stable while the gas step is short against ε ρ / Σk).
    Explicit,
    /// Evaporation: the drying step (`engine::drying`) fills the exchange at the gas step, implicitly in the
    /// scalar and the particles' temperatures, and steps the scalar itself, in the conservative form.
    Evaporation,
}

/// A scalar's condition on a wall side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScalarWall {
    /// No flux through the wall.
    ZeroFlux,
    /// The scalar held at `value` on the wall (diffusion over the half cell next to it).
    Fixed { value: f64 },
}

/// A transported scalar's declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct GasScalarSpec {
    /// The field's name with its unit suffix (`temperature_k`): views, errors and checkpoints use it.
    pub name: &'static str,
    /// The unit of φ (`K`, `kg/kg`).
    pub unit: &'static str,
    /// ρ × diffusivity, kg/(m·s) (for heat: the gas conductivity over its specific heat).
    pub diffusion_kg_per_m_s: f64,
    /// φ everywhere at the start.
    pub initial_value: f64,
    /// φ of the gas entering through inlet sides, and through jets without a value of their own.
    pub inlet_value: f64,
    /// φ of the gas entering through each jet, in the order of `GasConfig::inlet_faces`; empty: every jet at
    /// `inlet_value`.
    pub jet_values: Vec<f64>,
    /// The condition on each side (`grid::side` order) that is a wall; must be `ZeroFlux` on the other sides.
    pub walls: [ScalarWall; 6],
    pub exchange: ScalarExchange,
    /// The value the faces of blocked cells hold (a kiln's heated drum), diffusing into the gas beside them;
    /// `None`: they pass nothing.
    pub blocked_value: Option<f64>,
    /// Walls held at a value (and `blocked_value`) act from this gas time on, s; before it they pass nothing (a
    /// kiln's wall heats once its bed has settled).
    pub fixed_from_s: f64,
}

impl GasScalarSpec {
    /// Checks the declaration against the gas it is carried by.
    pub fn check(&self, solver: &GasSolver) -> Result<(), String> {
        let name = self.name;
        if name.is_empty() {
            return Err("transported scalar: expected a name".into());
        }
        if !(self.diffusion_kg_per_m_s.is_finite() && self.diffusion_kg_per_m_s >= 0.0) {
            return Err(format!(
                "transported scalar {name}: diffusion_kg_per_m_s: expected ≥ 0, got {}",
                self.diffusion_kg_per_m_s
            ));
        }
        let jets = solver.config.inlet_faces.len();
        if !self.jet_values.is_empty() && self.jet_values.len() != jets {
            return Err(format!(
                "transported scalar {name}: jet_values: expected one per jet ({jets}) or none, got {}",
                self.jet_values.len()
            ));
        }
        let values = [self.initial_value, self.inlet_value]
            .into_iter()
            .chain(self.jet_values.iter().copied());
        if let Some(v) = values.into_iter().find(|v| !v.is_finite()) {
            return Err(format!("transported scalar {name}: value {v} is not finite"));
        }
        let grid = &solver.config.grid;
        for (s, wall) in self.walls.iter().enumerate() {
            if let ScalarWall::Fixed { value } = wall {
                if !matches!(grid.boundary[s], Boundary::Wall { .. }) || (s >= 4 && grid.two_d()) {
                    return Err(format!(
                        "transported scalar {name}: side {s} holds a wall value but is not a wall of the grid"
                    ));
                }
                if !value.is_finite() {
                    return Err(format!("transported scalar {name}: wall value {value} is not finite"));
                }
            }
        }
        Ok(())
    }
}

/// A transported scalar's field and what the particles exchanged with it since the last gas step.
#[derive(Debug, Clone, PartialEq)]
pub struct TransportedScalar {
    pub spec: GasScalarSpec,
    /// φ at the cell centres, in `spec.unit`.
    pub value: Vec<f64>,
    /// Per cell: the exchange coefficient K per unit volume, kg/(m³·s), with the particle value φ_p it pulls
    /// towards; the gas step takes K (φ_p − φ) implicitly from the means over the sub-steps.
    pub exchange: ExchangeAccumulator,
}

impl TransportedScalar {
    /// The scalar at its initial value over `solver`'s grid, after checking the spec.
    pub fn new(spec: GasScalarSpec, solver: &GasSolver) -> Result<Self, String> {
        spec.check(solver)?;
        let cells = solver.config.grid.cells();
        Ok(TransportedScalar {
            value: vec![spec.initial_value; cells],
            exchange: ExchangeAccumulator::new(cells),
            spec,
        })
    }

    /// φ on each boundary face where the boundary gives it (inlets, jets, walls held at a value); `None` for zero
    /// gradient (outlets, walls without flux, faces of blocked cells).
    pub fn boundary_values(&self, solver: &GasSolver) -> [Vec<Option<f64>>; 3] {
        let grid = &solver.config.grid;
        let mut values: [Vec<Option<f64>>; 3] = std::array::from_fn(|a| vec![None; grid.faces(a)]);
        for (a, values) in values.iter_mut().enumerate().take(grid.axes()) {
            if grid.periodic(a) {
                continue;
            }
            for (f, value) in values.iter_mut().enumerate() {
                let idx = face_index(grid, a, f);
                let along = idx[a];
                if (along != 0 && along != grid.n[a])
                    || super::simple::face_touches_blocked(grid, &solver.config.blocked, a, idx)
                {
                    continue;
                }
                let s = side(a, along == grid.n[a]);
                *value = match (grid.boundary[s], self.spec.walls[s]) {
                    (Boundary::Inlet { .. }, _) => Some(self.spec.inlet_value),
                    (Boundary::Wall { .. }, ScalarWall::Fixed { value }) if self.fixed_active(solver) => Some(value),
                    _ => None,
                };
            }
        }
        for (k, jet) in solver.config.inlet_faces.iter().enumerate() {
            let idx = face_index(grid, jet.axis, jet.face);
            if !super::simple::face_touches_blocked(grid, &solver.config.blocked, jet.axis, idx) {
                values[jet.axis][jet.face] =
                    Some(self.spec.jet_values.get(k).copied().unwrap_or(self.spec.inlet_value));
            }
        }
        values
    }

    /// Whether the walls held at a value act at the solver's current time.
    fn fixed_active(&self, solver: &GasSolver) -> bool {
        solver.state.time_s >= self.spec.fixed_from_s
    }

    /// The discretised equation of a step of this scalar over the gas step `solver` has just taken from porosity
    /// `old_porosity`, with the given exchange (per cell: K and K φ_p per unit volume, empty for none) and explicit
    /// source; `boundary_value` from [`Self::boundary_values`].
    #[allow(clippy::too_many_arguments)]
    pub fn equation<'a>(
        &'a self,
        solver: &'a GasSolver,
        old_porosity: &'a [f64],
        mass_flow_kg_per_s: &'a [Vec<f64>; 3],
        boundary_value: &'a [Vec<Option<f64>>; 3],
        exchange_coefficient: &'a [f64],
        exchange_coefficient_value: &'a [f64],
        source: &'a [f64],
        conservative: bool,
    ) -> ScalarEquation<'a> {
        let config = &solver.config;
        ScalarEquation {
            grid: &config.grid,
            convection: config.convection,
            density_kg_per_m3: config.density_kg_per_m3,
            diffusion_kg_per_m_s: self.spec.diffusion_kg_per_m_s,
            mass_flow_kg_per_s,
            porosity: &solver.state.porosity,
            old_porosity,
            boundary_value,
            blocked: &config.blocked,
            blocked_value: self.spec.blocked_value.filter(|_| self.fixed_active(solver)),
            source,
            exchange_coefficient,
            exchange_coefficient_value,
            conservative,
        }
    }

    /// φ after one step of `equation` from the present value, solved to relative residual `tolerance`, or an error
    /// naming the field when the solve fails or φ stops being finite (the field itself is not changed).
    pub fn solve(
        &self,
        equation: &ScalarEquation,
        dt_s: f64,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(Vec<f64>, SolveReport), String> {
        let mut phi = self.value.clone();
        let report = equation.step(&mut phi, dt_s, tolerance, max_iterations);
        let name = self.spec.name;
        if let Some(k) = phi.iter().position(|v| !v.is_finite()) {
            return Err(format!("gas scalar {name} of cell {k} is not finite"));
        }
        if !report.converged {
            return Err(format!(
                "gas scalar {name}: the linear solve stopped at relative residual {:e} after {} iterations",
                report.relative_residual, report.iterations
            ));
        }
        Ok((phi, report))
    }

    /// Advances φ over the gas step of `dt_s` that `solver` has just taken from porosity `old_porosity`, with the
    /// mean particle exchange of the accumulator (which is then cleared for the next sub-steps). Returns the
    /// linear solve's report and the step's budget, or an error naming the field when the solve fails or φ stops
    /// being finite.
    pub fn step(
        &mut self,
        solver: &GasSolver,
        old_porosity: &[f64],
        mass_flow_kg_per_s: &[Vec<f64>; 3],
        dt_s: f64,
    ) -> Result<(SolveReport, ScalarBudget), String> {
        let boundary_value = self.boundary_values(solver);
        let (coefficient, coefficient_value, source) = match self.spec.exchange {
            ScalarExchange::Implicit => (
                self.exchange.mean_coefficient(),
                self.exchange.mean_coefficient_value(),
                Vec::new(),
            ),
            ScalarExchange::Explicit => (Vec::new(), Vec::new(), self.exchange.mean_transfer()),
            ScalarExchange::Evaporation => {
                return Err(format!(
                    "gas scalar {}: stepped by the drying step, not with the other scalars",
                    self.spec.name
                ));
            }
        };
        let equation = self.equation(
            solver,
            old_porosity,
            mass_flow_kg_per_s,
            &boundary_value,
            &coefficient,
            &coefficient_value,
            &source,
            false,
        );
        let config = &solver.config;
        let tolerance = config.linear_tolerance.min(SCALAR_SOLVE_TOLERANCE);
        let (phi, report) = self.solve(&equation, dt_s, tolerance, config.max_linear_iterations)?;
        let flows = equation.boundary_flows(&phi);
        let budget = ScalarBudget {
            boundary_in: flows.in_per_s * dt_s,
            boundary_out: flows.out_per_s * dt_s,
            continuity: equation.continuity_flow(&phi, dt_s) * dt_s,
        };
        self.value = phi;
        self.exchange.clear();
        Ok((report, budget))
    }
}

/// What one step of a scalar's equation moved across its boundary and what Patankar's form added (its
/// `continuity_flow`), in (unit of φ)·kg: the energy ledger's gas terms divided by c_g for the temperature.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScalarBudget {
    pub boundary_in: f64,
    pub boundary_out: f64,
    pub continuity: f64,
}

impl ScalarBudget {
    /// Adds a later step's budget.
    pub fn add(&mut self, later: ScalarBudget) {
        self.boundary_in += later.boundary_in;
        self.boundary_out += later.boundary_out;
        self.continuity += later.continuity;
    }
}
