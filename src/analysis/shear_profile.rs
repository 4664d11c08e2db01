//! The shear rate of a chute flow from its layer-averaged velocity profile (seed 000 §3.2, eq. 3.4 and Figs 13,
//! 15c): the particles are cut into layers across the flow, each layer's mean velocity along the flow is taken, and
//! the shear rate γ̇ = ∂u_x/∂y is the steepest difference between neighbouring layers — "the most highly shearing
//! portion of the flow", from which the seed reads γ̇ for its critical flip frequency (eq. 3.5), since "many of our
//! simulations resulted in non-linear shear profiles".

use crate::engine::Vec3;

/// A layer holds too few particles to give a mean below this fraction of the fullest layer's count: the bed's
/// loose surface (saltating particles) and the empty gap above it are left out.
pub const DENSE_LAYER_FRACTION: f64 = 0.5;

/// The steepest shear rate |Δū/Δh| between neighbouring dense layers of thickness `layer_m`, 1/s.
///
/// Directions come from `gravity`: the height axis is the coordinate axis gravity is most along (y for seed 000's
/// inclined chute, gravity 22-29° from it), heights measured against gravity along it; the flow direction is
/// gravity's component across that axis, normalised. Layers are [k·layer_m, (k+1)·layer_m) of height from the lowest
/// particle centre; a layer is dense when it holds at least [`DENSE_LAYER_FRACTION`] of the fullest layer's
/// particles, and only neighbouring dense layers are compared. Particles count equally (the seed's Fig. 15c averages
/// particle velocities per layer).
///
/// NaN when gravity has no component across its main axis (no flow direction) or fewer than two neighbouring
/// dense layers exist.
///
/// # Panics
/// If the slices differ in length or `layer_m` is not positive.
pub fn steepest_layer_shear_rate_per_s(
    positions_m: &[Vec3],
    velocities_m_per_s: &[Vec3],
    gravity: Vec3,
    layer_m: f64,
) -> f64 {
    assert_eq!(positions_m.len(), velocities_m_per_s.len(), "one velocity per position");
    assert!(layer_m > 0.0, "layer thickness {layer_m} m");
    let axis = (0..3)
        .max_by(|&a, &b| gravity[a].abs().total_cmp(&gravity[b].abs()))
        .expect("three axes");
    let up = -gravity[axis].signum();
    let mut across = gravity;
    across[axis] = 0.0;
    if across.norm() == 0.0 || gravity[axis] == 0.0 || positions_m.is_empty() {
        return f64::NAN;
    }
    let flow = across.normalize();
    let heights: Vec<f64> = positions_m.iter().map(|x| up * x[axis]).collect();
    let lowest = heights.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let layers = (((highest - lowest) / layer_m).floor() as usize + 1).min(positions_m.len());
    let (mut count, mut sum) = (vec![0usize; layers], vec![0.0; layers]);
    for (h, v) in heights.iter().zip(velocities_m_per_s) {
        let k = (((h - lowest) / layer_m).floor() as usize).min(layers - 1);
        count[k] += 1;
        sum[k] += v.dot(&flow);
    }
    let fullest = count.iter().copied().max().unwrap_or(0) as f64;
    let dense = |k: usize| count[k] > 0 && count[k] as f64 >= DENSE_LAYER_FRACTION * fullest;
    (1..layers)
        .filter(|&k| dense(k) && dense(k - 1))
        .map(|k| ((sum[k] / count[k] as f64 - sum[k - 1] / count[k - 1] as f64) / layer_m).abs())
        .fold(f64::NAN, f64::max)
}

/// Seed 000's critical flip frequency (eq. 3.5): f_crit = 0.01 β γ̇ (1 − ρ̄), Hz, from the segregation Péclet
/// number β(1 − ρ̄) and the collisional diffusivity D_c = 0.01 R² γ̇; ρ̄ the light over the heavy density.
pub fn critical_flip_frequency_hz(beta: f64, shear_rate_per_s: f64, density_ratio: f64) -> f64 {
    0.01 * beta * shear_rate_per_s * (1.0 - density_ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear profile u = 3 h (1/s) on an incline: every layer's mean is 3 h at its centre, so the steepest
    /// difference is 3 whatever the layer thickness; a kink to 7 h above h = 5 mm is found; the sparse top layer
    /// (two particles moving fast) is left out.
    #[test]
    fn steepest_layer_difference_of_a_known_profile() {
        let angle = 26f64.to_radians();
        let g = Vec3::new(9.81 * angle.sin(), -9.81 * angle.cos(), 0.0);
        let mut x = Vec::new();
        let mut v = Vec::new();
        for k in 0..10 {
            let h = 0.0005 + 0.001 * k as f64;
            for j in 0..20 {
                x.push(Vec3::new(0.001 * j as f64, h, 0.0));
                let u = if h < 0.005 {
                    3.0 * h
                } else {
                    3.0 * 0.005 + 7.0 * (h - 0.005)
                };
                v.push(Vec3::new(u, 0.0, 0.0));
            }
        }
        x.push(Vec3::new(0.0, 0.0108, 0.0));
        v.push(Vec3::new(10.0, 0.0, 0.0));
        x.push(Vec3::new(0.001, 0.0108, 0.0));
        v.push(Vec3::new(10.0, 0.0, 0.0));
        let rate = steepest_layer_shear_rate_per_s(&x, &v, g, 0.001);
        assert!((rate - 7.0).abs() < 1e-9, "{rate}");
        // Gravity flipped (the bed on the roof): heights count downwards, the same layers, the same rate.
        let flipped = Vec3::new(g.x, -g.y, 0.0);
        let rate = steepest_layer_shear_rate_per_s(&x, &v, flipped, 0.001);
        assert!((rate - 7.0).abs() < 1e-9, "{rate}");
        // Straight down: no flow direction.
        assert!(steepest_layer_shear_rate_per_s(&x, &v, Vec3::new(0.0, -9.81, 0.0), 0.001).is_nan());
    }

    /// Seed 000 Fig. 19's axis: f_crit = 0.01 × 0.1 × γ̇ × (1 − ρ̄).
    #[test]
    fn critical_frequency_of_eq_3_5() {
        assert!((critical_flip_frequency_hz(0.1, 40.0, 0.25) - 0.03).abs() < 1e-15);
    }
}
