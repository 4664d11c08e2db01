//! The `heat` section: validation at its keys, and the engine's [`HeatConfig`] and initial temperatures.

use std::path::Path;

use super::ConfigError;
use super::build::walls_named;
use super::gas::GasSetup;
use super::spec::ScenarioSpec;
use crate::engine::gas::heat::GasThermal;
use crate::engine::gas::{Boundary, GasScalarSpec, ScalarExchange, ScalarWall};
use crate::engine::geometry::Wall;
use crate::engine::heat::{BridgeConduction, HeatConfig};
use crate::engine::models::PairTable;
use crate::engine::models::cohesion_law::CohesionModel;
use crate::engine::models::gas_lens::GasLens;
use crate::engine::particles::{Particles, SpeciesTable};

/// The run's heat configuration, with `particles.temperature_k` set from the fills (`fill_ends[k]`: one past the
/// last particle of fill k); `None` without a `heat` section. Refuses a temperature that is not above 0 K, a fill
/// temperature without `heat`, a particle species without a conductivity or heat capacity, a wall entry that is
/// neither fixed nor adiabatic, and a time step too long for the explicit temperature update.
#[allow(clippy::too_many_arguments)]
pub(super) fn build_heat(
    path: &Path,
    spec: &ScenarioSpec,
    species: &SpeciesTable,
    walls: &[Wall],
    pair_table: &PairTable,
    fill_ends: &[usize],
    particles: &mut Particles,
    dt_s: f64,
) -> Result<Option<HeatConfig>, ConfigError> {
    let fail = |key: String, message: String| ConfigError::invalid(path, key, message);
    let temperature = |key: String, t: f64| {
        if t.is_finite() && t > 0.0 {
            Ok(())
        } else {
            Err(fail(key, format!("expected an absolute temperature > 0 K, got {t}")))
        }
    };
    let Some(heat) = &spec.heat else {
        if let Some((k, f)) = spec.fill.iter().enumerate().find(|(_, f)| f.temperature_k().is_some()) {
            return Err(fail(
                format!("fill[{k}].{}.temperature_k", f.kind()),
                "an initial temperature needs a `heat` section (heat transfer is off)".into(),
            ));
        }
        return Ok(None);
    };
    temperature("heat.initial_temperature_k".into(), heat.initial_temperature_k)?;
    let k_l = heat.liquid_conductivity_w_per_m_k;
    if !(k_l.is_finite() && k_l > 0.0) {
        return Err(fail(
            "heat.liquid_conductivity_w_per_m_k".into(),
            format!("expected a finite value > 0, got {k_l}"),
        ));
    }
    let core = heat.bed_core_radius_fraction;
    if !(core.is_finite() && core > 0.0 && core <= 1.0) {
        return Err(fail(
            "heat.bed_core_radius_fraction".into(),
            format!("expected 0 < value <= 1 (of the bed centroid's distance to the drum wall), got {core}"),
        ));
    }
    // The gas's properties are checked whether or not the scenario has a gas (a campaign may switch it off).
    let g = &heat.gas;
    // Each (key under `heat.gas`, value) must be finite and > 0.
    let positive = |entries: &[(&str, f64)]| {
        for &(key, value) in entries {
            if !(value.is_finite() && value > 0.0) {
                return Err(fail(
                    format!("heat.gas.{key}"),
                    format!("expected a finite value > 0, got {value}"),
                ));
            }
        }
        Ok(())
    };
    positive(&[
        ("conductivity_w_per_m_k", g.conductivity_w_per_m_k),
        ("heat_capacity_j_per_kg_k", g.heat_capacity_j_per_kg_k),
    ])?;
    g.nusselt
        .check()
        .map_err(|(key, message)| fail(format!("heat.gas.nusselt.{key}"), message))?;
    for (key, t) in [
        ("initial_temperature_k", g.initial_temperature_k),
        ("inlet_temperature_k", g.inlet_temperature_k),
    ] {
        if let Some(t) = t {
            temperature(format!("heat.gas.{key}"), t)?;
        }
    }
    for (k, &t) in g.jet_temperatures_k.iter().enumerate() {
        temperature(format!("heat.gas.jet_temperatures_k[{k}]"), t)?;
    }
    let mut start = 0;
    particles.temperature_k = Vec::with_capacity(particles.len());
    for (k, (f, &end)) in spec.fill.iter().zip(fill_ends).enumerate() {
        let t = match f.temperature_k() {
            Some(t) => {
                temperature(format!("fill[{k}].{}.temperature_k", f.kind()), t)?;
                t
            }
            None => heat.initial_temperature_k,
        };
        particles.temperature_k.extend(std::iter::repeat_n(t, end - start));
        start = end;
    }
    // Every species a particle is made of needs its thermal properties.
    for (k, s) in species.species.iter().enumerate() {
        if !particles.species.iter().any(|id| id.index() == k) {
            continue;
        }
        for (key, value, unit) in [
            (
                "thermal_conductivity_w_per_m_k",
                s.thermal_conductivity_w_per_m_k,
                "W/(m K)",
            ),
            ("heat_capacity_j_per_kg_k", s.heat_capacity_j_per_kg_k, "J/(kg K)"),
        ] {
            if value.is_none() {
                return Err(fail(
                    format!("species[{k}].{key}"),
                    format!(
                        "heat transfer is on and particles are made of '{}': expected its `{key}` in {unit} (or a \
                         `material`: glass, steel, aluminium)",
                        s.name
                    ),
                ));
            }
        }
    }
    let mut wall_temperature_k = vec![None; walls.len()];
    let mut wall_heated_from_s = vec![0.0; walls.len()];
    for (name, condition) in &heat.walls {
        let key = |field: &str| format!("heat.walls.{name}{field}");
        let Some(named) = walls_named(walls, name) else {
            let names: Vec<&str> = walls.iter().map(|w| w.name.as_str()).collect();
            return Err(fail(
                key(""),
                format!("no wall named '{name}'; the walls are: {}", names.join(", ")),
            ));
        };
        match (condition.temperature_k, condition.adiabatic) {
            (Some(t), false) => {
                temperature(key(".temperature_k"), t)?;
                if !(condition.from_s.is_finite() && condition.from_s >= 0.0) {
                    return Err(fail(
                        key(".from_s"),
                        format!("expected a time >= 0 s, got {}", condition.from_s),
                    ));
                }
                for w in named {
                    wall_temperature_k[w] = Some(t);
                    wall_heated_from_s[w] = condition.from_s;
                }
            }
            (None, true) => {}
            (Some(_), true) => {
                return Err(fail(
                    key(""),
                    "a wall is either at a fixed `temperature_k` or `adiabatic: true`, not both".into(),
                ));
            }
            (None, false) => {
                return Err(fail(
                    key(""),
                    "expected the wall's `temperature_k` (a heated wall) or `adiabatic: true`".into(),
                ));
            }
        }
    }
    let mut config = HeatConfig::new(
        species,
        pair_table,
        heat.soft_contact_correction,
        wall_temperature_k,
        wall_heated_from_s,
    );
    if let Some(CohesionModel::LiquidBridge(bridge)) = &spec.cohesion {
        // Tables for the species particles are made of, and for the walls they can bridge to.
        let particle_species: Vec<usize> = (0..species.len())
            .filter(|&k| particles.species.iter().any(|id| id.index() == k))
            .collect();
        let mut wall_species: Vec<usize> = if bridge.walls {
            walls.iter().map(|w| w.species.index()).collect()
        } else {
            Vec::new()
        };
        wall_species.sort_unstable();
        wall_species.dedup();
        config.bridges = Some(
            BridgeConduction::new(species, &particle_species, &wall_species, k_l)
                .map_err(|m| fail("cohesion.liquid_bridge".into(), m))?,
        );
    }
    if let Some(lens) = g.lens_conduction {
        positive(&[
            ("lens_conduction.lens_radius_fraction", lens.lens_radius_fraction),
            ("lens_conduction.min_gap_m", lens.min_gap_m),
        ])?;
        if lens.min_gap_m >= particles.max_radius_m().max(f64::MIN_POSITIVE) {
            return Err(fail(
                "heat.gas.lens_conduction.min_gap_m".into(),
                format!(
                    "expected a gap well below the particles' radius ({} m), got {} m",
                    particles.max_radius_m(),
                    lens.min_gap_m
                ),
            ));
        }
        // The lens is gas: without one (no `gas`, or `gas.vacuum`) there is nothing to conduct through.
        if spec.gas.as_ref().is_some_and(|gas| !gas.vacuum) {
            config = config.with_lens(
                GasLens {
                    gas_conductivity_w_per_m_k: g.conductivity_w_per_m_k,
                    lens_radius_fraction: lens.lens_radius_fraction,
                    min_gap_m: lens.min_gap_m,
                },
                particles.max_radius_m(),
            );
        }
    }
    let rate_per_s = config.fastest_relaxation_per_s(particles, spec.max_overlap_fraction);
    if dt_s * rate_per_s >= 1.0 {
        return Err(fail(
            "time".into(),
            format!(
                "the time step {dt_s:.3e} s is too long for the explicit temperature update: the most conductive \
                 contacts could relax a particle's temperature at up to {rate_per_s:.3e} 1/s, which needs dt < \
                 {:.3e} s",
                1.0 / rate_per_s
            ),
        ));
    }
    Ok(Some(config))
}

/// The gas's temperature field and convection for a run with heat transfer and a gas (`gas` is changed in place;
/// the properties were checked by [`build_heat`]):
/// Γ = k_g/c_g, the walls of the gas grid that are box walls held at a temperature heat the gas, inlets and jets
/// carry their temperatures.
pub(super) fn build_gas_heat(path: &Path, spec: &ScenarioSpec, gas: &mut GasSetup) -> Result<(), ConfigError> {
    let Some(heat) = &spec.heat else {
        return Ok(());
    };
    let fail = |key: &str, message: String| ConfigError::invalid(path, format!("heat.gas.{key}"), message);
    let g = &heat.gas;
    let initial = g.initial_temperature_k.unwrap_or(heat.initial_temperature_k);
    let inlet = g.inlet_temperature_k.unwrap_or(initial);
    let jets = gas.jet_face_ends.len();
    if !g.jet_temperatures_k.is_empty() && g.jet_temperatures_k.len() != jets {
        return Err(fail(
            "jet_temperatures_k",
            format!(
                "expected one temperature per entry of gas.jets ({jets}), got {}",
                g.jet_temperatures_k.len()
            ),
        ));
    }
    // (The values were checked by `build_heat`.) Each jet face gets its jet's temperature: the faces are listed jet by jet in `inlet_faces`.
    let jet_values = if g.jet_temperatures_k.is_empty() {
        Vec::new()
    } else {
        (0..gas.config.inlet_faces.len())
            .map(|f| g.jet_temperatures_k[gas.jet_face_ends.iter().position(|&end| f < end).unwrap_or(jets - 1)])
            .collect()
    };
    let walls: [ScalarWall; 6] = std::array::from_fn(|s| {
        let name = format!("box_{}_{}", ["x", "y", "z"][s / 2], ["lo", "hi"][s % 2]);
        match (
            gas.config.grid.boundary[s],
            heat.walls.get(&name).and_then(|w| w.temperature_k),
        ) {
            (Boundary::Wall { .. }, Some(value)) => ScalarWall::Fixed { value },
            _ => ScalarWall::ZeroFlux,
        }
    });
    // A kiln's drum (the gas's `outside_drum`) holds the faces of the blocked cells at its temperature. CHOICE: the
    // gas's heated walls act from the earliest `from_s` among them.
    let drum = spec.gas.as_ref().and_then(|g| g.outside_drum.as_ref());
    let blocked_value = drum.and_then(|name| heat.walls.get(name)).and_then(|w| w.temperature_k);
    let fixed_from_s = heat
        .walls
        .iter()
        .filter(|(_, w)| w.temperature_k.is_some())
        .map(|(_, w)| w.from_s)
        .fold(f64::INFINITY, f64::min);
    let fixed_from_s = if fixed_from_s.is_finite() { fixed_from_s } else { 0.0 };
    let thermal = GasThermal {
        conductivity_w_per_m_k: g.conductivity_w_per_m_k,
        heat_capacity_j_per_kg_k: g.heat_capacity_j_per_kg_k,
        nusselt: g.nusselt,
    };
    gas.heat = Some((
        thermal,
        GasScalarSpec {
            name: "temperature_k",
            unit: "K",
            diffusion_kg_per_m_s: g.conductivity_w_per_m_k / g.heat_capacity_j_per_kg_k,
            initial_value: initial,
            inlet_value: inlet,
            jet_values,
            walls,
            exchange: ScalarExchange::Explicit,
            blocked_value,
            fixed_from_s,
        },
    ));
    Ok(())
}
