//! The `drying` section (seed 000 chapter 7): validation at its keys, and the engine's drying model and vapour
//! field (`engine::drying`).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::ConfigError;
use super::gas::GasSetup;
use super::spec::ScenarioSpec;
use crate::engine::drying::DryingConfig;
use crate::engine::gas::{GasScalarSpec, ScalarExchange, ScalarWall};
use crate::engine::models::evaporation::{
    NORMAL_ATMOSPHERE_PA, WATER_MOLAR_MASS_KG_PER_MOL, saturated_vapour_density_kg_per_m3, vapour_diffusivity_m2_per_s,
};

/// Evaporation of the particles' liquid (water: its saturation pressure is seed 000's eq. 7.4) into the gas.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DryingSpec {
    /// α of the Hertz–Knudsen rate (seed 000 eq. 7.2), 0 < α ≤ 1; required (the seed gives no value; measured
    /// values for water range from about 0.01 to 1).
    pub evaporation_coefficient: f64,
    /// Latent heat of vaporisation H (eq. 7.12), J/kg (default 2.26e6: water at 100 °C; 2.44e6 at 25 °C).
    #[serde(default = "water_latent_heat", skip_serializing_if = "is_water_latent_heat")]
    pub latent_heat_j_per_kg: f64,
    /// The liquid's density ρ_l, kg/m³ (default 1000: water); liquid contents and bridges are volumes.
    #[serde(default = "water_density", skip_serializing_if = "is_water_density")]
    pub liquid_density_kg_per_m3: f64,
    /// The gas's relative humidity at the start, p_v/p_sat at its initial temperature, 0 to 1 (default 0: dry, as
    /// seed 000 §7.3).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub initial_relative_humidity: f64,
    /// The relative humidity of the gas entering through inlet sides and jets, at the inlet temperature, 0 to 1
    /// (default 0: dry).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub inlet_relative_humidity: f64,
}

fn water_latent_heat() -> f64 {
    2.26e6
}

fn is_water_latent_heat(x: &f64) -> bool {
    *x == water_latent_heat()
}

fn water_density() -> f64 {
    1000.0
}

fn is_water_density(x: &f64) -> bool {
    *x == water_density()
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Checks the `drying` section against the rest of the scenario (it needs `heat` and a gas that is not switched
/// off), and gives `gas` its vapour field and the drying model. `gas` is `None` in vacuum or without a `gas`.
pub(super) fn build_drying(path: &Path, spec: &ScenarioSpec, gas: Option<&mut GasSetup>) -> Result<(), ConfigError> {
    let Some(drying) = &spec.drying else {
        return Ok(());
    };
    let fail = |key: &str, message: String| ConfigError::invalid(path, key.to_string(), message);
    let alpha = drying.evaporation_coefficient;
    if !(alpha.is_finite() && alpha > 0.0 && alpha <= 1.0) {
        return Err(fail(
            "drying.evaporation_coefficient",
            format!("expected 0 < α ≤ 1 (the fraction of molecules striking the surface that stay), got {alpha}"),
        ));
    }
    for (key, value, unit) in [
        ("latent_heat_j_per_kg", drying.latent_heat_j_per_kg, "J/kg"),
        ("liquid_density_kg_per_m3", drying.liquid_density_kg_per_m3, "kg/m3"),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(fail(
                &format!("drying.{key}"),
                format!("expected a finite value > 0 {unit}, got {value}"),
            ));
        }
    }
    for (key, value) in [
        ("initial_relative_humidity", drying.initial_relative_humidity),
        ("inlet_relative_humidity", drying.inlet_relative_humidity),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(fail(
                &format!("drying.{key}"),
                format!("expected a relative humidity from 0 to 1, got {value}"),
            ));
        }
        if value > 1.0 {
            return Err(fail(
                &format!("drying.{key}"),
                format!(
                    "a relative humidity of {value} is above saturation (p_v > p_sat): expected a value from 0 to 1"
                ),
            ));
        }
    }
    let Some(heat) = &spec.heat else {
        return Err(fail(
            "drying",
            "drying needs heat transfer (a `heat` section): evaporation takes its latent heat from the particles \
             and its rate depends on their temperature"
                .into(),
        ));
    };
    let Some(gas) = gas else {
        let why = if spec.gas.is_some() {
            "the gas is switched off (`gas.vacuum: true`)"
        } else {
            "the scenario has no `gas` section"
        };
        return Err(fail(
            "drying",
            format!("drying needs a gas to carry the vapour away, and {why}"),
        ));
    };
    let (_, temperature) = gas.heat.as_ref().expect("a gas with heat has a temperature field");
    let rho = gas.config.density_kg_per_m3;
    let fraction = |relative_humidity: f64, t: f64| {
        relative_humidity * saturated_vapour_density_kg_per_m3(t, WATER_MOLAR_MASS_KG_PER_MOL) / rho
    };
    let initial_t = heat.gas.initial_temperature_k.unwrap_or(heat.initial_temperature_k);
    let inlet_t = heat.gas.inlet_temperature_k.unwrap_or(initial_t);
    let jet_values = temperature
        .jet_values
        .iter()
        .map(|&t| fraction(drying.inlet_relative_humidity, t))
        .collect();
    gas.drying = Some((
        DryingConfig {
            evaporation_coefficient: alpha,
            latent_heat_j_per_kg: drying.latent_heat_j_per_kg,
            liquid_density_kg_per_m3: drying.liquid_density_kg_per_m3,
            molar_mass_kg_per_mol: WATER_MOLAR_MASS_KG_PER_MOL,
        },
        GasScalarSpec {
            name: crate::engine::drying::VAPOUR_FIELD,
            unit: "kg/kg",
            // Set again at every step from the gas's mean temperature.
            diffusion_kg_per_m_s: rho * vapour_diffusivity_m2_per_s(initial_t, NORMAL_ATMOSPHERE_PA),
            initial_value: fraction(drying.initial_relative_humidity, initial_t),
            inlet_value: fraction(drying.inlet_relative_humidity, inlet_t),
            jet_values,
            walls: [ScalarWall::ZeroFlux; 6],
            exchange: ScalarExchange::Evaporation,
            blocked_value: None,
            fixed_from_s: 0.0,
        },
    ));
    Ok(())
}
