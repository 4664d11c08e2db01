//! Evaporation of a particle's liquid into the gas (seed 000 §7.1): the Hertz–Knudsen rate (eq. 7.2), water's
//! saturation pressure (eq. 7.4) and the diffusivity of water vapour in air (eq. 7.6), as pure functions.
//!
//! ṁ_f = −α π d² (p_sat(T) − p_v) √(M_w/(2π R T)) is the mass a particle of diameter d at temperature T gains (a
//! negative value: loses) against vapour at partial pressure p_v; α, the evaporation coefficient, is a parameter
//! (the seed gives no value). The engine's drying step ([`crate::engine::drying`]) takes the rate implicitly in the
//! vapour and the particle's temperature, with these functions' values and the derivative of p_sat.

use std::f64::consts::PI;

/// The universal gas constant R, J/(mol K) (seed 000 §7.1.1: 8.3145).
pub const GAS_CONSTANT_J_PER_MOL_K: f64 = 8.3145;

/// Water's molar mass M_w, kg/mol (seed 000 §7.1.1: 0.018).
pub const WATER_MOLAR_MASS_KG_PER_MOL: f64 = 0.018;

/// One normal atmosphere p0, Pa (eq. 7.6).
pub const NORMAL_ATMOSPHERE_PA: f64 = 101_325.0;

/// 0 °C in kelvin.
const ZERO_CELSIUS_K: f64 = 273.15;

/// 1 mmHg in Pa: eq. 7.4's factor 133.322.
const MMHG_PA: f64 = 133.322;

/// Water's saturation vapour pressure at `temperature_k`, Pa (seed 000 eq. 7.4):
/// p_sat = 133.322 × 10^(0.6715 + 0.030 t − 0.0000798 t²), t = T − 273.15 in °C.
#[inline]
pub fn saturation_pressure_pa(temperature_k: f64) -> f64 {
    let t = temperature_k - ZERO_CELSIUS_K;
    MMHG_PA * 10f64.powf(0.6715 + 0.030 * t - 0.0000798 * t * t)
}

/// dp_sat/dT of eq. 7.4 at `temperature_k`, Pa/K: p_sat ln 10 (0.030 − 2 × 0.0000798 t).
#[inline]
pub fn saturation_pressure_slope_pa_per_k(temperature_k: f64) -> f64 {
    let t = temperature_k - ZERO_CELSIUS_K;
    saturation_pressure_pa(temperature_k) * std::f64::consts::LN_10 * (0.030 - 2.0 * 0.0000798 * t)
}

/// The Hertz–Knudsen conductance of a particle of diameter `diameter_m` at `temperature_k`, kg/(s Pa):
/// α π d² √(M/(2π R T)), so that the evaporation rate is this times p_sat(T) − p_v (eq. 7.2).
#[inline]
pub fn hertz_knudsen_conductance_kg_per_s_pa(
    evaporation_coefficient: f64,
    diameter_m: f64,
    temperature_k: f64,
    molar_mass_kg_per_mol: f64,
) -> f64 {
    evaporation_coefficient
        * PI
        * diameter_m
        * diameter_m
        * (molar_mass_kg_per_mol / (2.0 * PI * GAS_CONSTANT_J_PER_MOL_K * temperature_k)).sqrt()
}

/// The partial pressure of vapour of density `vapour_density_kg_per_m3` at `temperature_k` (an ideal gas), Pa:
/// p_v = ρ_v R T / M.
#[inline]
pub fn vapour_pressure_pa(vapour_density_kg_per_m3: f64, temperature_k: f64, molar_mass_kg_per_mol: f64) -> f64 {
    vapour_density_kg_per_m3 * GAS_CONSTANT_J_PER_MOL_K * temperature_k / molar_mass_kg_per_mol
}

/// The density of saturated vapour at `temperature_k`, kg/m³: p_sat M/(R T).
#[inline]
pub fn saturated_vapour_density_kg_per_m3(temperature_k: f64, molar_mass_kg_per_mol: f64) -> f64 {
    saturation_pressure_pa(temperature_k) * molar_mass_kg_per_mol / (GAS_CONSTANT_J_PER_MOL_K * temperature_k)
}

/// The diffusivity of water vapour in air at `temperature_k` and pressure `pressure_pa`, m²/s (seed 000 eq. 7.6,
/// Bird, Stewart & Lightfoot): D_g = 1.87e−10 T^2.072 p0/p.
#[inline]
pub fn vapour_diffusivity_m2_per_s(temperature_k: f64, pressure_pa: f64) -> f64 {
    1.87e-10 * temperature_k.powf(2.072) * NORMAL_ATMOSPHERE_PA / pressure_pa
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturation_pressure_matches_steam_tables_within_two_per_cent() {
        // Steam tables: 3169.9 Pa at 25 °C, 12352 Pa at 50 °C, 101418 Pa at 100 °C.
        for (t_c, table_pa) in [(25.0, 3169.9), (50.0, 12_352.0), (100.0, 101_418.0)] {
            let p = saturation_pressure_pa(t_c + 273.15);
            assert!((p / table_pa - 1.0).abs() < 0.02, "{t_c} °C: {p} Pa against {table_pa}");
        }
    }

    #[test]
    fn the_slope_is_the_derivative_of_the_saturation_pressure() {
        for t in [280.0, 298.15, 330.0, 373.15] {
            let h = 1e-4;
            let numeric = (saturation_pressure_pa(t + h) - saturation_pressure_pa(t - h)) / (2.0 * h);
            let slope = saturation_pressure_slope_pa_per_k(t);
            assert!((slope / numeric - 1.0).abs() < 1e-8, "{t} K: {slope} against {numeric}");
        }
    }

    #[test]
    fn hertz_knudsen_flux_of_water_at_25_celsius() {
        // α = 1, d = 3 mm: √(M/(2πRT)) = 1.0748e-3 s/m at 298.15 K, so 3.0396e-8 kg/(s Pa).
        let g = hertz_knudsen_conductance_kg_per_s_pa(1.0, 3e-3, 298.15, WATER_MOLAR_MASS_KG_PER_MOL);
        let expected = PI * 9e-6 * (0.018 / (2.0 * PI * 8.3145 * 298.15)).sqrt();
        assert!((g / expected - 1.0).abs() < 1e-15);
        assert!((g / 3.0396e-8 - 1.0).abs() < 1e-3, "{g}");
    }

    #[test]
    fn vapour_diffusivity_in_air_near_room_temperature() {
        // 2.5e-5 m²/s at 25 °C and 1 atm (Bird, Stewart & Lightfoot give 2.6e-5 at 298 K).
        let d = vapour_diffusivity_m2_per_s(298.15, NORMAL_ATMOSPHERE_PA);
        assert!((d - 2.5e-5).abs() < 0.1e-5, "{d}");
        assert!((vapour_diffusivity_m2_per_s(298.15, 2.0 * NORMAL_ATMOSPHERE_PA) / d - 0.5).abs() < 1e-15);
    }

    #[test]
    fn saturated_vapour_density_inverts_the_vapour_pressure() {
        let t = 320.0;
        let rho = saturated_vapour_density_kg_per_m3(t, WATER_MOLAR_MASS_KG_PER_MOL);
        let p = vapour_pressure_pa(rho, t, WATER_MOLAR_MASS_KG_PER_MOL);
        assert!((p / saturation_pressure_pa(t) - 1.0).abs() < 1e-14);
    }
}
