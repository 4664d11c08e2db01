//! The text of `granflow models`: every model name a scenario can use, with its parameters and units. Kept next to
//! the enums it describes by a test that parses every example below.

pub const MODELS: &str = r#"contact.normal (one of):
  linear_spring_dashpot: { stiffness_n_per_m, damping_kg_per_s }       seed 001 eq. 6.16, seed 002 eq. 21
  hertz: { restitution }                                                 Hertz + Tsuji viscoelastic damping (LIGGGHTS)
  thornton: { plastic_slope: continuous | seed_printed }                 seed 000 eqs. 2.3-2.9; species.yield_force_n
contact.tangential (one of):
  linear_spring_coulomb: { stiffness_n_per_m, damping_kg_per_s }       seed 001 eqs. 6.20-6.24, seed 002 eq. 22
  linear_step_spring_coulomb: { stiffness_n_per_m, damping_kg_per_s }  seed 001 eq. 6.24 read literally: spring
                                                                         on this step's Δt v_t only (no static
                                                                         friction)
  mindlin                                                                k_t = 8 G* a, LIGGGHTS tangential history
  walton_braun: { exponent }                                             seed 000 eqs. 2.10-2.13 (exponent default 1/3)
contact.rolling (optional, default none):
  none
  constant_directional_torque                                            M = mu_r R* F_n; species.rolling_friction_coefficient
cohesion (optional, one of):
  liquid_bridge: { surface_tension_n_per_m, viscosity_pa_s?, min_gap_m? }  seed 000 eqs. 2.16-2.20, 6.1-6.44;
                 { ..., spray?, capillary_force?, walls? }               species.liquid_content, contact_angle_deg;
                                                                         capillary_force: auto (Mikami for equal
                                                                         beads at θ = 0, else the Young-Laplace
                                                                         table) or young_laplace; walls default false
  hamaker: { constant_j, inner_cutoff_m, outer_cutoff_m, walls? }        seed 001 eqs. 6.34-6.37
  square_well: { depth_j, outer_to_inner_radius_ratio, walls? }          seed 001 eqs. 3.6-3.11 as impulses
species: { name, radius_m, density_kg_per_m3, youngs_modulus_pa, poisson_ratio, friction_coefficient,
           yield_force_n?, rolling_friction_coefficient?, thermal_conductivity_w_per_m_k?, heat_capacity_j_per_kg_k?,
           contact_angle_deg?, liquid_content? }
walls (list of):
  box: { species }                                                       planes on every non-periodic face
  plane: { name, species, point_m, normal }
  drum: { name, species, axis_point_m, axis, radius_m, rotation_rpm, baffles: [...] }
    baffles: traditional: { count, length_m, half_thickness_m, tilt_deg }
             axial: { count, length_m, half_thickness_m, inner_radius_m }
             segment: { start_m, end_m, half_thickness_m }
gravity: { vector_m_per_s2, flip?: { axis: x|y|z, frequency_hz } }       flip: seed 000 zig-zag chute
fill (list of):
  lattice: { species, spacing_m, lo_m, hi_m, origin_m?, inside_drum? }
  random: { species, count, lo_m, hi_m, inside_drum? }
time: { end_time_s, dt_s | dt_fraction_of_contact_time, reference_velocity_m_per_s? }
"#;

#[cfg(test)]
mod tests {
    use super::MODELS;
    use crate::engine::models::cohesion_law::CohesionModel;
    use crate::engine::models::{ContactLaw, NormalModel, PlasticSlope, RollingModel, TangentialModel};

    /// Every model the enums define is listed, under the name the YAML and checkpoints use, and the listed forms
    /// parse.
    #[test]
    fn every_model_is_listed_and_its_form_parses() {
        let normals = [
            NormalModel::LinearSpringDashpot {
                stiffness_n_per_m: 800.0,
                damping_kg_per_s: 1e-3,
            },
            NormalModel::Hertz { restitution: 0.9 },
            NormalModel::Thornton {
                plastic_slope: PlasticSlope::Continuous,
            },
        ];
        let tangentials = [
            TangentialModel::LinearSpringCoulomb {
                stiffness_n_per_m: 800.0,
                damping_kg_per_s: 1e-3,
            },
            TangentialModel::LinearStepSpringCoulomb {
                stiffness_n_per_m: 800.0,
                damping_kg_per_s: 1e-3,
            },
            TangentialModel::Mindlin,
            TangentialModel::WaltonBraun { exponent: 1.0 / 3.0 },
        ];
        let rollings = [RollingModel::None, RollingModel::ConstantDirectionalTorque];
        for name in normals
            .iter()
            .map(|m| m.name())
            .chain(tangentials.iter().map(|m| m.name()))
            .chain(rollings.iter().map(|m| m.name()))
        {
            assert!(MODELS.contains(name), "`granflow models` does not list {name}");
        }
        for yaml in [
            "{ normal: { linear_spring_dashpot: { stiffness_n_per_m: 800.0, damping_kg_per_s: 0.001 } }, tangential: { linear_spring_coulomb: { stiffness_n_per_m: 800.0, damping_kg_per_s: 0.001 } } }",
            "{ normal: { hertz: { restitution: 0.9 } }, tangential: mindlin, rolling: constant_directional_torque }",
            "{ normal: { thornton: { plastic_slope: seed_printed } }, tangential: { walton_braun: { exponent: 0.5 } }, rolling: none }",
        ] {
            let de = serde_norway::Deserializer::from_str(yaml);
            let law: ContactLaw =
                serde_norway::with::singleton_map_recursive::deserialize(de).unwrap_or_else(|e| panic!("{yaml}: {e}"));
            for name in law.model_names() {
                assert!(MODELS.contains(name));
            }
        }
        for yaml in [
            "liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.001, min_gap_m: 1.0e-5 }",
            "liquid_bridge: { surface_tension_n_per_m: 0.072, capillary_force: young_laplace, walls: true }",
            "hamaker: { constant_j: 1.0e-18, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-4, walls: false }",
            "square_well: { depth_j: 1.0e-10, outer_to_inner_radius_ratio: 1.01, walls: true }",
        ] {
            let de = serde_norway::Deserializer::from_str(yaml);
            let model: CohesionModel =
                serde_norway::with::singleton_map_recursive::deserialize(de).unwrap_or_else(|e| panic!("{yaml}: {e}"));
            assert!(MODELS.contains(&format!("  {}: {{", model.name())));
        }
    }
}
