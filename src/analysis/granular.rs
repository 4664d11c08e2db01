//! Granular temperature and coordination number of a particle bed at one instant.
//!
//! Granular temperature after seed 000 eq 3.1: the mean squared velocity fluctuation per component about the local
//! mean velocity. Coordination number after seed 002 (§ on Fig. 5–6 and 11): the mean number of contacting
//! neighbours of a particle, and the share of contacting particles in multicontacts.
//!
//! Not here: the shear rate from a layer-averaged velocity profile and the critical flipping frequency (seed 000
//! eqs 3.4–3.5), nor the contact detection itself; the caller supplies the contact pairs or their count.

use crate::engine::Vec3;

/// Seed 000 eq 3.1 for one particle: T_g = [(u_x − ū_x)² + (u_y − ū_y)² + (u_z − ū_z)²]/3, m²/s².
///
/// The seed's temperature scale sets m/k = 1 (its eq 3.2 with the mass and Boltzmann constant dropped), so T_g is a
/// squared velocity. For mixtures of unequal masses the seed offers m·(…)/3 (eq 3.3); multiply by the mass for it.
pub fn fluctuation_temperature_m2_per_s2(velocity_m_per_s: &Vec3, local_mean_m_per_s: &Vec3) -> f64 {
    (velocity_m_per_s - local_mean_m_per_s).norm_squared() / 3.0
}

/// Granular temperature of a bed divided into bins (layers or cells), after seed 000 eq 3.1.
#[derive(Debug, Clone, PartialEq)]
pub struct GranularTemperature {
    /// Mean of eq 3.1 over the particles counted (those in bins of at least two particles), m²/s²; 0 if none.
    pub mean_m2_per_s2: f64,
    /// Mean of eq 3.1 over the particles of each bin, m²/s²; 0 for bins with fewer than two particles.
    pub per_bin_m2_per_s2: Vec<f64>,
    /// Mean velocity of each bin (the ū of eq 3.1), m/s; zero for an empty bin.
    pub mean_velocity_per_bin_m_per_s: Vec<Vec3>,
    /// Particles in each bin.
    pub particles_per_bin: Vec<usize>,
    /// Particles that count towards `mean_m2_per_s2`.
    pub particles_counted: usize,
}

/// Granular temperature of seed 000 eq 3.1, each particle's fluctuation taken about the mean velocity of its bin.
///
/// The seed defines T_g per particle about "the local mean velocities in the shear layer" (ū_x, ū_y, ū_z) and
/// reads the mean flow from velocities "at different heights" (§3.2, Fig. 15c): the local mean is that of a region,
/// here a bin. `bin_of_particle[i]` is particle i's bin, `None` (or an index ≥ `bin_count`) leaves the particle out;
/// make bins with `layer_bins` for the seed's layers, or pass any cell map (seed 002's per-cell mean velocity, eq 6
/// with C = v − v_sm, is the same definition with fluid cells as bins). One bin for all particles gives the
/// temperature about the bed's mean velocity, which counts a mean shear as fluctuation.
///
/// CHOICES: ū is the arithmetic mean of the bin's particle velocities (the seed does not weight it; seed 002's v_sm
/// is volume-weighted, the same for equal particles). A particle alone in its bin equals its own mean, so bins with
/// fewer than two particles are left out of the mean rather than counted as zero. The bed value is the mean over the
/// counted particles (each particle weighs the same, as in seed 001's T = (1/2N) Σ (v'_x² + v'_y²), eq 3.22, which
/// is the 2-D form with 2 components over 2; this follows seed 000's 3-D form, dividing by 3).
///
/// # Panics
/// If the slices differ in length.
pub fn granular_temperature(
    velocities_m_per_s: &[Vec3],
    bin_of_particle: &[Option<usize>],
    bin_count: usize,
) -> GranularTemperature {
    assert_eq!(
        velocities_m_per_s.len(),
        bin_of_particle.len(),
        "granular_temperature: one bin per particle velocity"
    );
    let bin = |b: &Option<usize>| b.filter(|&b| b < bin_count);
    let mut sum_m_per_s = vec![Vec3::zeros(); bin_count];
    let mut particles_per_bin = vec![0usize; bin_count];
    for (v, b) in velocities_m_per_s.iter().zip(bin_of_particle) {
        if let Some(b) = bin(b) {
            sum_m_per_s[b] += v;
            particles_per_bin[b] += 1;
        }
    }
    let mean_velocity_per_bin_m_per_s: Vec<Vec3> = sum_m_per_s
        .iter()
        .zip(&particles_per_bin)
        .map(|(s, &n)| if n > 0 { s / n as f64 } else { Vec3::zeros() })
        .collect();
    let mut sum_t = vec![0.0f64; bin_count];
    for (v, b) in velocities_m_per_s.iter().zip(bin_of_particle) {
        if let Some(b) = bin(b) {
            sum_t[b] += fluctuation_temperature_m2_per_s2(v, &mean_velocity_per_bin_m_per_s[b]);
        }
    }
    let (mut total_t, mut particles_counted) = (0.0, 0usize);
    let per_bin_m2_per_s2 = sum_t
        .iter()
        .zip(&particles_per_bin)
        .map(|(&t, &n)| {
            if n >= 2 {
                total_t += t;
                particles_counted += n;
                t / n as f64
            } else {
                0.0
            }
        })
        .collect();
    GranularTemperature {
        mean_m2_per_s2: if particles_counted > 0 {
            total_t / particles_counted as f64
        } else {
            0.0
        },
        per_bin_m2_per_s2,
        mean_velocity_per_bin_m_per_s,
        particles_per_bin,
        particles_counted,
    }
}

/// Layers of equal thickness between `bottom_m` and `top_m` along `axis` (0 = x, 1 = y, 2 = z): the bins of a
/// layer-averaged profile (seed 000 §3.2, Fig. 15c; eq 3.4 takes the shear rate from it).
///
/// Layer 0 starts at `bottom_m`; a coordinate equal to `top_m` is in the last layer; particles outside the range,
/// with a non-finite coordinate, or any particle if `layers` is 0 or the range is empty, get `None`.
///
/// # Panics
/// If `axis` > 2.
pub fn layer_bins(positions_m: &[Vec3], axis: usize, bottom_m: f64, top_m: f64, layers: usize) -> Vec<Option<usize>> {
    assert!(axis < 3, "layer_bins: axis {axis} is not 0, 1 or 2");
    let thickness_m = (top_m - bottom_m) / layers as f64;
    positions_m
        .iter()
        .map(|p| {
            let h = p[axis];
            if layers == 0 || thickness_m.is_nan() || thickness_m <= 0.0 || !(bottom_m..=top_m).contains(&h) {
                return None;
            }
            Some((((h - bottom_m) / thickness_m).floor() as usize).min(layers - 1))
        })
        .collect()
}

/// Bulk coordination number of seed 002 (Fig. 5): the mean number of contacting neighbours of a particle, 2·pairs/n.
///
/// Each particle–particle contact gives a neighbour to both of its particles. CHOICE: wall contacts are not counted
/// (the seed says "contacting neighbors" of a particle and does not mention walls). 0 for an empty bed.
pub fn mean_coordination_number(particle_count: usize, contact_pairs: usize) -> f64 {
    if particle_count == 0 {
        0.0
    } else {
        2.0 * contact_pairs as f64 / particle_count as f64
    }
}

/// N_c of every particle (seed 002: "the number of contacting neighbors of one particle") from its contact pairs.
///
/// # Panics
/// If a pair names a particle ≥ `particle_count`.
pub fn coordination_numbers(particle_count: usize, contact_pairs: &[(u32, u32)]) -> Vec<u32> {
    let mut n_c = vec![0u32; particle_count];
    for &(i, j) in contact_pairs {
        n_c[i as usize] += 1;
        n_c[j as usize] += 1;
    }
    n_c
}

/// Seed 002's multicontact ratio (Fig. 11): particles in multicontacts (N_c > 1) over particles in contact (N_c ≥ 1).
///
/// CHOICE: the caption's definition. The seed's text says "the number of multicontacts over the total number of
/// collisions" instead; the caption's is what the figure most likely plots (seed notes §6). 0 if no particle is in
/// contact.
pub fn multicontact_ratio(coordination: &[u32]) -> f64 {
    let in_contact = coordination.iter().filter(|&&n| n >= 1).count();
    let multi = coordination.iter().filter(|&&n| n > 1).count();
    if in_contact == 0 {
        0.0
    } else {
        multi as f64 / in_contact as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;

    #[test]
    fn rigid_motion_has_no_temperature_and_a_known_fluctuation_does() {
        let drift = Vec3::new(0.3, -0.1, 0.05);
        let v = vec![drift; 10];
        let t = granular_temperature(&v, &[Some(0); 10], 1);
        // Zero up to the rounding of the mean (sum/10 is not exactly the drift).
        assert!(t.mean_m2_per_s2 < 1e-32, "{}", t.mean_m2_per_s2);
        assert_eq!(t.particles_counted, 10);
        // ±a along x about the drift: every particle has (a²)/3.
        let a = 0.2;
        let v: Vec<Vec3> = (0..10)
            .map(|i| drift + Vec3::new(if i % 2 == 0 { a } else { -a }, 0.0, 0.0))
            .collect();
        let t = granular_temperature(&v, &[Some(0); 10], 1);
        assert!((t.mean_m2_per_s2 - a * a / 3.0).abs() < 1e-15);
        assert!((t.mean_velocity_per_bin_m_per_s[0] - drift).norm() < 1e-15);
    }

    #[test]
    fn layers_remove_a_mean_shear_that_one_bin_would_count() {
        // Simple shear u_x = γ̇ y with no fluctuation: zero per layer, but one bin sees the profile as spread.
        let shear_rate_per_s = 50.0;
        let positions: Vec<Vec3> = (0..400)
            .map(|i| Vec3::new((i % 20) as f64 * 1e-3, (i / 20) as f64 * 1e-3, 0.0))
            .collect();
        let v: Vec<Vec3> = positions
            .iter()
            .map(|p| Vec3::new(shear_rate_per_s * p.y, 0.0, 0.0))
            .collect();
        let bins = layer_bins(&positions, 1, -0.5e-3, 19.5e-3, 20);
        assert!(bins.iter().all(|b| b.is_some()));
        let layered = granular_temperature(&v, &bins, 20);
        assert!(layered.mean_m2_per_s2 < 1e-24, "{}", layered.mean_m2_per_s2);
        assert_eq!(layered.particles_per_bin, vec![20; 20]);
        // Whole bed: u_x uniform over 20 levels 0..19 × γ̇·1 mm, variance (20² − 1)/12 levels², over 3 components.
        let whole = granular_temperature(&v, &vec![Some(0); 400], 1);
        let level = shear_rate_per_s * 1e-3;
        let expected = level * level * (400.0 - 1.0) / 12.0 / 3.0;
        assert!(
            (whole.mean_m2_per_s2 - expected).abs() < 1e-12 * expected.max(1.0),
            "{} {expected}",
            whole.mean_m2_per_s2
        );
    }

    #[test]
    fn maxwellian_velocities_give_their_variance() {
        // Each component N(0, s²): T_g = (3 s²)/3 = s², less the (n − 1)/n of the sample mean.
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let s = 0.07;
        let mut normal = || {
            let u1: f64 = 1.0 - rng.random::<f64>();
            let u2: f64 = rng.random::<f64>();
            s * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let n = 60_000;
        let v: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(1.0 + normal(), normal(), -2.0 + normal()))
            .collect();
        let bins: Vec<Option<usize>> = (0..n).map(|i| Some(i % 6)).collect();
        let t = granular_temperature(&v, &bins, 6);
        assert!((t.mean_m2_per_s2 / (s * s) - 1.0).abs() < 0.02, "{}", t.mean_m2_per_s2);
        for per_bin in &t.per_bin_m2_per_s2 {
            assert!((per_bin / (s * s) - 1.0).abs() < 0.05);
        }
    }

    #[test]
    fn singletons_and_excluded_particles_do_not_count() {
        let v = vec![
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(5.0, 5.0, 5.0),
            Vec3::new(9.0, 0.0, 0.0),
        ];
        let bins = [Some(0), Some(0), Some(1), None];
        let t = granular_temperature(&v, &bins, 3);
        assert_eq!(t.particles_counted, 2);
        assert_eq!(t.particles_per_bin, vec![2, 1, 0]);
        assert!((t.mean_m2_per_s2 - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(t.per_bin_m2_per_s2[1], 0.0);
        assert_eq!(granular_temperature(&[], &[], 0).mean_m2_per_s2, 0.0);
        // An index past bin_count is ignored like None.
        assert_eq!(granular_temperature(&v, &[Some(7); 4], 3).particles_counted, 0);
    }

    #[test]
    fn layer_bins_edges() {
        let p = |y: f64| Vec3::new(0.0, y, 0.0);
        let positions = [p(0.0), p(0.999), p(1.0), p(3.0), p(-0.1), p(3.1), p(f64::NAN)];
        assert_eq!(
            layer_bins(&positions, 1, 0.0, 3.0, 3),
            vec![Some(0), Some(0), Some(1), Some(2), None, None, None]
        );
        assert!(layer_bins(&positions, 1, 0.0, 3.0, 0).iter().all(|b| b.is_none()));
        assert!(layer_bins(&positions, 1, 3.0, 3.0, 2).iter().all(|b| b.is_none()));
    }

    #[test]
    fn coordination_from_pairs() {
        // A chain 0–1–2 and a pair 3–4; particle 5 free.
        let pairs = [(0u32, 1u32), (1, 2), (3, 4)];
        let n_c = coordination_numbers(6, &pairs);
        assert_eq!(n_c, vec![1, 2, 1, 1, 1, 0]);
        let mean = mean_coordination_number(6, pairs.len());
        assert_eq!(mean, 1.0);
        assert_eq!(mean, n_c.iter().sum::<u32>() as f64 / 6.0);
        assert!((multicontact_ratio(&n_c) - 1.0 / 5.0).abs() < 1e-15);
        assert_eq!(mean_coordination_number(0, 0), 0.0);
        assert_eq!(multicontact_ratio(&[0, 0]), 0.0);
    }
}
