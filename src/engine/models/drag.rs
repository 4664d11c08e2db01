//! Gas–particle drag laws, each giving the coefficient K of the drag on one particle, F = K (u − v), where u is the
//! (interstitial) gas velocity at the particle and v the particle's velocity. This is the whole drag the particle
//! feels (seed 000's ε f_d, eq 2.67; seed 002's ε_g f_di, eq 28); the gas receives −F (Newton's third law), and the
//! momentum-exchange coefficient per unit volume of a cell is β = Σ K / V_cell.
//!
//! Laws (PHYSICS §3): Di Felice (default; seed 000), Ergun/Wen-Yu as in seed 000 eq 2.69 (ε^−2.65, C_d = 0.44 for
//! Re ≥ 1000) and as in seed 002 eqs 29–31 (ε^−2.7, C_d = 0.43), Syamlal-O'Brien (seed 001 eqs 6.4–6.9).

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DragLaw {
    DiFelice,
    ErgunWenYu,
    ErgunWenYuSeed002,
    SyamlalOBrien,
}

/// What a drag law needs to know about one particle and the gas around it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DragInput {
    /// Gas volume fraction ε of the particle's cell (clamped to [0.05, 1] by the laws).
    pub porosity: f64,
    /// |u − v|, m/s.
    pub slip_speed_m_per_s: f64,
    pub diameter_m: f64,
    pub gas_density_kg_per_m3: f64,
    pub gas_viscosity_pa_s: f64,
}

/// Single-sphere drag coefficient of Schiller & Naumann as used by Wen & Yu (seed 000 eq 2.69, seed 002 eq 31).
fn wen_yu_cd(re: f64, high_re_cd: f64) -> f64 {
    if re < 1000.0 {
        24.0 * (1.0 + 0.15 * re.powf(0.687)) / re
    } else {
        high_re_cd
    }
}

/// Di Felice's single-sphere drag coefficient C_d = (0.63 + 4.8/√Re)² (seed 000 eq 2.72), Re = 2R ρ_g ε |u − v|/μ.
pub fn di_felice_drag_coefficient(re: f64) -> f64 {
    (0.63 + 4.8 / re.sqrt()).powi(2)
}

/// Di Felice's voidage exponent χ = 3.7 − 0.65 exp(−(1.5 − log₁₀ Re)²/2) (seed 000 eq 2.73).
pub fn di_felice_exponent(re: f64) -> f64 {
    3.7 - 0.65 * (-(1.5 - re.log10()).powi(2) / 2.0).exp()
}

/// Terminal-velocity ratio of Garside & Al-Dibouni (seed 001 eqs 6.6–6.8).
pub fn garside_al_dibouni_vr(porosity: f64, re: f64) -> f64 {
    let a = porosity.powf(4.14);
    let b = if porosity <= 0.85 {
        0.8 * porosity.powf(1.28)
    } else {
        porosity.powf(2.65)
    };
    0.5 * (a - 0.06 * re + ((0.06 * re).powi(2) + 0.12 * re * (2.0 * b - a) + a * a).sqrt())
}

impl DragLaw {
    /// K (N·s/m) with F = K (u − v) on the particle.
    pub fn coefficient_n_s_per_m(self, input: &DragInput) -> f64 {
        let eps = input.porosity.clamp(0.05, 1.0);
        let w = input.slip_speed_m_per_s.abs();
        let (d, rho, mu) = (input.diameter_m, input.gas_density_kg_per_m3, input.gas_viscosity_pa_s);
        let volume = PI * d * d * d / 6.0;
        let solids = (1.0 - eps).max(1e-12);
        match self {
            DragLaw::DiFelice => {
                // PHYSICS §3: f_d = ½ C_d ρ πR² |w| w ε^(1−χ); the particle feels ε f_d.
                if w == 0.0 {
                    // The limit Re → 0: C_d |w| → 4.8² μ/(ρ d ε) and χ → 3.7.
                    let cd_w = 4.8 * 4.8 * mu / (rho * d * eps);
                    return 0.5 * cd_w * rho * PI * d * d / 4.0 * eps.powf(2.0 - 3.7);
                }
                let re = rho * d * eps * w / mu;
                let (cd, chi) = (di_felice_drag_coefficient(re), di_felice_exponent(re));
                0.5 * cd * rho * PI * d * d / 4.0 * w * eps.powf(2.0 - chi)
            }
            DragLaw::ErgunWenYu | DragLaw::ErgunWenYuSeed002 => {
                let (exponent, high_re_cd) = if self == DragLaw::ErgunWenYu {
                    (-2.65, 0.44)
                } else {
                    (-2.7, 0.43)
                };
                let beta = if eps <= 0.8 {
                    150.0 * solids * solids * mu / (eps * d * d) + 1.75 * solids * rho * w / d
                } else {
                    let re = rho * d * eps * w / mu;
                    if re == 0.0 {
                        // C_D w → 24 μ/(ρ d ε) as Re → 0.
                        0.75 * 24.0 * mu / (rho * d * eps) * eps * solids * rho / d * eps.powf(exponent)
                    } else {
                        0.75 * wen_yu_cd(re, high_re_cd) * eps * solids * rho * w / d * eps.powf(exponent)
                    }
                };
                beta * volume / solids
            }
            DragLaw::SyamlalOBrien => {
                let re = rho * d * w / mu;
                let vr = garside_al_dibouni_vr(eps, re);
                let cd_w = if re == 0.0 {
                    // (0.63 + 4.8 √(V_r/Re))² w → 4.8² V_r μ/(ρ d) as Re → 0.
                    4.8 * 4.8 * vr * mu / (rho * d)
                } else {
                    (0.63 + 4.8 * (vr / re).sqrt()).powi(2) * w
                };
                let beta = 3.0 * solids * eps * rho / (4.0 * vr * vr * d) * cd_w;
                beta * volume / solids
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(eps: f64, w: f64) -> DragInput {
        DragInput {
            porosity: eps,
            slip_speed_m_per_s: w,
            diameter_m: 0.003,
            gas_density_kg_per_m3: 1.2,
            gas_viscosity_pa_s: 1.8e-5,
        }
    }

    #[test]
    fn single_sphere_limits() {
        // ε = 1: Di Felice is a single sphere with C_d = (0.63 + 4.8/√Re)² (Dalla Valle); at Re = 1000,
        // C_d = (0.63 + 0.1518)² = 0.611.
        let w = 1000.0 * 1.8e-5 / (1.2 * 0.003);
        let k = DragLaw::DiFelice.coefficient_n_s_per_m(&input(1.0, w));
        let cd = k / (0.5 * 1.2 * PI * 0.003 * 0.003 / 4.0 * w);
        assert!((cd - (0.63 + 4.8 / 1000f64.sqrt()).powi(2)).abs() < 1e-12, "{cd}");
        // Wen-Yu at ε → 1 and Re = 0.1: Stokes-like 24/Re (1 + 0.15 Re^0.687).
        let w = 0.1 * 1.8e-5 / (1.2 * 0.003);
        let k = DragLaw::ErgunWenYu.coefficient_n_s_per_m(&input(0.999999, w));
        let stokes = 3.0 * PI * 1.8e-5 * 0.003 * (1.0 + 0.15 * 0.1f64.powf(0.687));
        assert!((k / stokes - 1.0).abs() < 1e-4, "{}", k / stokes);
    }

    #[test]
    fn ergun_branch_gives_the_ergun_pressure_gradient() {
        // In a fixed bed, −dp/dx = β U/ε² with U = ε w superficial; Ergun: 150 μ(1−ε)²U/(ε³d²) + 1.75ρ(1−ε)U²/(ε³d).
        let (eps, u_sup) = (0.4, 0.5);
        let w = u_sup / eps;
        let k = DragLaw::ErgunWenYu.coefficient_n_s_per_m(&input(eps, w));
        let volume = PI * 0.003f64.powi(3) / 6.0;
        let beta = k * (1.0 - eps) / volume;
        let ergun = 150.0 * 1.8e-5 * 0.36 * u_sup / (eps.powi(3) * 9e-6)
            + 1.75 * 1.2 * 0.6 * u_sup * u_sup / (eps.powi(3) * 0.003);
        assert!((beta * u_sup / (eps * eps) / ergun - 1.0).abs() < 1e-12);
    }

    #[test]
    fn seed_002_variant_differs_only_above_0_8() {
        let a = DragLaw::ErgunWenYu.coefficient_n_s_per_m(&input(0.6, 1.0));
        let b = DragLaw::ErgunWenYuSeed002.coefficient_n_s_per_m(&input(0.6, 1.0));
        assert_eq!(a, b);
        let a = DragLaw::ErgunWenYu.coefficient_n_s_per_m(&input(0.9, 1.0));
        let b = DragLaw::ErgunWenYuSeed002.coefficient_n_s_per_m(&input(0.9, 1.0));
        assert!((b / a - 0.9f64.powf(-0.05)).abs() < 1e-12);
    }

    #[test]
    fn syamlal_obrien_is_dalla_valle_for_a_single_sphere() {
        // ε → 1: V_r → 1, so β V_p/ε_s = ½ C_D ρ π d²/4 w with C_D = (0.63 + 4.8/√Re)².
        let w = 2.0;
        let k = DragLaw::SyamlalOBrien.coefficient_n_s_per_m(&input(1.0, w));
        let re = 1.2 * 0.003 * w / 1.8e-5;
        let single = 0.5 * (0.63 + 4.8 / re.sqrt()).powi(2) * 1.2 * PI * 0.003 * 0.003 / 4.0 * w;
        assert!((k / single - 1.0).abs() < 1e-9, "{}", k / single);
    }

    #[test]
    fn laws_are_finite_at_zero_slip() {
        for law in [
            DragLaw::DiFelice,
            DragLaw::ErgunWenYu,
            DragLaw::ErgunWenYuSeed002,
            DragLaw::SyamlalOBrien,
        ] {
            for eps in [0.4, 0.9, 1.0] {
                let k = law.coefficient_n_s_per_m(&input(eps, 0.0));
                assert!(k.is_finite() && k > 0.0, "{law:?} ε = {eps}: {k}");
            }
        }
    }
}
