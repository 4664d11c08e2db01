//! The text of `granflow models`: every model name a scenario can use, with its parameters and units, then every
//! per-job metric a campaign can ask for. The models are written out here and kept next to the enums they describe
//! by tests that parse every example and find every variant; the metrics are generated from their table
//! (`crate::campaign::metrics`).

use crate::campaign::metrics::JobMetric;

/// The width the metric descriptions are wrapped to, as the hand-written lines above them.
const WIDTH: usize = 118;

/// The whole text of `granflow models`.
pub fn text() -> String {
    let mut out = String::from(MODELS);
    out.push_str("metrics (campaign files' `metrics:`; per job, stored with their units):\n");
    for metric in JobMetric::ALL {
        let needs: Vec<&str> = metric.needs().iter().map(|n| n.label()).collect();
        out.push_str(&format!("  {} [{}]", metric.name(), metric.unit()));
        if !needs.is_empty() {
            out.push_str(&format!("  needs {}", needs.join(", ")));
        }
        out.push('\n');
        out.push_str(&wrapped(metric.description(), "      ", WIDTH));
    }
    out
}

/// `text` in lines of at most `width` characters (a longer word stays whole), each starting with `indent`.
fn wrapped(text: &str, indent: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && indent.chars().count() + line.chars().count() + 1 + word.chars().count() > width {
            out.push_str(&format!("{indent}{line}\n"));
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        out.push_str(&format!("{indent}{line}\n"));
    }
    out
}

/// The models part of the text, written by hand.
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
                 { ..., spray?, capillary_force?, walls?,                species.liquid_content, contact_angle_deg;
                   bridges_from_s?, bridge_volume?, viscous_radius? }    capillary_force: auto (Mikami for equal
                                                                         beads at θ = 0, else the Young-Laplace
                                                                         table), young_laplace or
                                                                         mikami_as_printed (F = 2πRγ F̂(S/2R));
                                                                         viscous_radius: effective (R*) or
                                                                         as_printed (2R*); bridge_volume: caps
                                                                         (eqs 6.1-6.4) or { fixed: V/R³ };
                                                                         walls default false
                                                                         (bridges to walls: the sphere-plane
                                                                         Young-Laplace table)
  hamaker: { constant_j, inner_cutoff_m, outer_cutoff_m, walls? }        seed 001 eqs. 6.34-6.37
  square_well: { depth_j, outer_to_inner_radius_ratio, walls? }          seed 001 eqs. 3.6-3.11 as impulses
species: { name, material?, radius_m, density_kg_per_m3, youngs_modulus_pa, poisson_ratio, friction_coefficient,
           yield_force_n?, rolling_friction_coefficient?, real_youngs_modulus_pa?, thermal_conductivity_w_per_m_k?,
           heat_capacity_j_per_kg_k?, contact_angle_deg?, liquid_content? }
  material: glass | steel | aluminium                                    seed 000 Table 7; fills what is not given
                                                                         (a youngs_modulus_pa given beside it is
                                                                         the softened one, the material's the real)
walls (list of):
  box: { species }                                                       planes on every non-periodic face
  plane: { name, species, point_m, normal }
  drum: { name, species, axis_point_m, axis, radius_m, rotation_rpm, baffles: [...] }
    baffles: traditional: { count, length_m, half_thickness_m, tilt_deg }
             axial: { count, length_m, half_thickness_m, inner_radius_m }
             segment: { start_m, end_m, half_thickness_m }
gravity: { vector_m_per_s2, flip?: { axis: x|y|z, frequency_hz } }       flip: seed 000 zig-zag chute
fill (list of):
  lattice: { species, spacing_m, lo_m, hi_m, origin_m?, inside_drum?, jitter_m?, temperature_k? }
  random: { species, count, lo_m, hi_m, inside_drum?, temperature_k? }
  explicit: { species, positions_m, velocities_m_per_s?, angular_velocities_rad_per_s?, temperature_k? }
time: { end_time_s, dt_s | dt_fraction_of_contact_time, reference_velocity_m_per_s? }
heat (optional: particle temperatures and conduction, seed 000 chapter 5):
     { initial_temperature_k, walls?: { <wall name>: { temperature_k, from_s? } | { adiabatic: true } },
       soft_contact_correction? }                                        Q = 2 R_c k_s ΔT (eqs. 5.3-5.4), R_c the
                                                                         Hertz radius, k_s the harmonic mean; walls
                                                                         not listed are adiabatic; the correction
                                                                         (default on) scales R_c by
                                                                         (E*_sim/E*_real)^(1/5)
  gas?: { conductivity_w_per_m_k?, heat_capacity_j_per_kg_k?, nusselt?,  with a gas: eq. 5.8 on the grid and
          initial_temperature_k?, inlet_temperature_k?,                  Q_f = h_gp S_p (T_gas - T_p), eq. 5.5;
          jet_temperatures_k?, lens_conduction? }                        defaults: Table 7's air
    lens_conduction: { lens_radius_fraction?, min_gap_m? }               gas between nearly touching surfaces,
                                                                         H = k_g ∫ 2πr dr/max(gap, s) over a lens
                                                                         of (1+f)R (Rong & Horio 1999, MFIX's
                                                                         PFP; defaults f 0.2, s 4e-10 m); pairs
                                                                         and heated walls; off by default
    nusselt: seed000: { coefficient? } (default, 1.8)                    eqs. 5.6-5.7
             ranz_marshall                                               Nu = 2 + 0.6 Re^1/2 Pr^1/3
             gunn                                                        Gunn (1978), beds
drying (optional, with heat and a gas: evaporation, seed 000 chapter 7):
     { evaporation_coefficient, latent_heat_j_per_kg?,                   m = α π d² (p_sat(T) - p_v) √(M/(2πRT))
       liquid_density_kg_per_m3?, initial_relative_humidity?,            (eq. 7.2), p_sat water's (eq. 7.4), from
       inlet_relative_humidity? }                                        film and bridge shares; vapour a gas
                                                                         scalar (eqs. 7.5-7.6); latent heat
                                                                         (eq. 7.12); defaults: water, dry gas
gas (optional: a gas coupled to the particles, fluidized beds):
     { vacuum?, density_kg_per_m3, viscosity_pa_s, cells: [nx, ny, nz], dem_steps_per_gas_step, sides?, jets?, blocked?,
       outside_drum?,
       drag?, drag_velocities?, drag_coupling?, drag_update?, porosity?, min_porosity?, convection?, solver?,
       inflow_ramp?, inflow_levels?, pressure_probe_height_m? }
  sides: { x_low?, x_high?, y_low?, y_high?, z_low?, z_high? }, each one of:
    wall                                                                 no-slip (default where not periodic)
    periodic                                                             exactly where domain.periodic is
    outlet                                                               zero gradient, pressure 0
    inlet: { superficial_velocity_m_per_s }                              uniform inflow (a distributor)
  jets (list of): { side, lo_m, hi_m, superficial_velocity_m_per_s }     faces of a side in a box (seed 002's jet)
  blocked (list of): { lo_m, hi_m }                                      cells outside the gas
  outside_drum: <drum name>                                              a kiln: cells outside the drum are
                                                                         blocked, their walls turn with it
  drag (default di_felice):
    di_felice                                                            seed 000 eqs. 2.71-2.73
    ergun_wen_yu                                                         seed 000 eq. 2.69 (eps^-2.65, C_d 0.44)
    ergun_wen_yu_seed002                                                 seed 002 eqs. 29-31 (eps^-2.7, C_d 0.43)
    syamlal_o_brien                                                      seed 001 eqs. 6.4-6.9
  drag_velocities: instantaneous (default) | cell_averaged               seed 002 §3.3 methods 2 and 1
  drag_coupling: explicit (default) | semi_implicit                      the gas's share of the drag
  drag_update: every_dem_step (default) | every_gas_step                 K, u(x_p), ∇p held over a gas step (CFDEM)
  porosity: volume_split (default) | centre_binning                      particle volume into cells
  convection: upwind (default) | hybrid
  solver: { relax_velocity, relax_pressure, max_outer_iterations, mass_tolerance, velocity_tolerance,
            linear_tolerance, max_linear_iterations, pressure_solver: auto (default) | direct | conjugate_gradient,
            pressure_velocity: simple (default) | { piso: { correctors: 2 } } }
  inflow_ramp: { start_s, duration_s? }                                  off until start_s, then linear to full
  inflow_levels: { start_s?, hold_s, factors }                           held levels (seed 001's gas cycle)
"#;

#[cfg(test)]
mod tests {
    use super::{MODELS, text, wrapped};
    use crate::campaign::metrics::JobMetric;

    /// Every metric of the table is listed with its unit, what it needs and its whole description.
    #[test]
    fn every_metric_is_listed_with_its_unit_and_description() {
        let text = text();
        let metrics = &text[text.find("\nmetrics (").expect("a metrics section")..];
        for metric in JobMetric::ALL {
            let head = format!("\n  {} [{}]", metric.name(), metric.unit());
            let at = metrics.find(&head).unwrap_or_else(|| panic!("{head} is not listed"));
            // The entry runs to the next metric's line (two spaces in; its description lines have six).
            let rest = &metrics[at + head.len()..];
            let end = rest
                .match_indices("\n  ")
                .find(|(i, _)| !rest[i + 3..].starts_with(' '))
                .map_or(rest.len(), |(i, _)| i);
            let entry = &rest[..end];
            let words: Vec<&str> = entry.split_whitespace().collect();
            let description: Vec<&str> = metric.description().split_whitespace().collect();
            assert!(
                words.windows(description.len()).any(|w| w == description.as_slice()),
                "{}: {entry}",
                metric.name()
            );
            for need in metric.needs() {
                assert!(entry.contains(need.label()), "{}: {entry}", metric.name());
            }
        }
        for line in metrics.lines() {
            assert!(line.chars().count() <= super::WIDTH, "too long: {line}");
        }
    }

    #[test]
    fn wrapping_keeps_every_word_and_the_width() {
        let text = "a bb ccc dddd eeeee ffffff";
        let out = wrapped(text, "  ", 10);
        assert_eq!(out, "  a bb ccc\n  dddd\n  eeeee\n  ffffff\n");
        assert!(out.lines().all(|l| l.chars().count() <= 10));
        assert_eq!(wrapped("", "  ", 10), "");
    }
    use crate::engine::models::cohesion_law::CohesionModel;
    use crate::engine::models::{ContactLaw, NormalModel, PlasticSlope, RollingModel, TangentialModel};

    /// The names a closed choice of the scenario takes in YAML, read from its JSON Schema (plain strings and
    /// single-key maps alike).
    fn variant_names(schema: &serde_json::Value) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(values) = schema.get("enum").and_then(|v| v.as_array()) {
            out.extend(values.iter().filter_map(|v| v.as_str().map(String::from)));
        }
        if let Some(c) = schema.get("const").and_then(|v| v.as_str()) {
            out.push(c.to_string());
        }
        for key in ["oneOf", "anyOf"] {
            for alternative in schema.get(key).and_then(|v| v.as_array()).into_iter().flatten() {
                out.extend(variant_names(alternative));
                if let Some(props) = alternative.get("properties").and_then(|v| v.as_object())
                    && alternative
                        .get("required")
                        .and_then(|r| r.as_array())
                        .is_some_and(|r| r.len() == 1)
                {
                    out.extend(props.keys().cloned());
                }
            }
        }
        out
    }

    /// Every gas choice (drag laws, drag velocities and coupling, porosity methods, convection, pressure solvers,
    /// side kinds) is listed under its YAML name, as are the inflow ramp and levels.
    #[test]
    fn every_gas_choice_is_listed() {
        use crate::engine::gas::Convection;
        use crate::engine::gas::coupling::PorosityMethod;
        use crate::engine::gas::fluid_forces::{DragCoupling, DragVelocities};
        use crate::engine::gas::linsolve::PressureSolver;
        use crate::engine::models::drag::DragLaw;
        use crate::scenario::gas::SideSpec;
        let schemas = [
            serde_json::to_value(schemars::schema_for!(DragLaw)).unwrap(),
            serde_json::to_value(schemars::schema_for!(DragVelocities)).unwrap(),
            serde_json::to_value(schemars::schema_for!(DragCoupling)).unwrap(),
            serde_json::to_value(schemars::schema_for!(crate::engine::gas::held_drag::DragUpdate)).unwrap(),
            serde_json::to_value(schemars::schema_for!(PorosityMethod)).unwrap(),
            serde_json::to_value(schemars::schema_for!(Convection)).unwrap(),
            serde_json::to_value(schemars::schema_for!(PressureSolver)).unwrap(),
            serde_json::to_value(schemars::schema_for!(SideSpec)).unwrap(),
        ];
        let gas = &MODELS[MODELS.find("\ngas (optional").expect("a gas section")..];
        let mut listed = 0;
        for schema in &schemas {
            let names = variant_names(schema);
            assert!(names.len() >= 2, "no variants read from {schema}");
            for name in names {
                let as_word = |w: &str| {
                    gas.match_indices(w).any(|(i, _)| {
                        let before = gas[..i]
                            .chars()
                            .next_back()
                            .is_none_or(|c| !c.is_alphanumeric() && c != '_');
                        let after = gas[i + w.len()..]
                            .chars()
                            .next()
                            .is_none_or(|c| !c.is_alphanumeric() && c != '_');
                        before && after
                    })
                };
                assert!(
                    as_word(&name),
                    "`granflow models` does not list the gas choice `{name}`"
                );
                listed += 1;
            }
        }
        assert!(listed >= 18, "{listed}");
        for key in [
            "inflow_ramp",
            "inflow_levels",
            "jets",
            "blocked",
            "dem_steps_per_gas_step",
        ] {
            assert!(gas.contains(key), "{key}");
        }
    }

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
            "liquid_bridge: { surface_tension_n_per_m: 0.072, capillary_force: mikami_as_printed, viscous_radius: as_printed, bridge_volume: { fixed: 0.02 } }",
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
