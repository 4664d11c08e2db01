//! The conversion between a [`SimState`] and the flat [`Arrays`] of a checkpoint, both ways (the arrays' layout
//! and checks are in the parent module).

use super::{Arrays, Header, HistoryArrays};
use crate::engine::Vec3;
use crate::engine::contacts::{ContactStore, WallId};
use crate::engine::gas::ExchangeAccumulator;
use crate::engine::gas::coupled::{GasScalarSnapshot, GasSnapshot, GasStepStats};
use crate::engine::gas::held_drag::HeldDragSnapshot;
use crate::engine::heat_ledger::HeatLedger;
use crate::engine::models::ContactHistory;
use crate::engine::net_force::NetForceTally;
use crate::engine::particles::{ParticleId, Particles, SpeciesId};
use crate::engine::state::{RngState, SimState};

/// The name of the gas temperature among the gas's transported scalars.
const GAS_TEMPERATURE: &str = "temperature_k";

/// The name of the vapour among the gas's transported scalars (a run with drying).
const GAS_VAPOUR: &str = crate::engine::drying::VAPOUR_FIELD;

fn flatten(v: &[Vec3]) -> Vec<f64> {
    v.iter().flat_map(|x| [x.x, x.y, x.z]).collect()
}

fn unflatten(v: &[f64]) -> Vec<Vec3> {
    v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
}

impl Arrays {
    /// The datasets of `state`. Call [`Arrays::check`] on the result before writing it.
    pub(crate) fn from_state(state: &SimState) -> Arrays {
        let p = &state.particles;
        let gas = state.gas.as_ref();
        // The one transported scalar a checkpoint holds today: the gas temperature of a run with heat transfer.
        let gas_temperature = gas.and_then(|g| g.scalars.iter().find(|s| s.name == GAS_TEMPERATURE));
        let held = gas.and_then(|g| g.held_drag.as_ref());
        let vapour = gas.and_then(|g| g.scalars.iter().find(|s| s.name == GAS_VAPOUR));
        let ledger = gas.and_then(|g| g.drying.as_ref());
        let ledger_value = |f: fn(&crate::engine::drying::DryingLedger) -> f64| ledger.map(f).into_iter().collect();
        let heat_value = |f: fn(&HeatLedger) -> f64| state.heat_ledger.as_ref().map(f).into_iter().collect();
        Arrays {
            particle_id: p.id.iter().map(|id| id.0).collect(),
            particle_species: p.species.iter().map(|s| s.0).collect(),
            radius_m: p.radius_m.clone(),
            mass_kg: p.mass_kg.clone(),
            inertia_kg_m2: p.inertia_kg_m2.clone(),
            position_m: flatten(&p.position_m),
            velocity_m_per_s: flatten(&p.velocity_m_per_s),
            angular_velocity_rad_per_s: flatten(&p.angular_velocity_rad_per_s),
            force_n: flatten(&p.force_n),
            torque_n_m: flatten(&p.torque_n_m),

            pair_i: state.contacts.pairs.iter().map(|(i, _, _)| i.0).collect(),
            pair_j: state.contacts.pairs.iter().map(|(_, j, _)| j.0).collect(),
            pair_active: state
                .contacts
                .pairs
                .iter()
                .map(|(_, _, h)| u8::from(h.active))
                .collect(),

            wall_i: state.contacts.walls.iter().map(|(i, _, _)| i.0).collect(),
            wall_wall: state.contacts.walls.iter().map(|(_, w, _)| w.0).collect(),
            wall_active: state
                .contacts
                .walls
                .iter()
                .map(|(_, _, h)| u8::from(h.active))
                .collect(),

            wall_angle_rad: state.wall_angle_rad.clone(),

            rng_seed: state.rng.seed.to_vec(),
            rng_stream: vec![state.rng.stream],
            rng_word_pos_hi: vec![(state.rng.word_pos >> 64) as u64],
            rng_word_pos_lo: vec![state.rng.word_pos as u64],

            gas_pressure_pa: gas.map(|g| g.pressure_pa.clone()).unwrap_or_default(),
            gas_porosity: gas.map(|g| g.porosity.clone()).unwrap_or_default(),
            gas_velocity_x: gas.map(|g| g.velocity_m_per_s[0].clone()).unwrap_or_default(),
            gas_velocity_y: gas.map(|g| g.velocity_m_per_s[1].clone()).unwrap_or_default(),
            gas_velocity_z: gas.map(|g| g.velocity_m_per_s[2].clone()).unwrap_or_default(),
            gas_reaction_x: gas.map(|g| g.reaction_n_per_m3[0].clone()).unwrap_or_default(),
            gas_reaction_y: gas.map(|g| g.reaction_n_per_m3[1].clone()).unwrap_or_default(),
            gas_reaction_z: gas.map(|g| g.reaction_n_per_m3[2].clone()).unwrap_or_default(),
            gas_beta_x: gas.map(|g| g.beta_sum[0].clone()).unwrap_or_default(),
            gas_beta_y: gas.map(|g| g.beta_sum[1].clone()).unwrap_or_default(),
            gas_beta_z: gas.map(|g| g.beta_sum[2].clone()).unwrap_or_default(),
            gas_beta_v_x: gas.map(|g| g.beta_velocity_sum[0].clone()).unwrap_or_default(),
            gas_beta_v_y: gas.map(|g| g.beta_velocity_sum[1].clone()).unwrap_or_default(),
            gas_beta_v_z: gas.map(|g| g.beta_velocity_sum[2].clone()).unwrap_or_default(),
            gas_time_s: gas.map(|g| g.time_s).into_iter().collect(),
            gas_reaction_steps: gas.map(|g| g.reaction_steps).into_iter().collect(),
            gas_last_outer_iterations: gas.map(|g| g.last.outer_iterations).into_iter().collect(),
            gas_last_linear_iterations: gas.map(|g| g.last.linear_iterations).into_iter().collect(),
            gas_last_mass_imbalance: gas.map(|g| g.last.mass_imbalance).into_iter().collect(),
            gas_last_converged: gas.map(|g| u8::from(g.last.converged)).into_iter().collect(),
            gas_temperature_k: gas_temperature.map(|s| s.value.clone()).unwrap_or_default(),
            gas_heat_transfer_sum: gas_temperature
                .map(|s| s.exchange.transfer_sum.clone())
                .unwrap_or_default(),
            gas_heat_exchange_steps: gas_temperature.map(|s| s.exchange.steps).into_iter().collect(),
            gas_vapour_mass_fraction: vapour.map(|s| s.value.clone()).unwrap_or_default(),
            drying_initial_liquid_kg: ledger_value(|l| l.initial_liquid_kg),
            drying_initial_vapour_kg: ledger_value(|l| l.initial_vapour_kg),
            drying_sprayed_kg: ledger_value(|l| l.sprayed_kg),
            drying_evaporated_kg: ledger_value(|l| l.evaporated_kg),
            drying_vapour_in_kg: ledger_value(|l| l.vapour_in_kg),
            drying_vapour_out_kg: ledger_value(|l| l.vapour_out_kg),
            held_drag_position_m: held.map(|h| flatten(&h.position_m)).unwrap_or_default(),
            held_drag_velocity: held.map(|h| flatten(&h.velocity_m_per_s)).unwrap_or_default(),
            held_drag_velocity_sum: held.map(|h| flatten(&h.velocity_sum_m_per_s)).unwrap_or_default(),

            liquid_m3: p.liquid_m3.clone(),
            sprayed_m3: p.sprayed_m3.clone(),
            temperature_k: p.temperature_k.clone(),

            heat_initial_energy_j: heat_value(|l| l.initial_energy_j),
            heat_wall_to_particles_j: heat_value(|l| l.wall_to_particles_j),
            heat_gas_boundary_in_j: heat_value(|l| l.gas_boundary_in_j),
            heat_gas_boundary_out_j: heat_value(|l| l.gas_boundary_out_j),
            heat_gas_continuity_j: heat_value(|l| l.gas_continuity_j),
            net_force_steps: state.net_force.as_ref().map(|t| t.steps).into_iter().collect(),
            net_force_fluid_n: state
                .net_force
                .as_ref()
                .map(|t| flatten(&[t.fluid_n]))
                .unwrap_or_default(),
            net_force_wall_contact_n: state
                .net_force
                .as_ref()
                .map(|t| flatten(&t.wall_contact_n))
                .unwrap_or_default(),
            net_force_wall_cohesion_n: state
                .net_force
                .as_ref()
                .map(|t| flatten(&t.wall_cohesion_n))
                .unwrap_or_default(),

            pair_history: HistoryArrays::of(state.contacts.pairs.iter().map(|(_, _, h)| h)),
            wall_history: HistoryArrays::of(state.contacts.walls.iter().map(|(_, _, h)| h)),
            channels: p.channels.clone(),
        }
    }

    /// The state these arrays describe. The arrays must have passed [`Arrays::check`].
    pub(crate) fn into_state(self, header: &Header<'_>) -> SimState {
        let particles = Particles {
            id: self.particle_id.iter().map(|&i| ParticleId(i)).collect(),
            species: self.particle_species.iter().map(|&s| SpeciesId(s)).collect(),
            radius_m: self.radius_m,
            mass_kg: self.mass_kg,
            inertia_kg_m2: self.inertia_kg_m2,
            position_m: unflatten(&self.position_m),
            velocity_m_per_s: unflatten(&self.velocity_m_per_s),
            angular_velocity_rad_per_s: unflatten(&self.angular_velocity_rad_per_s),
            force_n: unflatten(&self.force_n),
            torque_n_m: unflatten(&self.torque_n_m),
            liquid_m3: self.liquid_m3,
            sprayed_m3: self.sprayed_m3,
            temperature_k: self.temperature_k,
            channels: self.channels,
        };
        let record = |active: u8, history: &HistoryArrays, k: usize| {
            let mut h = ContactHistory {
                active: active != 0,
                ..ContactHistory::INACTIVE
            };
            history.fill(k, &mut h);
            h
        };
        let pairs = (0..self.pair_i.len())
            .map(|k| {
                (
                    ParticleId(self.pair_i[k]),
                    ParticleId(self.pair_j[k]),
                    record(self.pair_active[k], &self.pair_history, k),
                )
            })
            .collect();
        let walls = (0..self.wall_i.len())
            .map(|k| {
                (
                    ParticleId(self.wall_i[k]),
                    WallId(self.wall_wall[k]),
                    record(self.wall_active[k], &self.wall_history, k),
                )
            })
            .collect();
        let mut seed = [0u8; 32];
        seed.copy_from_slice(&self.rng_seed);
        let word_pos = (u128::from(self.rng_word_pos_hi[0]) << 64) | u128::from(self.rng_word_pos_lo[0]);
        let cells = self.gas_pressure_pa.len();
        let gas = (self.gas_time_s.len() == 1).then(|| GasSnapshot {
            pressure_pa: self.gas_pressure_pa,
            velocity_m_per_s: [self.gas_velocity_x, self.gas_velocity_y, self.gas_velocity_z],
            porosity: self.gas_porosity,
            time_s: self.gas_time_s[0],
            reaction_n_per_m3: [self.gas_reaction_x, self.gas_reaction_y, self.gas_reaction_z],
            beta_sum: [self.gas_beta_x, self.gas_beta_y, self.gas_beta_z],
            beta_velocity_sum: [self.gas_beta_v_x, self.gas_beta_v_y, self.gas_beta_v_z],
            reaction_steps: self.gas_reaction_steps[0],
            last: GasStepStats {
                outer_iterations: self.gas_last_outer_iterations[0],
                linear_iterations: self.gas_last_linear_iterations[0],
                mass_imbalance: self.gas_last_mass_imbalance[0],
                converged: self.gas_last_converged[0] == 1,
            },
            held_drag: (!self.held_drag_position_m.is_empty()).then(|| HeldDragSnapshot {
                position_m: unflatten(&self.held_drag_position_m),
                velocity_m_per_s: unflatten(&self.held_drag_velocity),
                velocity_sum_m_per_s: unflatten(&self.held_drag_velocity_sum),
            }),
            scalars: (self.gas_temperature_k.len() == cells && cells > 0)
                .then(|| GasScalarSnapshot {
                    name: GAS_TEMPERATURE.into(),
                    unit: "K".into(),
                    value: self.gas_temperature_k,
                    exchange: ExchangeAccumulator {
                        coefficient_sum: vec![0.0; cells],
                        coefficient_value_sum: vec![0.0; cells],
                        transfer_sum: self.gas_heat_transfer_sum,
                        steps: self.gas_heat_exchange_steps.first().copied().unwrap_or(0),
                    },
                })
                .into_iter()
                .chain(
                    (self.gas_vapour_mass_fraction.len() == cells && cells > 0).then(|| GasScalarSnapshot {
                        name: GAS_VAPOUR.into(),
                        unit: "kg/kg".into(),
                        value: self.gas_vapour_mass_fraction,
                        exchange: ExchangeAccumulator::new(cells),
                    }),
                )
                .collect(),
            drying: (self.drying_evaporated_kg.len() == 1).then(|| crate::engine::drying::DryingLedger {
                initial_liquid_kg: self.drying_initial_liquid_kg[0],
                initial_vapour_kg: self.drying_initial_vapour_kg[0],
                sprayed_kg: self.drying_sprayed_kg[0],
                evaporated_kg: self.drying_evaporated_kg[0],
                vapour_in_kg: self.drying_vapour_in_kg[0],
                vapour_out_kg: self.drying_vapour_out_kg[0],
            }),
        });
        let net_force = (self.net_force_steps.len() == 1).then(|| NetForceTally {
            steps: self.net_force_steps[0],
            fluid_n: unflatten(&self.net_force_fluid_n)[0],
            wall_contact_n: unflatten(&self.net_force_wall_contact_n),
            wall_cohesion_n: unflatten(&self.net_force_wall_cohesion_n),
        });
        let heat_ledger = (self.heat_initial_energy_j.len() == 1).then(|| HeatLedger {
            initial_energy_j: self.heat_initial_energy_j[0],
            wall_to_particles_j: self.heat_wall_to_particles_j[0],
            gas_boundary_in_j: self.heat_gas_boundary_in_j[0],
            gas_boundary_out_j: self.heat_gas_boundary_out_j[0],
            gas_continuity_j: self.heat_gas_continuity_j[0],
        });
        SimState {
            gas,
            net_force,
            heat_ledger,
            step: header.step,
            time_s: header.time_s,
            dt_s: header.dt_s,
            particles,
            wall_angle_rad: self.wall_angle_rad,
            contacts: ContactStore { pairs, walls },
            rng: RngState {
                seed,
                stream: self.rng_stream[0],
                word_pos,
            },
        }
    }
}
