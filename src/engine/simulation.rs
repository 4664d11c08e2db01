//! `Simulation`: the configuration (immutable during a run, `config.rs`), the state, the workspace and the timers;
//! `step()` advances one DEM time step.
//!
//! A step is velocity Verlet: half kick with the forces of the previous step, drift, wall rotation, neighbour-list
//! refresh if needed, the gas's forces, the liquid inventory's events (`liquid.rs`), the pair pass (contact and
//! cohesion forces and the scalar channels, `pair_pass.rs`) with the second half kick fused in, then the numerical
//! checks (non-finite values, lost particles, excessive overlap), each reported as a [`NumericalError`] naming the
//! step and particle; the gas steps after every `dem_steps_per_gas_step`-th step.

mod measures;

use std::sync::Arc;
use std::time::{Duration, Instant};

use super::cohesion::CohesionEvents;
pub use super::config::SimConfig;
use super::contacts::AlignedHistory;
use super::gas::coupled::GasCoupling;
use super::geometry::turns;
use super::heat_ledger::HeatLedger;
use super::integrate::{InverseInertia, find_lost, kick_drift};
use super::liquid::{BridgeCache, step_liquid};
use super::models::cohesion_law::CohesionModel;
use super::neighbor::{Criteria, NeighborList};
use super::net_force::NetForceTally;
use super::pair_pass::{ForcePass, HalfKick, PairBuffers, add_wall_forces, compute_pair_forces};
use super::particle_order::{reorder_state, spatial_order};
use super::particles::Particles;
use super::range_plan::RangePlan;
use super::state::{RngState, SimState};
use super::team::Team;
use super::{NumericalError, Vec3};

/// Below this many particles the fluid forces are computed on the calling thread (a hand-over to the team costs a
/// few µs).
const PARALLEL_FLUID_FORCES_MIN_PARTICLES: usize = 1000;

/// Steps after which the parallel ranges are rebalanced from measured times even without a neighbour-list build.
const REBALANCE_EVERY_STEPS: u64 = 200;

/// Wall-clock time spent per stage.
#[derive(Debug, Clone, Copy, Default)]
pub struct StageTimers {
    pub neighbor: Duration,
    pub force: Duration,
    pub integrate: Duration,
    /// Gas steps (porosity, assembly, linear solves).
    pub gas: Duration,
    /// The gas's forces on the particles and their reaction (inside `force`).
    pub fluid_forces: Duration,
    /// The liquid inventory's events (inside `force`).
    pub liquid: Duration,
    /// Drying steps: evaporation and the vapour's solves (inside `gas`).
    pub drying: Duration,
}

/// The simulation's workspace: what it keeps between steps only to go fast, none of it state (a simulation restored
/// from a checkpoint rebuilds it): the neighbour lists, the standing bridges' constants, the parallel pass's buffers,
/// ranges and thread team, the inverse masses, and the fused-step bookkeeping.
struct Workspace {
    /// The force pass's list: every pair within the inner skin (`SimConfig::inner_skin_m`).
    list: NeighborList,
    /// The two-level scheme's outer list (pairs within `SimConfig::skin_m`), which `list` is refiltered from;
    /// empty with one level.
    candidates: NeighborList,
    /// Refilters of `list` from `candidates` in this process.
    refilters: u64,
    /// The standing bridges' constants per slot of `list` (kept by the liquid inventory, `liquid.rs`).
    bridges: BridgeCache,
    buffers: PairBuffers,
    inverse: InverseInertia,
    /// Particle ranges of the parallel force pass, rebalanced at every neighbour-list build.
    ranges: RangePlan,
    /// Set between two steps of one `run_steps` call when the force loop has already applied the next step's
    /// first half kick and drift: the largest squared displacement it found. Never set outside `run_steps`.
    pending_drift: Option<f64>,
    /// A bound on how far any particle has moved since the neighbour list was built: the sum over the drifts since
    /// of each drift's largest displacement, m.
    drift_bound_m: f64,
    /// The force and torque arrays are zero (the last force pass fused the next drift and consumed them).
    accumulators_zeroed: bool,
    /// Force passes since the particle ranges were last rebalanced.
    steps_since_rebalance: u64,
    /// Each wall's temperature at the current step (heat transfer; `None` while adiabatic).
    wall_temperature_k: Vec<Option<f64>>,
    /// The run's cohesion can never act: liquid bridges without a spray, and no liquid on any particle or in any
    /// bridge, so no bridge can ever form (the dry beds of a wet sweep). The steps then skip the liquid inventory
    /// and take the dry force pass: the same forces, since the cohesion kernels add exact zeros there, and the
    /// neighbour lists keep the cohesion's reach (`SimConfig::reach`), so the same bits.
    cohesion_inert: bool,
    /// Threads of the per-step parallel force pass, which also run the drift of an unfused step and the neighbour
    /// lists' work (shared with that work through the `Arc`).
    team: Arc<Team>,
}

/// One simulation: its configuration (fixed for the run), its state (everything a checkpoint holds, and nothing
/// else the next step depends on), its workspace, and what this process measured (timers and event counters).
pub struct Simulation {
    pub config: Arc<SimConfig>,

    // The state (`snapshot()` gives it in its checkpointed form).
    pub particles: Particles,
    pub step: u64,
    pub time_s: f64,
    pub dt_s: f64,
    pub wall_angle_rad: Vec<f64>,
    pub rng: RngState,
    /// The contact records (histories, cohesion states) aligned with the force pass's neighbour list: the state's
    /// contacts in the form the pass streams through (`SimState::contacts` is their keyed, checkpointed form).
    history: AlignedHistory,
    /// The gas, when the scenario has one. Its forces on the particles (under the frozen gas field) are
    /// evaluated once per step, at the new positions and half-step velocities, and loaded into the force arrays
    /// before the contact pass adds onto them, so the pass itself is unchanged and any thread count gives the same
    /// bits. The gas steps after every `dem_steps_per_gas_step`-th DEM step.
    pub gas: Option<Box<GasCoupling>>,
    /// The net force on the particles by mechanism, summed every step when asked for
    /// ([`Simulation::record_net_forces`]); a diagnostic that never feeds back into the motion.
    pub net_force: Option<NetForceTally>,
    /// The energy ledger of a run with heat transfer ([`Simulation::start_heat_ledger`], `engine::heat_ledger`); a
    /// diagnostic that never feeds back into the motion or the temperatures.
    pub heat_ledger: Option<HeatLedger>,

    // The workspace.
    /// What the engine keeps between steps only to go fast (rebuilt from the state on restore).
    work: Workspace,
    /// Cost shares of one thread's ranges, front to back (see [`RangePlan::shares_for`]); a tuning knob of the
    /// parallel pass that never changes a bit.
    pub range_block: Vec<f64>,

    // What this process measured.
    pub timers: StageTimers,
    /// Cohesion events (bridges formed and broken, well crossings) since the start of this process.
    pub cohesion_events: CohesionEvents,
    /// Liquid sprayed since the start of this process, m³ (the state keeps it per particle).
    pub sprayed_m3: f64,
}

impl Workspace {
    /// Empty lists and buffers, built at the first step.
    fn new(inverse: InverseInertia, threads: usize) -> Self {
        Workspace {
            list: NeighborList::default(),
            candidates: NeighborList::default(),
            refilters: 0,
            bridges: BridgeCache::default(),
            buffers: PairBuffers::default(),
            inverse,
            ranges: RangePlan::default(),
            pending_drift: None,
            drift_bound_m: 0.0,
            accumulators_zeroed: false,
            steps_since_rebalance: 0,
            wall_temperature_k: Vec::new(),
            cohesion_inert: false,
            team: Arc::new(Team::new(threads)),
        }
    }
}

impl Simulation {
    /// A new simulation at t = 0 with `particles` as placed; computes the initial contact forces.
    pub fn new(
        config: Arc<SimConfig>,
        particles: Particles,
        dt_s: f64,
        rng: RngState,
        threads: usize,
    ) -> Result<Self, NumericalError> {
        let n_walls = config.walls.len();
        let inverse = InverseInertia::new(&particles, config.rotation, config.heat.as_ref());
        let mut sim = Simulation {
            config,
            particles,
            step: 0,
            time_s: 0.0,
            dt_s,
            wall_angle_rad: vec![0.0; n_walls],
            rng,
            history: AlignedHistory::default(),
            work: Workspace::new(inverse, threads),
            range_block: RangePlan::BLOCK.to_vec(),
            cohesion_events: CohesionEvents::default(),
            sprayed_m3: 0.0,
            gas: None,
            net_force: None,
            heat_ledger: None,
            timers: StageTimers::default(),
        };
        sim.refresh_neighbors();
        sim.work.cohesion_inert = sim.cohesion_is_inert();
        // The first half kick needs F(0). With dt = 0 the tangential springs do not move (and nothing is sprayed).
        sim.step_liquid(0.0);
        let pass = sim.forces(0.0, None);
        sim.check_overlap(pass.worst_overlap)?;
        Ok(sim)
    }

    /// Resumes from a checkpointed state; the next `step()` continues exactly where the saved run was.
    pub fn restore(config: Arc<SimConfig>, state: SimState, threads: usize) -> Result<Self, NumericalError> {
        let inverse = InverseInertia::new(&state.particles, config.rotation, config.heat.as_ref());
        let mut sim = Simulation {
            config,
            particles: Particles::default(),
            step: 0,
            time_s: 0.0,
            dt_s: state.dt_s,
            wall_angle_rad: Vec::new(),
            rng: state.rng,
            history: AlignedHistory::default(),
            work: Workspace::new(inverse, threads),
            range_block: RangePlan::BLOCK.to_vec(),
            cohesion_events: CohesionEvents::default(),
            sprayed_m3: 0.0,
            gas: None,
            net_force: None,
            heat_ledger: None,
            timers: StageTimers::default(),
        };
        sim.load(state)?;
        Ok(sim)
    }

    /// Puts `state` (its gas aside, which is [`Self::restore_gas`]'s) in place of this simulation's state and
    /// rebuilds the workspace from it, keeping the thread team, the timers and the event counters: a restore, and
    /// the second half of a sort, so that a sorted run continues exactly as one resumed from its checkpoint would.
    fn load(&mut self, state: SimState) -> Result<(), NumericalError> {
        self.work.inverse = InverseInertia::new(&state.particles, self.config.rotation, self.config.heat.as_ref());
        self.particles = state.particles;
        self.step = state.step;
        self.time_s = state.time_s;
        self.dt_s = state.dt_s;
        self.wall_angle_rad = state.wall_angle_rad;
        self.rng = state.rng;
        self.net_force = state.net_force;
        self.heat_ledger = state.heat_ledger;
        self.work.bridges = BridgeCache::default();
        self.work.pending_drift = None;
        self.work.accumulators_zeroed = false;
        let team = Arc::clone(&self.work.team);
        self.build_lists(true, &team);
        let layout = self.config.history_layout();
        let (history, orphans) =
            AlignedHistory::from_store(&state.contacts, &self.work.list, layout, &mut self.particles.liquid_m3);
        if orphans > 0 {
            return Err(NumericalError::OrphanContacts { count: orphans });
        }
        self.history = history;
        self.work.cohesion_inert = self.cohesion_is_inert();
        self.rebalance();
        Ok(())
    }

    /// Whether the run's cohesion can never act from this state on (see `Workspace::cohesion_inert`): liquid
    /// bridges without a spray (nothing else adds liquid) and not a drop of liquid on the particles or in bridges.
    fn cohesion_is_inert(&self) -> bool {
        let Some(CohesionModel::LiquidBridge(b)) = self.config.cohesion.as_ref().map(|c| &c.model) else {
            return false;
        };
        let dry = |v: &[f64]| v.iter().all(|&x| x == 0.0);
        b.spray.is_none()
            && dry(&self.particles.liquid_m3)
            && dry(&self.history.pair.cohesion.bridge_volume_m3)
            && dry(&self.history.wall.cohesion.bridge_volume_m3)
    }

    /// Sorts the particles by place (`engine::particle_order`, `neighbor.sort_every_steps`): the state is taken as
    /// a checkpoint would take it, put in the new order, and loaded back as a restore would load it.
    fn sort_particles(&mut self) -> Result<(), NumericalError> {
        let t = Instant::now();
        let mut state = self.snapshot();
        let order = spatial_order(&state.particles.position_m, 2.0 * self.particles.max_radius_m());
        reorder_state(&mut state, &order);
        let gas = state.gas.take();
        self.load(state)?;
        if let (Some(coupling), Some(snap)) = (self.gas.as_mut(), gas) {
            coupling
                .restore(&snap, &self.particles.radius_m)
                .expect("the gas takes back its own snapshot, its particles reordered");
        }
        self.timers.neighbor += t.elapsed();
        Ok(())
    }

    /// The complete state, for checkpoints and comparisons.
    pub fn snapshot(&self) -> SimState {
        SimState {
            step: self.step,
            time_s: self.time_s,
            dt_s: self.dt_s,
            particles: self.particles.clone(),
            wall_angle_rad: self.wall_angle_rad.clone(),
            contacts: self.history.to_store(&self.work.list),
            rng: self.rng,
            gas: self.gas.as_ref().map(|g| g.snapshot()),
            net_force: self.net_force.clone(),
            heat_ledger: self.heat_ledger,
        }
    }

    pub fn threads(&self) -> usize {
        self.work.team.size()
    }

    /// This invocation's wall time per engine stage, seconds, by name (what a job's `result.json` and a
    /// simulation's `summary.json` report).
    pub fn stage_timings(&self) -> Vec<(String, f64)> {
        let gas_solve_s = self.gas.as_ref().map_or(0.0, |g| g.linear_solve_s);
        vec![
            ("dem_neighbor".into(), self.timers.neighbor.as_secs_f64()),
            (
                "dem_contact_forces".into(),
                (self.timers.force - self.timers.fluid_forces - self.timers.liquid).as_secs_f64(),
            ),
            ("dem_liquid".into(), self.timers.liquid.as_secs_f64()),
            (
                "fluid_forces_on_particles".into(),
                self.timers.fluid_forces.as_secs_f64(),
            ),
            ("dem_integrate".into(), self.timers.integrate.as_secs_f64()),
            (
                "gas_assembly_and_porosity".into(),
                self.timers.gas.as_secs_f64() - gas_solve_s,
            ),
            ("gas_linear_solve".into(), gas_solve_s),
        ]
    }

    /// Cell searches for neighbours in this process.
    pub fn neighbor_builds(&self) -> u64 {
        if self.two_level() {
            self.work.candidates.builds
        } else {
            self.work.list.builds
        }
    }

    /// Refilterings of the force pass's list from the outer candidates in this process (two-level scheme only).
    pub fn neighbor_refilters(&self) -> u64 {
        self.work.refilters
    }

    /// Number of candidate pairs the force pass examines (each pair once).
    pub fn candidate_pairs(&self) -> usize {
        self.work.list.pair_count()
    }

    fn two_level(&self) -> bool {
        self.config.inner_skin_m < self.config.skin_m
    }

    /// Number of active particle–particle and particle–wall contacts.
    pub fn contact_counts(&self) -> (usize, usize) {
        (
            self.history.pair.touching.iter().filter(|&&t| t).count(),
            self.history.wall.touching.iter().filter(|&&t| t).count(),
        )
    }

    /// Approximate heap bytes of state and workspace.
    pub fn heap_bytes(&self) -> usize {
        self.particles.heap_bytes()
            + self.work.list.heap_bytes()
            + self.work.candidates.heap_bytes()
            + self.history.heap_bytes()
            + self.work.buffers.heap_bytes()
    }

    /// Advances `n` steps.
    pub fn run_steps(&mut self, n: u64) -> Result<(), NumericalError> {
        // The force pass and the list rebuilds run on the team, whose helpers spin between them (a hand-over to a
        // sleeping thread costs a wake-up) and park when this returns. Every step
        // but the last hands its first half (kick + drift) of the next step to its own force loop; the state is
        // a whole step again when this returns.
        let result = (0..n).try_for_each(|k| {
            // A gas step sees the particles at the end of a DEM step, so the step before it does not fuse the next
            // step's drift into its force loop.
            let gas_due = self
                .gas
                .as_ref()
                .is_some_and(|g| (self.step + 1).is_multiple_of(g.dem_steps_per_gas_step));
            // A sort too sees whole steps (it takes the state as a checkpoint does).
            let sort_due = self
                .config
                .sort_every_steps
                .is_some_and(|every| (self.step + 1).is_multiple_of(every));
            self.step_inner(k + 1 < n && !gas_due && !sort_due)?;
            if gas_due {
                self.advance_gas()?;
            }
            if sort_due {
                self.sort_particles()?;
            }
            Ok(())
        });
        self.work.team.rest();
        if result.is_err() {
            // A failed step leaves no meaningful state; do not pretend the next step's drift is pending.
            self.work.pending_drift = None;
            self.work.accumulators_zeroed = false;
        }
        result
    }

    /// Attaches a gas (a coupled run); a restored run then restores the gas state with [`Self::restore_gas`].
    pub fn attach_gas(&mut self, gas: GasCoupling) {
        if gas.drying.is_some() {
            // Condensation may wet a dry bed.
            self.work.cohesion_inert = false;
        }
        self.gas = Some(Box::new(gas));
    }

    /// Puts a checkpointed gas state into the attached gas.
    pub fn restore_gas(&mut self, snap: &super::gas::coupled::GasSnapshot) -> Result<(), String> {
        match self.gas.as_mut() {
            Some(g) => g.restore(snap, &self.particles.radius_m),
            None => Err("the checkpoint holds a gas but the scenario has none".into()),
        }
    }

    fn advance_gas(&mut self) -> Result<(), NumericalError> {
        let t = Instant::now();
        let gas = self.gas.as_mut().expect("called only with a gas");
        let dt_gas = self.dt_s * gas.dem_steps_per_gas_step as f64;
        let mut result = gas
            .advance(dt_gas, &self.particles.position_m, &self.particles.radius_m)
            .map(|_| ());
        if result.is_ok()
            && gas.drying.is_some()
            && let Some(heat) = self.config.heat.as_ref()
        {
            let t = Instant::now();
            result = super::drying::dry(
                gas,
                &mut self.particles,
                &heat.heat_capacity_j_per_kg_k,
                &self.work.list,
                &mut self.history,
                dt_gas,
            )
            .map(|_| ());
            // The bridges' volumes changed: the next liquid step examines every slot and refreshes their constants.
            self.work.bridges.forget_watch();
            self.timers.drying += t.elapsed();
        }
        let budget = std::mem::take(&mut gas.heat_budget);
        if let (Some(ledger), Some(heat)) = (self.heat_ledger.as_mut(), gas.heat) {
            let c_g = heat.thermal.heat_capacity_j_per_kg_k;
            ledger.gas_boundary_in_j += c_g * budget.boundary_in;
            ledger.gas_boundary_out_j += c_g * budget.boundary_out;
            ledger.gas_continuity_j += c_g * budget.continuity;
        }
        self.timers.gas += t.elapsed();
        result.map_err(|detail| NumericalError::GasDiverged {
            step: self.step,
            detail,
        })
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<(), NumericalError> {
        self.run_steps(1)
    }

    fn step_inner(&mut self, fuse_next_drift: bool) -> Result<(), NumericalError> {
        let dt = self.dt_s;
        let config = Arc::clone(&self.config);
        let t0 = Instant::now();
        let step_displacement2 = match self.work.pending_drift.take() {
            // The previous step's force loop already kicked and drifted every particle.
            Some(d2) => d2,
            None => {
                let g0 = config.gravity.at(self.time_s);
                let (particles, inverse) = (&mut self.particles, &self.work.inverse);
                let team = &*self.work.team;
                kick_drift(particles, inverse, &g0, dt, config.pseudo_2d, &config.domain, team)
            }
        };
        // No particle has moved further since the list was built than the sum of each drift's largest step: a bound
        // that costs nothing per particle, where the distance from each particle's position at the build cost a
        // read of that position per particle and step (12 % of a step without contacts, `docs/performance.md`).
        self.work.drift_bound_m += step_displacement2.sqrt();
        let max_displacement2 = self.work.drift_bound_m * self.work.drift_bound_m;
        for (angle, wall) in self.wall_angle_rad.iter_mut().zip(&config.walls) {
            *angle += wall.angular_velocity_rad_per_s() * dt;
        }
        self.step += 1;
        self.time_s += dt;
        let t1 = Instant::now();
        if self.work.list.needs_rebuild(
            self.particles.len(),
            max_displacement2,
            &config.walls,
            &self.wall_angle_rad,
        ) {
            if let Some(i) = find_lost(
                &self.particles.position_m,
                &config.domain,
                self.particles.max_radius_m(),
                &self.work.team,
            ) {
                let position_m = self.particles.position_m[i];
                return Err(if (position_m.x + position_m.y + position_m.z).is_finite() {
                    NumericalError::ParticleLost {
                        step: self.step,
                        particle: self.particles.id[i],
                        position_m,
                    }
                } else {
                    NumericalError::NonFinite {
                        step: self.step,
                        particle: self.particles.id[i],
                        field: "position",
                    }
                });
            }
            self.refresh_neighbors();
        } else if self.threads() > 1 && self.work.steps_since_rebalance >= REBALANCE_EVERY_STEPS {
            self.rebalance();
        }
        self.work.steps_since_rebalance += 1;
        let t2 = Instant::now();
        if let Some(fluid) = self.gas.as_mut().map(|g| &mut g.fluid) {
            if !self.work.accumulators_zeroed {
                self.particles.force_n.iter_mut().for_each(|f| *f = Vec3::zeros());
                self.particles.torque_n_m.iter_mut().for_each(|t| *t = Vec3::zeros());
                self.work.accumulators_zeroed = true;
            }
            let p = &mut self.particles;
            let t = Instant::now();
            // On the force pass's team, whose helpers are still spinning from the previous step (a rayon pool's
            // sleeping workers took tens of µs to wake, more than the work of a few thousand particles).
            let team = (p.len() >= PARALLEL_FLUID_FORCES_MIN_PARTICLES).then_some(&*self.work.team);
            fluid.add_forces(&p.position_m, &p.velocity_m_per_s, &p.radius_m, &mut p.force_n, team);
            if let Some(tally) = self.net_force.as_mut() {
                // The arrays were zero: they hold exactly the gas's forces.
                tally.fluid_n += p.force_n.iter().fold(Vec3::zeros(), |sum, f| sum + f);
            }
            self.timers.fluid_forces += t.elapsed();
        }
        if let Some(gas) = self.gas.as_mut().filter(|g| g.heat.is_some()) {
            // Convection under the frozen gas field into the heat channel (zero here: the last pass consumed it),
            // which the pair pass completes with conduction and turns into each particle's temperature step.
            let t = Instant::now();
            let p = &mut self.particles;
            gas.add_convection(
                &p.position_m,
                &p.velocity_m_per_s,
                &p.radius_m,
                &p.temperature_k,
                &mut p.channels.heat_flow_w,
            );
            self.timers.fluid_forces += t.elapsed();
        }
        self.step_liquid(dt);
        let kick = HalfKick {
            gravity: config.gravity.at(self.time_s),
            dt_s: dt,
            fuse_next_drift,
        };
        if let Some(tally) = self.net_force.as_mut() {
            add_wall_forces(
                &config,
                &self.particles,
                &self.work.inverse,
                &self.wall_angle_rad,
                dt,
                &self.work.list,
                &self.history,
                config.cohesion.as_ref().filter(|_| !self.work.cohesion_inert),
                &self.work.bridges,
                &mut tally.wall_contact_n,
                &mut tally.wall_cohesion_n,
            );
            tally.steps += 1;
        }
        let pass = self.forces(dt, Some(kick));
        if let Some(ledger) = self.heat_ledger.as_mut() {
            ledger.wall_to_particles_j += dt * pass.wall_heat_flow_w;
        }
        if fuse_next_drift {
            self.work.pending_drift = Some(pass.max_displacement2_m2);
        }
        let t3 = Instant::now();
        self.timers.integrate += t1 - t0;
        self.timers.neighbor += t2 - t1;
        self.timers.force += t3 - t2;
        if let Some(i) = pass.non_finite {
            return Err(self.non_finite(i));
        }
        self.check_overlap(pass.worst_overlap)
    }

    fn non_finite(&self, i: usize) -> NumericalError {
        let p = &self.particles;
        let velocity_finite = p.velocity_m_per_s[i].iter().all(|a| a.is_finite());
        let field = if self.work.accumulators_zeroed {
            // The pass consumed the force and torque and left the arrays zero. Velocities were finite before the
            // kick and masses, dt and gravity are, so a non-finite velocity means a non-finite force, and a
            // non-finite angular velocity a non-finite torque.
            if velocity_finite { "torque" } else { "force" }
        } else if !p.force_n[i].iter().all(|a| a.is_finite()) {
            "force"
        } else if !p.torque_n_m[i].iter().all(|a| a.is_finite()) {
            "torque"
        } else if !velocity_finite {
            "velocity"
        } else {
            "angular velocity"
        };
        NumericalError::NonFinite {
            step: self.step,
            particle: p.id[i],
            field,
        }
    }

    fn check_overlap(&self, worst: super::pair_pass::WorstOverlap) -> Result<(), NumericalError> {
        if worst.ratio > self.config.max_overlap_fraction {
            return Err(NumericalError::ExcessiveOverlap {
                step: self.step,
                particle: self.particles.id[worst.particle as usize],
                partner: worst.partner_name(&self.config.walls, &self.particles.id),
                overlap_m: worst.overlap_m,
                ratio: worst.ratio,
                limit: self.config.max_overlap_fraction,
            });
        }
        Ok(())
    }

    /// The pair pass's forces at the current positions (contacts, and cohesion in a cohesive run); with `kick`, also
    /// the second half kick.
    fn forces(&mut self, dt: f64, kick: Option<HalfKick>) -> ForcePass {
        if let Some(heat) = &self.config.heat {
            heat.wall_temperatures_at(self.time_s, &mut self.work.wall_temperature_k);
        }
        let pass = compute_pair_forces(
            &self.config,
            &mut self.particles,
            &self.work.inverse,
            &self.wall_angle_rad,
            dt,
            &self.work.list,
            &mut self.history,
            &mut self.work.buffers,
            &self.work.ranges,
            &self.work.team,
            kick,
            self.work.accumulators_zeroed,
            self.config.cohesion.as_ref().filter(|_| !self.work.cohesion_inert),
            &self.work.bridges,
            &self.work.wall_temperature_k,
        );
        self.work.accumulators_zeroed = kick.is_some_and(|k| k.fuse_next_drift);
        self.cohesion_events.well_crossings += pass.well_crossings;
        pass
    }

    /// The liquid inventory's step in a run with liquid bridges: the spray when it is due, then bridge formation and
    /// rupture at the current positions (`engine::liquid`).
    fn step_liquid(&mut self, dt: f64) {
        let config = Arc::clone(&self.config);
        let Some(cohesion) = config.cohesion.as_ref().filter(|_| !self.work.cohesion_inert) else {
            return;
        };
        let t = Instant::now();
        let events = step_liquid(
            cohesion,
            &config,
            &mut self.particles,
            &self.work.list,
            &mut self.history,
            &mut self.work.bridges,
            &self.wall_angle_rad,
            self.time_s,
            self.step,
            dt,
            self.work.drift_bound_m,
            config.inner_skin_m,
        );
        self.sprayed_m3 += events.sprayed_m3;
        if events.sprayed_m3 > 0.0
            && let Some(drying) = self.gas.as_mut().and_then(|g| g.drying.as_mut())
        {
            drying.ledger.sprayed_kg += events.sprayed_m3 * drying.config.liquid_density_kg_per_m3;
        }
        self.cohesion_events.bridges_formed += events.bridges_formed;
        self.cohesion_events.bridges_ruptured += events.bridges_ruptured;
        self.timers.liquid += t.elapsed();
    }

    /// Starts summing the net force on the particles by mechanism every step (see [`NetForceTally`]), unless
    /// it already does (a run restored with its sums); read and restart the sums with `net_force.take_means()`.
    pub fn record_net_forces(&mut self) {
        if self.net_force.is_none() {
            self.net_force = Some(NetForceTally::new(self.config.walls.len()));
        }
    }

    /// Records the present liquid and vapour as the drying ledger's start (a new run with drying, once its gas is
    /// attached; a restored run keeps its checkpointed ledger).
    pub fn start_drying_ledger(&mut self) {
        let liquid_m3 = self.total_liquid_m3();
        if let Some(gas) = self.gas.as_mut() {
            let vapour_kg = gas.vapour_kg();
            if let (Some(drying), Some(vapour_kg)) = (gas.drying.as_mut(), vapour_kg) {
                drying.ledger = super::drying::DryingLedger {
                    initial_liquid_kg: liquid_m3 * drying.config.liquid_density_kg_per_m3,
                    initial_vapour_kg: vapour_kg,
                    ..Default::default()
                };
            }
        }
    }

    /// The drying ledger's closure: (liquid + vapour in the gas + vapour gone out − vapour come in) over (the
    /// start's liquid and vapour + sprayed), minus 1 (`None` without drying).
    pub fn drying_closure(&self) -> Option<f64> {
        let gas = self.gas.as_ref()?;
        let drying = gas.drying.as_ref()?;
        let l = &drying.ledger;
        let liquid_kg = self.total_liquid_m3() * drying.config.liquid_density_kg_per_m3;
        let now = liquid_kg + gas.vapour_kg()? + l.vapour_out_kg - l.vapour_in_kg;
        let start = l.initial_liquid_kg + l.initial_vapour_kg + l.sprayed_kg;
        Some(now / start - 1.0)
    }

    /// Starts the energy ledger from the present state (a new run with heat transfer, once its gas is attached; a
    /// restored run keeps its checkpointed ledger). Without heat transfer it does nothing.
    pub fn start_heat_ledger(&mut self) {
        if self.config.heat.is_some() {
            self.heat_ledger = Some(HeatLedger::default());
            let held = self.held_energy_j();
            if let (Some(ledger), Some(held)) = (self.heat_ledger.as_mut(), held) {
                ledger.initial_energy_j = held;
            }
        }
    }

    /// The energy the run holds now (`engine::heat_ledger`): the particles' Σ m c_p T, the gas's Σ ε ρ c_g T V and
    /// the convection it has still to receive at its next step, and the latent heat of the liquid evaporated net,
    /// J (`None` without heat transfer).
    pub fn held_energy_j(&self) -> Option<f64> {
        let heat = self.config.heat.as_ref()?;
        let p = &self.particles;
        let particles: f64 = (0..p.len())
            .map(|i| p.mass_kg[i] * heat.heat_capacity_j_per_kg_k[p.species[i].index()] * p.temperature_k[i])
            .sum();
        let gas = self.gas.as_ref().map_or(0.0, |g| {
            let latent = g
                .drying
                .as_ref()
                .map_or(0.0, |d| d.config.latent_heat_j_per_kg * d.ledger.evaporated_kg);
            g.thermal_energy_j().unwrap_or(0.0) + g.pending_convection_j(self.dt_s).unwrap_or(0.0) + latent
        });
        Some(particles + gas)
    }

    /// The energy ledger's closure: the energy held now over the start plus all that crossed into the run, minus 1
    /// (`None` without heat transfer).
    pub fn energy_closure(&self) -> Option<f64> {
        let ledger = self.heat_ledger.as_ref()?;
        Some(self.held_energy_j()? / ledger.expected_energy_j() - 1.0)
    }

    fn rebalance(&mut self) {
        self.work.ranges = RangePlan::balanced(
            &self.work.list,
            &self.history.pair.touching,
            &RangePlan::shares_for(self.threads(), &self.range_block),
            Some(&self.work.ranges),
            &self.work.team,
        );
        self.work.steps_since_rebalance = 0;
    }

    fn refresh_neighbors(&mut self) {
        let old_list = std::mem::take(&mut self.work.list);
        self.work.list.builds = old_list.builds;
        // On the force pass's team, whose helpers are spinning from the last pass (no wake-up to pay).
        // (A one-thread team runs everything on this thread.)
        let team = Arc::clone(&self.work.team);
        let team = &*team;
        self.build_lists(self.needs_cell_search(), team);
        let layout = self.config.history_layout();
        let (history, orphans) =
            self.history
                .remap(&old_list, &self.work.list, layout, &mut self.particles.liquid_m3, team);
        // A contact is always a candidate of a list built from the same positions, and a bridge or well pair is
        // within the cohesion reach, hence a candidate too.
        debug_assert_eq!(orphans, 0, "contact histories lost in a neighbour-list rebuild");
        self.history = history;
        // The bridge constants are per slot of the old list.
        self.work.bridges = BridgeCache::default();
        self.rebalance();
    }

    /// Whether bringing `list` up to date needs a search of the cells. Two-level: only if a particle (or wall) has
    /// moved more than (skin − inner skin)/2 since the outer candidates were found, which would let a pair closer
    /// than the inner skin escape them; otherwise `list` is refiltered from them.
    fn needs_cell_search(&self) -> bool {
        let c = &self.config;
        let allowance_m = 0.5 * (c.skin_m - c.inner_skin_m);
        !self.two_level()
            || self.work.candidates.displaced_beyond(
                &c.domain,
                &self.particles.position_m,
                &c.walls,
                &self.wall_angle_rad,
                allowance_m,
                &self.work.team,
            )
    }

    /// Brings `list` up to date with the current positions, with a cell search when `searched` (which must be
    /// true whenever [`Simulation::needs_cell_search`] is), on `team`.
    fn build_lists(&mut self, searched: bool, team: &Team) {
        self.work.drift_bound_m = 0.0;
        let c = &self.config;
        let wall_turn = turns(&self.wall_angle_rad);
        let outer = Criteria {
            domain: &c.domain,
            position: &self.particles.position_m,
            radius: &self.particles.radius_m,
            skin_m: c.skin_m,
            range: c.reach(),
            walls: &c.walls,
            wall_angle: &self.wall_angle_rad,
            wall_turn: &wall_turn,
            pseudo_2d: c.pseudo_2d,
        };
        if !self.two_level() {
            self.work.list.build(&outer, team);
            return;
        }
        if searched {
            self.work.candidates.build(&outer, team);
        } else {
            self.work.refilters += 1;
        }
        let inner = Criteria {
            skin_m: c.inner_skin_m,
            ..outer
        };
        self.work.list.refilter(&self.work.candidates, &inner, team);
        if searched && c.inner_skin_auto && 2 * self.work.list.pair_count() > self.work.candidates.pair_count() {
            // The inner skin does not halve the pairs the force pass examines (a loose or fast bed): refilters
            // would cost more than they save, so one level until the next cell search.
            self.work.list.adopt(&self.work.candidates);
        }
    }
}
