//! Spraying liquid onto the free surface of a bed (seed 000 §6.3.2): "at each time-step we determine which
//! particles are at the surface of the particle bed and then increase their individual moisture content up to the
//! maximum moisture value (here taken to be a dimensionless volume of V = 0.02)".
//!
//! CHOICE: the seed does not say how the surface particles are found. Here the spray comes from above (against
//! gravity): the plane normal to gravity is cut into square columns as wide as the largest particle diameter, and in
//! each column the particle whose centre is highest along −g is on the surface. That is the first particle a
//! droplet falling straight down into that column would hit, and it follows a tilted or moving surface (a drum's
//! cascading layer) without any parameter. Particles hidden below others in their column stay dry, as the seed
//! observes for the interior of its drums.

use std::collections::HashMap;

use super::Vec3;
use super::particles::Particles;

/// Raises the liquid of every particle on the free surface (seen along gravity `g`) to `max_liquid_content` R³.
/// Adds what each particle receives to `sprayed_m3` and returns the total sprayed, m³.
pub fn spray_surface(p: &mut Particles, g: &Vec3, max_liquid_content: f64) -> f64 {
    if p.is_empty() || g.norm() == 0.0 {
        return 0.0;
    }
    let down = g.normalize();
    // An orthonormal basis (e1, e2) of the plane normal to gravity.
    let helper = if down.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    let e1 = down.cross(&helper).normalize();
    let e2 = down.cross(&e1);
    let width = 2.0 * p.max_radius_m();
    // Column → (highest particle, its height along −g). Particles are visited in index order and a tie keeps the
    // first, so the choice does not depend on anything but the positions.
    let mut top: HashMap<(i64, i64), (usize, f64)> = HashMap::new();
    for (i, x) in p.position_m.iter().enumerate() {
        let key = ((x.dot(&e1) / width).floor() as i64, (x.dot(&e2) / width).floor() as i64);
        let height = -x.dot(&down);
        let entry = top.entry(key).or_insert((i, height));
        if height > entry.1 {
            *entry = (i, height);
        }
    }
    let mut surface: Vec<usize> = top.values().map(|&(i, _)| i).collect();
    // Summing in index order keeps the total independent of the hash map's order.
    surface.sort_unstable();
    let mut total = 0.0;
    for i in surface {
        let target = max_liquid_content * p.radius_m[i].powi(3);
        let gain = target - p.liquid_m3[i];
        if gain > 0.0 {
            p.liquid_m3[i] = target;
            p.sprayed_m3[i] += gain;
            total += gain;
        }
    }
    total
}

/// CV_m = σ_m/μ_m of the particles' coating mass gains (seed 000 eq 6.45; `Simulation::coating_gain_m3`); NaN
/// before any gain.
pub fn coating_variability(sprayed_m3: &[f64]) -> f64 {
    let n = sprayed_m3.len() as f64;
    let mean = sprayed_m3.iter().sum::<f64>() / n;
    if mean.is_nan() || mean <= 0.0 {
        return f64::NAN;
    }
    let variance = sprayed_m3.iter().map(|s| (s - mean) * (s - mean)).sum::<f64>() / n;
    variance.sqrt() / mean
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::particles::{Species, SpeciesId};

    fn bead() -> Species {
        Species::test_bead("s", 0.001, 1000.0)
    }

    /// Two columns of three beads under gravity along −z: only the top bead of each column is sprayed, up to the
    /// maximum; a second spray adds nothing; CV_m of the gains follows.
    #[test]
    fn only_the_top_of_each_column_is_sprayed_up_to_the_maximum() {
        let mut p = Particles::default();
        let s = bead();
        for column in 0..2 {
            for layer in 0..3 {
                p.push(
                    SpeciesId(0),
                    &s,
                    0.001,
                    Vec3::new(0.0031 * column as f64, 0.0, 0.001 + 0.002 * layer as f64),
                );
            }
        }
        p.liquid_m3[5] = 0.005e-9;
        let g = Vec3::new(0.0, 0.0, -9.81);
        let total = spray_surface(&mut p, &g, 0.02);
        let full = 0.02 * 0.001f64.powi(3);
        assert_eq!(p.liquid_m3, vec![0.0, 0.0, full, 0.0, 0.0, full]);
        assert!((total - (2.0 * full - 0.005e-9)).abs() < 1e-24);
        assert_eq!(spray_surface(&mut p, &g, 0.02), 0.0);
        // Gains 0, 0, 0.02, 0, 0, 0.015 (×1e-9): mean 0.035/6, CV_m = σ/μ.
        let gains: Vec<f64> = vec![0.0, 0.0, 0.02, 0.0, 0.0, 0.015];
        let mean = 0.035 / 6.0;
        let sigma = (gains.iter().map(|g| (g - mean) * (g - mean)).sum::<f64>() / 6.0).sqrt();
        assert!((coating_variability(&p.sprayed_m3) - sigma / mean).abs() < 1e-9);
        // Gravity along x: the columns are now lines along x, and the beads with the smallest x top them.
        let mut q = p.clone();
        q.liquid_m3.iter_mut().for_each(|l| *l = 0.0);
        spray_surface(&mut q, &Vec3::new(9.81, 0.0, 0.0), 0.02);
        assert_eq!(q.liquid_m3.iter().filter(|&&l| l > 0.0).count(), 3);
        assert!(q.liquid_m3[0] > 0.0 && q.liquid_m3[1] > 0.0 && q.liquid_m3[2] > 0.0);
    }
}
