//! `SimState`: everything a checkpoint holds, and nothing that can be rebuilt (neighbour lists, buffers, timers).
//!
//! Restoring a `SimState` into a `Simulation` with the same configuration continues the run bit for bit.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

use super::Vec3;
use super::channels::CHANNELS;
use super::contacts::ContactStore;
use super::gas::coupled::GasSnapshot;
use super::heat_ledger::HeatLedger;
use super::models::ContactHistory;
use super::models::history::{FieldValue, HISTORY_FIELDS};
use super::net_force::NetForceTally;
use super::particles::Particles;

/// The complete state of a ChaCha8 generator: seed, stream and position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RngState {
    pub seed: [u8; 32],
    pub stream: u64,
    pub word_pos: u128,
}

impl RngState {
    /// A generator seeded from a 64-bit seed (e.g. derived from the campaign seed and job id).
    pub fn from_seed_u64(seed: u64) -> Self {
        let rng = ChaCha8Rng::seed_from_u64(seed);
        RngState::capture(&rng)
    }

    pub fn capture(rng: &ChaCha8Rng) -> Self {
        RngState {
            seed: rng.get_seed(),
            stream: rng.get_stream(),
            word_pos: rng.get_word_pos(),
        }
    }

    pub fn restore(&self) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::from_seed(self.seed);
        rng.set_stream(self.stream);
        rng.set_word_pos(self.word_pos);
        rng
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct SimState {
    pub step: u64,
    pub time_s: f64,
    pub dt_s: f64,
    pub particles: Particles,
    /// Angle turned by each wall (0 for static walls), rad.
    pub wall_angle_rad: Vec<f64>,
    /// Contact histories and the cohesion model's per-pair states (liquid bridges, square-well pairs).
    pub contacts: ContactStore,
    pub rng: RngState,
    /// The gas of a coupled run.
    pub gas: Option<GasSnapshot>,
    /// The net-force sums since the last series row, when the run records them (a diagnostic, but a run resumed
    /// from here must write the same rows).
    pub net_force: Option<NetForceTally>,
    /// The energy ledger of a run with heat transfer (`engine::heat_ledger`).
    pub heat_ledger: Option<HeatLedger>,
}

/// Bit-level comparison of two states: `None` when every value is identical to the bit (`to_bits()` for floats),
/// otherwise the first differing field, e.g. `particles.velocity_m_per_s[17].y: 0x3f... vs 0x3f...`. The restart
/// and thread-count tests use it, so a failure names the structure that differs.
pub fn first_difference(a: &SimState, b: &SimState) -> Option<String> {
    fn f(name: &str, x: f64, y: f64) -> Option<String> {
        (x.to_bits() != y.to_bits()).then(|| {
            format!(
                "{name}: {x:e} (0x{:016x}) vs {y:e} (0x{:016x})",
                x.to_bits(),
                y.to_bits()
            )
        })
    }
    fn v(name: &str, x: &Vec3, y: &Vec3) -> Option<String> {
        ["x", "y", "z"]
            .iter()
            .enumerate()
            .find_map(|(k, c)| f(&format!("{name}.{c}"), x[k], y[k]))
    }
    fn scalars(name: &str, x: &[f64], y: &[f64]) -> Option<String> {
        if x.len() != y.len() {
            return Some(format!("{name}: length {} vs {}", x.len(), y.len()));
        }
        x.iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (p, q))| f(&format!("{name}[{i}]"), *p, *q))
    }
    fn vectors(name: &str, x: &[Vec3], y: &[Vec3]) -> Option<String> {
        if x.len() != y.len() {
            return Some(format!("{name}: length {} vs {}", x.len(), y.len()));
        }
        x.iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (p, q))| v(&format!("{name}[{i}]"), p, q))
    }
    /// Every field of the record, walked through the declaration's table (`models::history`), so that a field
    /// added there is compared here too.
    fn history(name: &str, x: &ContactHistory, y: &ContactHistory) -> Option<String> {
        if x.active != y.active {
            return Some(format!("{name}.active: {} vs {}", x.active, y.active));
        }
        HISTORY_FIELDS.iter().find_map(|field| {
            let label = format!("{name}.{}.{}", field.slot, field.name);
            match ((field.get)(x), (field.get)(y)) {
                (FieldValue::Flag(p), FieldValue::Flag(q)) => (p != q).then(|| format!("{label}: {p} vs {q}")),
                (FieldValue::Scalar(p), FieldValue::Scalar(q)) => f(&label, p, q),
                (FieldValue::Vector(p), FieldValue::Vector(q)) => v(&label, &p, &q),
                (p, q) => Some(format!("{label}: {p:?} vs {q:?}")),
            }
        })
    }
    if a.step != b.step {
        return Some(format!("step: {} vs {}", a.step, b.step));
    }
    let (p, q) = (&a.particles, &b.particles);
    if p.id != q.id || p.species != q.species {
        return Some("particles.id or particles.species".into());
    }
    if a.rng != b.rng {
        return Some("rng".into());
    }
    if a.contacts.pairs.len() != b.contacts.pairs.len() {
        return Some(format!(
            "contacts.pairs: {} vs {} records",
            a.contacts.pairs.len(),
            b.contacts.pairs.len()
        ));
    }
    if a.contacts.walls.len() != b.contacts.walls.len() {
        return Some(format!(
            "contacts.walls: {} vs {} records",
            a.contacts.walls.len(),
            b.contacts.walls.len()
        ));
    }
    if a.gas.is_some() != b.gas.is_some() {
        return Some("gas: present in one state only".into());
    }
    if let (Some(g), Some(h)) = (&a.gas, &b.gas) {
        let names = |s: &GasSnapshot| {
            s.fields()
                .map(|v| format!("{} ({})", v.name, v.unit))
                .collect::<Vec<_>>()
        };
        let gas = f("gas.time_s", g.time_s, h.time_s)
            .or_else(|| (names(g) != names(h)).then(|| format!("gas fields: {:?} vs {:?}", names(g), names(h))))
            .or_else(|| {
                g.fields()
                    .zip(h.fields())
                    .find_map(|(x, y)| scalars(&format!("gas.{}", x.name), x.values, y.values))
            })
            .or_else(|| {
                (0..3).find_map(|k| {
                    scalars(
                        &format!("gas.reaction_n_per_m3[{k}]"),
                        &g.reaction_n_per_m3[k],
                        &h.reaction_n_per_m3[k],
                    )
                    .or_else(|| scalars(&format!("gas.beta_sum[{k}]"), &g.beta_sum[k], &h.beta_sum[k]))
                    .or_else(|| {
                        scalars(
                            &format!("gas.beta_velocity_sum[{k}]"),
                            &g.beta_velocity_sum[k],
                            &h.beta_velocity_sum[k],
                        )
                    })
                })
            })
            .or_else(|| (g.reaction_steps != h.reaction_steps).then(|| "gas.reaction_steps".to_string()))
            .or_else(|| match (&g.held_drag, &h.held_drag) {
                (Some(x), Some(y)) => vectors("gas.held_drag.position_m", &x.position_m, &y.position_m)
                    .or_else(|| {
                        vectors(
                            "gas.held_drag.velocity_m_per_s",
                            &x.velocity_m_per_s,
                            &y.velocity_m_per_s,
                        )
                    })
                    .or_else(|| {
                        vectors(
                            "gas.held_drag.velocity_sum_m_per_s",
                            &x.velocity_sum_m_per_s,
                            &y.velocity_sum_m_per_s,
                        )
                    }),
                (None, None) => None,
                _ => Some("gas.held_drag: present in one state only".into()),
            })
            .or_else(|| {
                g.scalars.iter().zip(&h.scalars).find_map(|(x, y)| {
                    let (p, q) = (&x.exchange, &y.exchange);
                    let name = |sum: &str| format!("gas.{}.exchange.{sum}", x.name);
                    scalars(&name("coefficient_sum"), &p.coefficient_sum, &q.coefficient_sum)
                        .or_else(|| {
                            scalars(
                                &name("coefficient_value_sum"),
                                &p.coefficient_value_sum,
                                &q.coefficient_value_sum,
                            )
                        })
                        .or_else(|| scalars(&name("transfer_sum"), &p.transfer_sum, &q.transfer_sum))
                        .or_else(|| (p.steps != q.steps).then(|| name("steps")))
                })
            });
        if gas.is_some() {
            return gas;
        }
    }
    match (&a.net_force, &b.net_force) {
        (Some(x), Some(y)) => {
            let sums = (x.steps != y.steps)
                .then(|| format!("net_force.steps: {} vs {}", x.steps, y.steps))
                .or_else(|| v("net_force.fluid_n", &x.fluid_n, &y.fluid_n))
                .or_else(|| vectors("net_force.wall_contact_n", &x.wall_contact_n, &y.wall_contact_n))
                .or_else(|| vectors("net_force.wall_cohesion_n", &x.wall_cohesion_n, &y.wall_cohesion_n));
            if sums.is_some() {
                return sums;
            }
        }
        (None, None) => {}
        _ => return Some("net_force: present in one state only".into()),
    }
    match (&a.heat_ledger, &b.heat_ledger) {
        (Some(x), Some(y)) => {
            let totals = f("heat_ledger.initial_energy_j", x.initial_energy_j, y.initial_energy_j)
                .or_else(|| {
                    f(
                        "heat_ledger.wall_to_particles_j",
                        x.wall_to_particles_j,
                        y.wall_to_particles_j,
                    )
                })
                .or_else(|| {
                    f(
                        "heat_ledger.gas_boundary_in_j",
                        x.gas_boundary_in_j,
                        y.gas_boundary_in_j,
                    )
                })
                .or_else(|| {
                    f(
                        "heat_ledger.gas_boundary_out_j",
                        x.gas_boundary_out_j,
                        y.gas_boundary_out_j,
                    )
                })
                .or_else(|| f("heat_ledger.gas_continuity_j", x.gas_continuity_j, y.gas_continuity_j));
            if totals.is_some() {
                return totals;
            }
        }
        (None, None) => {}
        _ => return Some("heat_ledger: present in one state only".into()),
    }
    f("time_s", a.time_s, b.time_s)
        .or_else(|| f("dt_s", a.dt_s, b.dt_s))
        .or_else(|| scalars("particles.radius_m", &p.radius_m, &q.radius_m))
        .or_else(|| scalars("particles.mass_kg", &p.mass_kg, &q.mass_kg))
        .or_else(|| scalars("particles.inertia_kg_m2", &p.inertia_kg_m2, &q.inertia_kg_m2))
        .or_else(|| vectors("particles.position_m", &p.position_m, &q.position_m))
        .or_else(|| vectors("particles.velocity_m_per_s", &p.velocity_m_per_s, &q.velocity_m_per_s))
        .or_else(|| {
            vectors(
                "particles.angular_velocity_rad_per_s",
                &p.angular_velocity_rad_per_s,
                &q.angular_velocity_rad_per_s,
            )
        })
        .or_else(|| vectors("particles.force_n", &p.force_n, &q.force_n))
        .or_else(|| vectors("particles.torque_n_m", &p.torque_n_m, &q.torque_n_m))
        .or_else(|| scalars("wall_angle_rad", &a.wall_angle_rad, &b.wall_angle_rad))
        .or_else(|| {
            a.contacts
                .pairs
                .iter()
                .zip(&b.contacts.pairs)
                .enumerate()
                .find_map(|(k, (x, y))| {
                    if (x.0, x.1) != (y.0, y.1) {
                        return Some(format!(
                            "contacts.pairs[{k}]: key ({}, {}) vs ({}, {})",
                            x.0.0, x.1.0, y.0.0, y.1.0
                        ));
                    }
                    history(&format!("contacts.pairs[{k}] ({}, {})", x.0.0, x.1.0), &x.2, &y.2)
                })
        })
        .or_else(|| {
            a.contacts
                .walls
                .iter()
                .zip(&b.contacts.walls)
                .enumerate()
                .find_map(|(k, (x, y))| {
                    if (x.0, x.1) != (y.0, y.1) {
                        return Some(format!(
                            "contacts.walls[{k}]: key ({}, {}) vs ({}, {})",
                            x.0.0, x.1.0, y.0.0, y.1.0
                        ));
                    }
                    history(&format!("contacts.walls[{k}] ({}, wall {})", x.0.0, x.1.0), &x.2, &y.2)
                })
        })
        .or_else(|| scalars("particles.liquid_m3", &p.liquid_m3, &q.liquid_m3))
        .or_else(|| scalars("particles.sprayed_m3", &p.sprayed_m3, &q.sprayed_m3))
        .or_else(|| scalars("particles.temperature_k", &p.temperature_k, &q.temperature_k))
        .or_else(|| {
            CHANNELS
                .iter()
                .find_map(|info| scalars(info.path, (info.get)(&p.channels), (info.get)(&q.channels)))
        })
}
