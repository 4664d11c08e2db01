//! The granular Bond and capillary numbers of wet particles (seed 000 §4.1.1 and §4.2.1, eqs 4.2–4.5).
//!
//! - Bo_g = F_c,max / W: the largest capillary force over the particle's weight.
//! - Ca_g = F_c,max / F_d (4.3): over the Di Felice drag F_d = ½ C_d ρ_g π R² w² ε^(1−χ) at slip speed w and
//!   porosity ε (eqs 2.70–2.73).
//! - F_c,max = 2πRγ cos θ. Seed 000 eq 4.2 prints 2πRγ; the cos θ is the classical limit of a small bridge (our
//!   exact bridge solver reaches it, `young_laplace.rs`) and is what Table 3 needs: its values at θ = 60° are half
//!   those at θ = 0 (see the test).
//! - Binary mixtures (4.4–4.5): the 1–2 pair's force uses the equal-sphere radius of the pair's effective radius,
//!   R₁₂ = 2R₁R₂/(R₁ + R₂), and the larger of the two contact angles; Bo_g12 divides it by the lighter particle's
//!   weight, and Ca_g12 by the drag of the particle whose drag-to-weight ratio is larger (F_d*). These readings
//!   reproduce every 1–2 entry of seed 000 Table 3 from its 1–1 and 2–2 entries (test below).
//!
//! CHOICE: Bo_g uses F_c,max/W. The seed's group φ3 = γ/(ρ_s g R²) is (2/3) Bo_g at θ = 0.

use std::f64::consts::PI;

use crate::engine::models::drag::{di_felice_drag_coefficient, di_felice_exponent};

/// One particle kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WetParticle {
    pub radius_m: f64,
    pub density_kg_per_m3: f64,
    pub contact_angle_rad: f64,
}

/// The gas around the particles, and how fast it slips past them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GasSlip {
    pub density_kg_per_m3: f64,
    pub viscosity_pa_s: f64,
    /// |u − v|, m/s.
    pub slip_speed_m_per_s: f64,
    pub porosity: f64,
}

/// F_c,max = 2πRγ cos θ, N.
pub fn max_capillary_force_n(radius_m: f64, surface_tension_n_per_m: f64, contact_angle_rad: f64) -> f64 {
    2.0 * PI * radius_m * surface_tension_n_per_m * contact_angle_rad.cos()
}

fn weight_n(p: &WetParticle, gravity_m_per_s2: f64) -> f64 {
    4.0 / 3.0 * PI * p.radius_m.powi(3) * p.density_kg_per_m3 * gravity_m_per_s2
}

/// Di Felice's drag on one particle (seed 000 eq 2.71 with 2.70, 2.72, 2.73), N.
pub fn di_felice_drag_n(radius_m: f64, gas: &GasSlip) -> f64 {
    let w = gas.slip_speed_m_per_s.abs();
    let re = 2.0 * radius_m * gas.density_kg_per_m3 * gas.porosity * w / gas.viscosity_pa_s;
    0.5 * di_felice_drag_coefficient(re)
        * gas.density_kg_per_m3
        * PI
        * radius_m
        * radius_m
        * w
        * w
        * gas.porosity.powf(1.0 - di_felice_exponent(re))
}

/// The force of the 1–2 pair's bridge: equal-sphere radius 2R₁R₂/(R₁ + R₂), the larger contact angle.
fn pair_capillary_force_n(a: &WetParticle, b: &WetParticle, surface_tension_n_per_m: f64) -> f64 {
    let radius = 2.0 * a.radius_m * b.radius_m / (a.radius_m + b.radius_m);
    max_capillary_force_n(
        radius,
        surface_tension_n_per_m,
        a.contact_angle_rad.max(b.contact_angle_rad),
    )
}

/// Bo_g of one kind.
pub fn granular_bond_number(p: &WetParticle, surface_tension_n_per_m: f64, gravity_m_per_s2: f64) -> f64 {
    max_capillary_force_n(p.radius_m, surface_tension_n_per_m, p.contact_angle_rad) / weight_n(p, gravity_m_per_s2)
}

/// Bo_g12: the pair's force over the lighter particle's weight.
pub fn binary_granular_bond_number(
    a: &WetParticle,
    b: &WetParticle,
    surface_tension_n_per_m: f64,
    gravity_m_per_s2: f64,
) -> f64 {
    let lighter = weight_n(a, gravity_m_per_s2).min(weight_n(b, gravity_m_per_s2));
    pair_capillary_force_n(a, b, surface_tension_n_per_m) / lighter
}

/// Ca_g of one kind (seed 000 eq 4.3).
pub fn granular_capillary_number(p: &WetParticle, surface_tension_n_per_m: f64, gas: &GasSlip) -> f64 {
    max_capillary_force_n(p.radius_m, surface_tension_n_per_m, p.contact_angle_rad) / di_felice_drag_n(p.radius_m, gas)
}

/// Ca_g12 (seed 000 eqs 4.4–4.5): the pair's force over F_d*, the drag of the kind with the larger F_d/W.
pub fn binary_granular_capillary_number(
    a: &WetParticle,
    b: &WetParticle,
    surface_tension_n_per_m: f64,
    gas: &GasSlip,
    gravity_m_per_s2: f64,
) -> f64 {
    let (drag_a, drag_b) = (di_felice_drag_n(a.radius_m, gas), di_felice_drag_n(b.radius_m, gas));
    let drag_star = if drag_a / weight_n(a, gravity_m_per_s2) >= drag_b / weight_n(b, gravity_m_per_s2) {
        drag_a
    } else {
        drag_b
    };
    pair_capillary_force_n(a, b, surface_tension_n_per_m) / drag_star
}

/// Seed 000 §4.2.1's phase rule: wetting makes a binary bed more mixed than dry (`Mixed`) if Ca_g11 < Ca_g12 and
/// Ca_g22 < Ca_g12, and more segregated (`Segregated`) otherwise. The text names "Ca_g12 between the two" for
/// segregation; Table 3 also marks Ca_g12 below both (its rows 2a and 2b) as segregated, so there is no third case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WetPhase {
    Mixed,
    Segregated,
}

pub fn wet_phase(number_11: f64, number_22: f64, number_12: f64) -> WetPhase {
    if number_11 < number_12 && number_22 < number_12 {
        WetPhase::Mixed
    } else {
        WetPhase::Segregated
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 9.81;

    /// Air slipping past the beads at 1.8 m/s in a bed of porosity 0.5.
    fn air_at_1_8_m_per_s() -> GasSlip {
        GasSlip {
            density_kg_per_m3: 1.23,
            viscosity_pa_s: 1.8e-5,
            slip_speed_m_per_s: 1.8,
            porosity: 0.5,
        }
    }

    fn particle(radius_mm: f64, density: f64, theta_deg: f64) -> WetParticle {
        WetParticle {
            radius_m: radius_mm * 1e-3,
            density_kg_per_m3: density,
            contact_angle_rad: theta_deg.to_radians(),
        }
    }

    #[test]
    fn bond_number_is_the_largest_capillary_force_over_the_weight() {
        let p = particle(1.0, 2500.0, 0.0);
        let bo = granular_bond_number(&p, 0.072, G);
        let expected = 2.0 * PI * 1e-3 * 0.072 / (4.0 / 3.0 * PI * 1e-9 * 2500.0 * G);
        assert!((bo / expected - 1.0).abs() < 1e-12);
        // φ3 = γ/(ρ g R²) = (2/3) Bo_g at θ = 0.
        assert!((0.072 / (2500.0 * G * 1e-6) / bo - 2.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn capillary_number_is_the_force_over_di_felice_drag() {
        let p = particle(1.35, 2000.0, 0.0);
        let gas = air_at_1_8_m_per_s();
        // By hand: Re = 2R ρ ε w/μ = 166.05, C_d = (0.63 + 4.8/√Re)², χ = 3.7 − 0.65 e^{−(1.5 − log Re)²/2}.
        let re: f64 = 2.0 * 1.35e-3 * 1.23 * 0.5 * 1.8 / 1.8e-5;
        let cd = (0.63 + 4.8 / re.sqrt()).powi(2);
        let chi = 3.7 - 0.65 * (-(1.5 - re.log10()).powi(2) / 2.0).exp();
        let drag = 0.5 * cd * 1.23 * PI * 1.35e-3 * 1.35e-3 * 1.8 * 1.8 * 0.5f64.powf(1.0 - chi);
        let ca = granular_capillary_number(&p, 0.03, &gas);
        assert!((ca / (2.0 * PI * 1.35e-3 * 0.03 / drag) - 1.0).abs() < 1e-12);
        // Faster gas, smaller Ca_g.
        let faster = GasSlip {
            slip_speed_m_per_s: 2.0,
            ..gas
        };
        assert!(granular_capillary_number(&p, 0.03, &faster) < ca);
    }

    /// Seed 000 Table 3 (gas at 1.8 m/s): given its 1–1 and 2–2 numbers, the binary rules above give its 1–2
    /// numbers and its phases. Particles: R₁ = 1.35 mm, R₂ = 1.5 mm; ρ₂ = 2000 (1a, 1b) or 1000 kg/m³ (2a, 2b);
    /// the second kind's contact angle 60° in 1b and 2b. The table's own values show θ = 0 in 1a/2a and θ₁ = 20° in
    /// 1b/2b (its Bo_g11 and Ca_g11 drop by cos 20° from a to b); the text says 20° throughout.
    /// Only ratios are checked, since the table's γ and slip are not given (its Bo_g11 = 1.26 needs γ = 0.030 N/m).
    #[test]
    fn seed_000_table_3_binary_numbers_follow_from_its_single_kind_numbers() {
        // (ρ₂, θ₁, θ₂, Bo11, Bo22, Bo12, Ca11, Ca22, Ca12, phase)
        let rows = [
            (2000.0, 0.0, 0.0, 1.26, 1.02, 1.32, 2.12, 1.93, 2.23, WetPhase::Mixed),
            (
                2000.0,
                20.0,
                60.0,
                1.18,
                0.51,
                0.66,
                1.99,
                0.96,
                1.11,
                WetPhase::Segregated,
            ),
            (
                1000.0,
                0.0,
                0.0,
                1.26,
                2.04,
                1.93,
                2.12,
                1.93,
                1.83,
                WetPhase::Segregated,
            ),
            (
                1000.0,
                20.0,
                60.0,
                1.18,
                1.02,
                0.97,
                1.99,
                0.96,
                0.91,
                WetPhase::Segregated,
            ),
        ];
        let gamma = 0.030;
        for (k, &(rho2, t1, t2, bo11, bo22, bo12, ca11, ca22, ca12, phase)) in rows.iter().enumerate() {
            let a = particle(1.35, 2000.0, t1);
            let b = particle(1.5, rho2, t2);
            // Bond numbers: absolute, with γ = 0.030 N/m (two printed digits).
            let (ours11, ours22) = (granular_bond_number(&a, gamma, G), granular_bond_number(&b, gamma, G));
            let ours12 = binary_granular_bond_number(&a, &b, gamma, G);
            for (ours, table) in [(ours11, bo11), (ours22, bo22), (ours12, bo12)] {
                assert!((ours / table - 1.0).abs() < 0.02, "row {k}: Bo {ours} vs {table}");
            }
            // Capillary numbers: the table's drag-to-weight ratios F_d/W = Bo/Ca pick F_d*, and Ca12 follows from
            // the picked kind's Ca by the ratio of the pair's force to that kind's force.
            let (ratio_a, ratio_b) = (bo11 / ca11, bo22 / ca22);
            let fc_pair = pair_capillary_force_n(&a, &b, gamma);
            let predicted = if ratio_a >= ratio_b {
                ca11 * fc_pair / max_capillary_force_n(a.radius_m, gamma, a.contact_angle_rad)
            } else {
                ca22 * fc_pair / max_capillary_force_n(b.radius_m, gamma, b.contact_angle_rad)
            };
            assert!(
                (predicted / ca12 - 1.0).abs() < 0.02,
                "row {k}: Ca12 {predicted} vs {ca12}"
            );
            assert_eq!(wet_phase(ca11, ca22, ca12), phase, "row {k}");
            assert_eq!(wet_phase(bo11, bo22, bo12), phase, "row {k} (Bo)");
        }
    }

    #[test]
    fn the_binary_capillary_number_divides_by_the_drag_of_the_kind_easier_to_lift() {
        let a = particle(1.35, 2000.0, 0.0);
        let b = particle(1.5, 1000.0, 0.0);
        let gas = air_at_1_8_m_per_s();
        // The light kind has the larger drag-to-weight ratio.
        let ca12 = binary_granular_capillary_number(&a, &b, 0.03, &gas, G);
        let expected = pair_capillary_force_n(&a, &b, 0.03) / di_felice_drag_n(b.radius_m, &gas);
        assert!((ca12 / expected - 1.0).abs() < 1e-12);
    }
}
