//! Particles in structure-of-arrays form, their stable identities, and the species (material) table.
//!
//! Hot loops touch one or two fields of many particles at a time (positions in the neighbour search, velocities in
//! the integrator), so each field is its own contiguous array rather than a `Vec<Particle>`. A particle's
//! [`ParticleId`] is stable for the life of a simulation (its fill order) and checkpoints store it; the array index
//! equals the id until the run sorts its particles by place (`engine::particle_order`), after which a particle is
//! found by its id. Contact records are keyed by array index. Per-pair material mixing lives in
//! `models::pair_table`, not here.

use serde::{Deserialize, Serialize};

use super::Vec3;
use super::channels::ParticleChannels;

/// Stable identity of a particle. Never reused within one simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub struct ParticleId(pub u32);

impl ParticleId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Index of a species in the [`SpeciesTable`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub struct SpeciesId(pub u16);

impl SpeciesId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A particle material as the engine uses it: SI units throughout (the scenario's `species` entries, with their
/// contact angle in degrees, are converted in `scenario/build.rs`). Walls are species too (with an infinite radius,
/// see `geometry::walls`).
#[derive(Debug, Clone, PartialEq)]
pub struct Species {
    pub name: String,
    /// Nominal radius of particles created from this species (walls ignore it).
    pub radius_m: f64,
    pub density_kg_per_m3: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    /// Coulomb sliding friction coefficient μ.
    pub friction_coefficient: f64,
    /// Thornton yield force F_y (seed 000 eq. 2.7); `None`: the material never yields.
    pub yield_force_n: Option<f64>,
    /// Rolling-resistance coefficient μ_r for the optional rolling slot (dimensionless).
    pub rolling_friction_coefficient: f64,
    /// Contact angle θ of the cohesion model's liquid on this material, rad.
    pub contact_angle_rad: f64,
    /// Liquid each particle of this species carries at the start, as V̂ = V/R³.
    pub liquid_content: f64,
    /// The real material's Young's modulus where `youngs_modulus_pa` is softened (heat conduction's contact radius
    /// correction), Pa.
    pub real_youngs_modulus_pa: Option<f64>,
    /// Solid thermal conductivity k_s, W/(m K).
    pub thermal_conductivity_w_per_m_k: Option<f64>,
    /// Specific heat capacity c_p, J/(kg K).
    pub heat_capacity_j_per_kg_k: Option<f64>,
}

impl Species {
    /// Shear modulus G = E / (2 (1 + ν)).
    pub fn shear_modulus_pa(&self) -> f64 {
        self.youngs_modulus_pa / (2.0 * (1.0 + self.poisson_ratio))
    }
}

#[cfg(test)]
impl Species {
    /// A dry bead (E = 1e7 Pa, ν = 0.3, μ = 0.3, nothing else set) for unit tests.
    pub fn test_bead(name: &str, radius_m: f64, density_kg_per_m3: f64) -> Species {
        Species {
            name: name.into(),
            radius_m,
            density_kg_per_m3,
            youngs_modulus_pa: 1e7,
            poisson_ratio: 0.3,
            friction_coefficient: 0.3,
            yield_force_n: None,
            rolling_friction_coefficient: 0.0,
            contact_angle_rad: 0.0,
            liquid_content: 0.0,
            real_youngs_modulus_pa: None,
            thermal_conductivity_w_per_m_k: None,
            heat_capacity_j_per_kg_k: None,
        }
    }
}

/// All species of a simulation, indexed by [`SpeciesId`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SpeciesTable {
    pub species: Vec<Species>,
}

impl SpeciesTable {
    pub fn get(&self, id: SpeciesId) -> &Species {
        &self.species[id.index()]
    }

    pub fn find(&self, name: &str) -> Option<SpeciesId> {
        self.species
            .iter()
            .position(|s| s.name == name)
            .map(|i| SpeciesId(i as u16))
    }

    pub fn len(&self) -> usize {
        self.species.len()
    }

    pub fn is_empty(&self) -> bool {
        self.species.is_empty()
    }
}

/// The particle arrays. All `Vec`s have the same length (the channels' columns that length or empty).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Particles {
    pub id: Vec<ParticleId>,
    pub species: Vec<SpeciesId>,
    pub radius_m: Vec<f64>,
    pub mass_kg: Vec<f64>,
    /// Moment of inertia of a solid sphere, (2/5) m r².
    pub inertia_kg_m2: Vec<f64>,
    pub position_m: Vec<Vec3>,
    pub velocity_m_per_s: Vec<Vec3>,
    pub angular_velocity_rad_per_s: Vec<Vec3>,
    /// Contact force of the last force evaluation (without gravity). Part of the state: velocity Verlet's first
    /// half-kick of the next step needs it.
    pub force_n: Vec<Vec3>,
    pub torque_n_m: Vec<Vec3>,
    /// Liquid carried on the particle's surface (not in bridges), m³.
    pub liquid_m3: Vec<f64>,
    /// Liquid the particle has received from the spray since the start, m³ (the liquid ledger's "sprayed" term).
    pub sprayed_m3: Vec<f64>,
    /// Temperature of each (lumped) particle, K; empty in a run without heat transfer (`engine::heat`).
    pub temperature_k: Vec<f64>,
    /// The scalar channels the pair pass adds into (`engine::channels`; empty columns when the run records none).
    pub channels: ParticleChannels,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// Appends a particle at rest made of `species`, with radius `radius_m`, and returns its id.
    pub fn push(&mut self, species_id: SpeciesId, species: &Species, radius_m: f64, position_m: Vec3) -> ParticleId {
        let id = ParticleId(self.id.len() as u32);
        let mass = species.density_kg_per_m3 * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3);
        self.id.push(id);
        self.species.push(species_id);
        self.radius_m.push(radius_m);
        self.mass_kg.push(mass);
        self.inertia_kg_m2.push(0.4 * mass * radius_m * radius_m);
        self.position_m.push(position_m);
        self.velocity_m_per_s.push(Vec3::zeros());
        self.angular_velocity_rad_per_s.push(Vec3::zeros());
        self.force_n.push(Vec3::zeros());
        self.torque_n_m.push(Vec3::zeros());
        self.liquid_m3.push(species.liquid_content * radius_m.powi(3));
        self.sprayed_m3.push(0.0);
        id
    }

    /// The particles in a new order: particle k of the result is particle `order[k]` of these, with its id and
    /// every per-particle array (`engine::particle_order`). `order` must be a permutation of `0..len`.
    pub fn permuted(&self, order: &[usize]) -> Particles {
        fn gather<T: Copy>(column: &[T], order: &[usize]) -> Vec<T> {
            if column.is_empty() {
                Vec::new()
            } else {
                order.iter().map(|&i| column[i]).collect()
            }
        }
        debug_assert_eq!(order.len(), self.len());
        Particles {
            id: gather(&self.id, order),
            species: gather(&self.species, order),
            radius_m: gather(&self.radius_m, order),
            mass_kg: gather(&self.mass_kg, order),
            inertia_kg_m2: gather(&self.inertia_kg_m2, order),
            position_m: gather(&self.position_m, order),
            velocity_m_per_s: gather(&self.velocity_m_per_s, order),
            angular_velocity_rad_per_s: gather(&self.angular_velocity_rad_per_s, order),
            force_n: gather(&self.force_n, order),
            torque_n_m: gather(&self.torque_n_m, order),
            liquid_m3: gather(&self.liquid_m3, order),
            sprayed_m3: gather(&self.sprayed_m3, order),
            temperature_k: gather(&self.temperature_k, order),
            channels: self.channels.permuted(order),
        }
    }

    pub fn max_radius_m(&self) -> f64 {
        self.radius_m.iter().copied().fold(0.0, f64::max)
    }

    /// Translational plus rotational kinetic energy, in J.
    pub fn kinetic_energy_j(&self) -> f64 {
        let mut e = 0.0;
        for i in 0..self.len() {
            e += 0.5 * self.mass_kg[i] * self.velocity_m_per_s[i].norm_squared()
                + 0.5 * self.inertia_kg_m2[i] * self.angular_velocity_rad_per_s[i].norm_squared();
        }
        e
    }

    /// Translational kinetic energy only, in J (what LIGGGHTS' thermo keyword `ke` reports).
    pub fn translational_kinetic_energy_j(&self) -> f64 {
        (0..self.len())
            .map(|i| 0.5 * self.mass_kg[i] * self.velocity_m_per_s[i].norm_squared())
            .sum()
    }

    /// Approximate heap bytes held by the particle arrays.
    pub fn heap_bytes(&self) -> usize {
        let v3 = std::mem::size_of::<Vec3>();
        self.id.capacity() * 4
            + self.species.capacity() * 2
            + (self.radius_m.capacity()
                + self.mass_kg.capacity()
                + self.inertia_kg_m2.capacity()
                + self.liquid_m3.capacity()
                + self.sprayed_m3.capacity()
                + self.temperature_k.capacity())
                * 8
            + (self.position_m.capacity()
                + self.velocity_m_per_s.capacity()
                + self.angular_velocity_rad_per_s.capacity()
                + self.force_n.capacity()
                + self.torque_n_m.capacity())
                * v3
    }
}
