//! Mixing and segregation indices of a two-species bed at one instant.
//!
//! Seed 000 §2.5 (eqs 2.77–2.80): the local concentration of species A around each particle, its standard deviation
//! (the intensity of segregation, IS), the relative standard deviation (RSD) and Lacey's index M, as used for the
//! tumblers of seed 000 ch. 3 and the fluidized beds of §4.1.3. Seed 001 §7.2.2: the height-based index of a
//! fluidized bed (mean height of the particles that started in the upper half over that of the rest).
//!
//! Not here: reductions over time (the mixing rate constant from an exponential fit of IS(t), seed 000 §4.1.3, and
//! the time to 90 % of the largest Lacey index, Table 1) are in `super::fit`; the neighbour search is `super::knn`.

use super::knn::k_nearest_neighbours;
use crate::engine::Vec3;

/// Neighbours in each local sample according to seed 000 §2.5: "each particle's 10 nearest neighbors".
pub const SEED_000_NEIGHBOURS: usize = 10;

/// How a local sample's concentration of species A is counted (`analysis.mixing_concentration`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Concentration {
    /// The number fraction of A in each sample, P the number fraction of A in the bed, every sample counted once.
    /// A random mixture of any sizes reads M ≈ 1 − 1/(k + 1) and a segregated one M ≈ 0.
    #[default]
    Number,
    /// The volume fraction of A in each sample, P the volume fraction in the bed, each sample weighted by its
    /// particle's volume (so that the segregated bed reads M ≈ 0 for unequal sizes too). For unequal sizes a
    /// random mixture reads below 1 − 1/(k + 1): a sample's volume rests on its few large particles.
    Volume,
}

/// Mixing state of a two-species bed (seed 000 eqs 2.77–2.80), from local samples of each particle and its nearest
/// neighbours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MixingState {
    /// P: the fraction of species A in the whole bed, by number or volume as the concentrations (0 for an empty bed
    /// or one with no volume read by volume).
    pub fraction_a: f64,
    /// IS = σ, the sample standard deviation of the local concentrations of A (eq 2.78). 0 for a completely mixed
    /// bed; √(P(1 − P)) for a completely segregated one (0.5 at P = 0.5).
    pub intensity_of_segregation: f64,
    /// Lacey's M = (σ0² − σ²)/(σ0² − σR²) with σ0² = P(1 − P), σR² = P(1 − P)/N (eq 2.80): 0 segregated, 1 random.
    pub lacey_index: f64,
    /// RSD = σ/c̄ (eq 2.79), c̄ the mean local concentration.
    pub relative_standard_deviation: f64,
    /// N: the number of local samples, one per particle.
    pub samples: usize,
}

/// IS, Lacey index and RSD of a bed whose particles are of species A (`is_a`) or B, after seed 000 §2.5.
///
/// Each particle i gives one sample: itself and its `neighbours` nearest other particles (by centre distance, ties
/// to the smaller index; `SEED_000_NEIGHBOURS` = 10 in the seed). Its local concentration c_i is the fraction of A
/// in the sample, counted as `concentration` says:
/// - `Number` (the default): c_i = n_A/(k + 1) and P the number fraction of A. The seed counts particles (its
///   species are the same volume, §2.5.1); for its 2:1 size pair (Table 2) this reading gives its values
///   (research/f1-size-lacey).
/// - `Volume`: c_i = Σ_{j∈S_i, A} V_j / Σ_{j∈S_i} V_j and P the volume fraction (PHYSICS §6 says "by volume"), and
///   every sum over samples below weighted by the sample particle's volume w_i = V_i/max V. Unweighted, a 2:1 pair
///   puts 89 % of the samples on small beads and a bed segregated into halves reads M ≈ 0.6 instead of 0.
///
/// With equal sizes both readings are the same quantity (the bits may differ in the last place); `Volume` keeps
/// the bits of the unweighted volume reading this function had before (w_i = 1 exactly).
///
/// - σ² = Σ_i w_i (c_i − c̄)² / (W − W/N) (eq 2.77), c̄ = Σ_i w_i c_i / W, W = Σ_i w_i, N the number of samples
///   (particles); w_i = 1 by number, which is the sample variance Σ_i (c_i − c̄)²/(N − 1).
///   CHOICE: c̄ is the mean of the local concentrations, as the N − 1 (a sample variance) implies; the seed calls it
///   "the average concentration" without saying which average. It differs from P only through unequal sampling.
/// - IS = σ (eq 2.78); RSD = σ/c̄ (eq 2.79).
/// - Lacey M = (σ0² − σ²)/(σ0² − σR²) (eq 2.80) with σ0² = P(1 − P) and σR² = P(1 − P)/N. N is the number of
///   samples, which the seed makes equal to the number of particles: "σR² is dependent on particle number … for
///   large numbers of particles, σR² is negligible" (PHYSICS §6 says the same). Classical Lacey would divide by the
///   particles per sample (k + 1) instead. With the seed's N, a random mixture, whose local concentrations have
///   variance P(1 − P)/(k + 1), gives M ≈ 1 − 1/(k + 1) ≈ 0.909 for k = 10, not 1; that matches the largest values
///   the seed reports (91.6 % in Table 1, 90.3 % in Table 2). M is not clamped: a bed more even than random gives
///   M > 1, a perfectly segregated one about −1/N.
///
/// The membership of the particle itself in its sample ("each particle's 10 nearest neighbors" in the seed) is
/// read as the particle plus 10 others, following PHYSICS §6 ("each particle with its 10 nearest neighbours").
/// Neighbourhoods do not wrap across periodic sides (see `super::knn`).
///
/// Degenerate beds give defined values, never NaN from the formulas:
/// - fewer than `neighbours + 1` particles: every sample is the whole bed, so every c_i = P, σ = 0, and M takes
///   its formula value N/(N − 1) (the bed is as even as it can be measured);
/// - one species only, no particles, or (by volume) no volume (σ0² = 0): nothing can segregate, so IS = 0,
///   RSD = 0 and M = 1;
/// - by volume, a sample with no volume (all its particles have zero volume) takes c_i = P;
/// - c̄ = 0 (possible only by volume, when every A particle has zero volume) gives RSD = 0.
///
/// Cost: O(n·k) on a uniform grid, serial; about 75 ms for 100,000 random particles and k = 10 (`cargo test --release
/// --lib analysis::mixing::tests::timing_100k -- --ignored --nocapture`).
///
/// # Panics
/// If the three slices differ in length.
pub fn mixing_state(
    positions_m: &[Vec3],
    volumes_m3: &[f64],
    is_a: &[bool],
    neighbours: usize,
    concentration: Concentration,
) -> MixingState {
    let n = positions_m.len();
    assert!(
        volumes_m3.len() == n && is_a.len() == n,
        "mixing_state: {n} positions, {} volumes and {} species flags",
        volumes_m3.len(),
        is_a.len()
    );
    // What each particle counts for in a concentration: 1 by number, its volume by volume.
    let amount = |i: usize| match concentration {
        Concentration::Number => 1.0,
        Concentration::Volume => volumes_m3[i],
    };
    let (mut total, mut total_a) = (0.0, 0.0);
    for (i, &a) in is_a.iter().enumerate() {
        total += amount(i);
        if a {
            total_a += amount(i);
        }
    }
    let fraction_a = if total > 0.0 { total_a / total } else { 0.0 };
    let sigma0_sq = fraction_a * (1.0 - fraction_a);
    if n == 0 || sigma0_sq.is_nan() || sigma0_sq <= 0.0 {
        return MixingState {
            fraction_a,
            intensity_of_segregation: 0.0,
            lacey_index: 1.0,
            relative_standard_deviation: 0.0,
            samples: n,
        };
    }

    let nn = k_nearest_neighbours(positions_m, neighbours);
    let local: Vec<f64> = (0..n)
        .map(|i| {
            let (mut v, mut v_a) = (amount(i), if is_a[i] { amount(i) } else { 0.0 });
            for &j in nn.of(i) {
                let j = j as usize;
                v += amount(j);
                if is_a[j] {
                    v_a += amount(j);
                }
            }
            if v > 0.0 { v_a / v } else { fraction_a }
        })
        .collect();

    // The weight of each sample: 1 by number; by volume V_i/max V, exactly 1 when all sizes are equal.
    let largest_m3 = volumes_m3.iter().copied().fold(0.0, f64::max);
    let weight = |i: usize| match concentration {
        Concentration::Number => 1.0,
        Concentration::Volume => volumes_m3[i] / largest_m3,
    };
    let weights = (0..n).map(weight).sum::<f64>();
    let mean = (0..n).map(|i| weight(i) * local[i]).sum::<f64>() / weights;
    let variance = if n > 1 {
        let squares = (0..n)
            .map(|i| weight(i) * (local[i] - mean) * (local[i] - mean))
            .sum::<f64>();
        squares / (weights - weights / n as f64)
    } else {
        0.0
    };
    let sigma = variance.sqrt();
    MixingState {
        fraction_a,
        intensity_of_segregation: sigma,
        lacey_index: lacey_index(variance, fraction_a, n),
        relative_standard_deviation: if mean > 0.0 { sigma / mean } else { 0.0 },
        samples: n,
    }
}

/// Lacey's M (seed 000 eq 2.80) for a variance of local concentrations, the fraction P and N samples.
///
/// CHOICE: 1 when σ0² − σR² is not positive (one species, or a single sample): there is no segregated state to
/// measure from, and the bed is as mixed as it can be.
fn lacey_index(variance: f64, fraction_a: f64, samples: usize) -> f64 {
    let sigma0_sq = fraction_a * (1.0 - fraction_a);
    let sigma_r_sq = sigma0_sq / samples.max(1) as f64;
    let span = sigma0_sq - sigma_r_sq;
    if span > 0.0 { (sigma0_sq - variance) / span } else { 1.0 }
}

/// Seed 001's mixing index (§7.2.2): the mean height of the particles that started in the upper half of the initial
/// packed bed (family 1, `started_above_median`) over the mean height of the others (family 2).
///
/// I = h̄1/h̄2. For a bed of uniform density standing on y = 0, I = 3 when completely segregated (the upper half
/// still on top) and 1 when perfectly mixed. Heights must therefore be measured from the bottom of the bed (the
/// distributor), as in the seed; the index is not invariant to the choice of origin. The seed's own equations
/// (7.7–7.9) are missing from its text; this follows the definition given in its words (seed 001 notes §4.1).
///
/// Degenerate inputs give defined values: if either family is empty the families cannot be compared and I = 1; if
/// h̄2 = 0 (every family-2 particle at the origin), I = +∞ when h̄1 > 0 and 1 when h̄1 = 0 too.
///
/// # Panics
/// If the slices differ in length.
pub fn height_mixing_index(heights_m: &[f64], started_above_median: &[bool]) -> f64 {
    assert_eq!(
        heights_m.len(),
        started_above_median.len(),
        "height_mixing_index: one family flag per height"
    );
    let (mut sum1_m, mut n1, mut sum2_m, mut n2) = (0.0, 0usize, 0.0, 0usize);
    for (&h, &upper) in heights_m.iter().zip(started_above_median) {
        if upper {
            sum1_m += h;
            n1 += 1;
        } else {
            sum2_m += h;
            n2 += 1;
        }
    }
    if n1 == 0 || n2 == 0 {
        return 1.0;
    }
    let (mean1_m, mean2_m) = (sum1_m / n1 as f64, sum2_m / n2 as f64);
    if mean2_m == 0.0 {
        return if mean1_m == 0.0 { 1.0 } else { f64::INFINITY };
    }
    mean1_m / mean2_m
}

/// Seed 001's family 1 (§7.2.2): true for the particles at or above the median height of the initial packed bed.
///
/// The median of an even count is the mean of the two middle heights, so with distinct heights exactly half the
/// particles are marked. Particles at exactly the median height are marked, as in the seed ("y ≥ the median").
/// A NaN height is never marked and does not take part in the median.
pub fn above_median_height(heights_m: &[f64]) -> Vec<bool> {
    let mut sorted: Vec<f64> = heights_m.iter().copied().filter(|h| !h.is_nan()).collect();
    if sorted.is_empty() {
        return vec![false; heights_m.len()];
    }
    sorted.sort_by(f64::total_cmp);
    let m = sorted.len();
    let median_m = if m % 2 == 1 {
        sorted[m / 2]
    } else {
        0.5 * (sorted[m / 2 - 1] + sorted[m / 2])
    };
    heights_m.iter().map(|&h| h >= median_m).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;

    const D_M: f64 = 1e-3;

    fn lattice(nx: usize, ny: usize, nz: usize, origin_m: [f64; 3]) -> Vec<Vec3> {
        let mut points = Vec::with_capacity(nx * ny * nz);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    points.push(Vec3::new(
                        origin_m[0] + x as f64 * D_M,
                        origin_m[1] + y as f64 * D_M,
                        origin_m[2] + z as f64 * D_M,
                    ));
                }
            }
        }
        points
    }

    #[test]
    fn separated_blocks_give_the_segregated_limit_exactly() {
        // Species A and B in two blocks far apart: every sample is pure, c_i ∈ {0, 1}, so σ² = P(1 − P)·N/(N − 1).
        for (n_a, n_b) in [(1000usize, 1000usize), (600, 1400)] {
            let mut positions = lattice(10, 10, n_a / 100, [0.0; 3]);
            positions.extend(lattice(10, 10, n_b / 100, [1.0, 0.0, 0.0]));
            let n = positions.len();
            let volumes = vec![1e-9; n];
            let is_a: Vec<bool> = (0..n).map(|i| i < n_a).collect();
            let s = mixing_state(&positions, &volumes, &is_a, SEED_000_NEIGHBOURS, Concentration::Number);
            let p = n_a as f64 / n as f64;
            let nf = n as f64;
            assert!((s.fraction_a - p).abs() < 1e-12);
            let expected_is = (p * (1.0 - p) * nf / (nf - 1.0)).sqrt();
            assert!((s.intensity_of_segregation - expected_is).abs() < 1e-12, "{s:?}");
            assert!(
                (s.lacey_index - (-nf / ((nf - 1.0) * (nf - 1.0)))).abs() < 1e-12,
                "{s:?}"
            );
            assert!((s.relative_standard_deviation - expected_is / p).abs() < 1e-12, "{s:?}");
            assert_eq!(s.samples, n);
        }
    }

    #[test]
    fn sharp_left_right_interface_is_within_the_lattice_band() {
        // A 20 × 20 × 20 cubic lattice, A where x < 10, k = 6. An interior particle's 6 nearest are its face
        // neighbours, so the only mixed samples are in the two columns at the interface: interior ones have exactly
        // one particle of 7 across (deviation 1/7 from pure); those on the box faces, which borrow diagonal
        // neighbours, have 1 to 3 across. Every other sample is pure. That bounds Σ(c − 1/2)² analytically.
        let (side, k) = (20usize, 6usize);
        let positions = lattice(side, side, side, [0.0; 3]);
        let n = positions.len();
        let is_a: Vec<bool> = positions.iter().map(|p| p.x < 9.5 * D_M).collect();
        let s = mixing_state(&positions, &vec![5e-10; n], &is_a, k, Concentration::Number);

        let column = (side * side) as f64;
        let interior = ((side - 2) * (side - 2)) as f64;
        let pure = n as f64 - 2.0 * column;
        let dev = |m: f64| (0.5 - m / (k + 1) as f64).powi(2);
        let sum_hi = pure * 0.25 + 2.0 * interior * dev(1.0) + 2.0 * (column - interior) * dev(1.0);
        let sum_lo = pure * 0.25 + 2.0 * interior * dev(1.0) + 2.0 * (column - interior) * dev(3.0);
        // Σ(c − c̄)² = Σ(c − 1/2)² − N(c̄ − 1/2)², and |c̄ − 1/2| ≤ (face particles × 2/7)/N.
        let mean_shift = 2.0 * (column - interior) * (2.0 / 7.0) / n as f64;
        let lo = ((sum_lo - n as f64 * mean_shift * mean_shift) / (n - 1) as f64).sqrt();
        let hi = (sum_hi / (n - 1) as f64).sqrt();
        assert!(
            lo <= s.intensity_of_segregation && s.intensity_of_segregation <= hi,
            "{lo} ≤ {s:?} ≤ {hi}"
        );
        assert!(hi < 0.49, "the band excludes the ideal 0.5");
        assert!(s.lacey_index > 0.0 && s.lacey_index < 0.07, "{s:?}");
    }

    fn random_mixture(n: usize, p: f64, seed: u64) -> (Vec<Vec3>, Vec<bool>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let positions = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.random::<f64>() * 0.04,
                    rng.random::<f64>() * 0.03,
                    rng.random::<f64>() * 0.02,
                )
            })
            .collect();
        let is_a = (0..n).map(|_| rng.random::<f64>() < p).collect();
        (positions, is_a)
    }

    #[test]
    fn random_mixture_gives_the_binomial_sample_variance() {
        // Species independent of position: each sample of k + 1 equal particles has Var c = P(1 − P)/(k + 1).
        for (p, k) in [(0.5, SEED_000_NEIGHBOURS), (0.3, SEED_000_NEIGHBOURS), (0.5, 4)] {
            let n = 40_000;
            let (positions, is_a) = random_mixture(n, p, 11);
            let s = mixing_state(&positions, &vec![1e-9; n], &is_a, k, Concentration::Number);
            let p_real = s.fraction_a;
            assert!((p_real - p).abs() < 0.01);
            let expected_is = (p_real * (1.0 - p_real) / (k + 1) as f64).sqrt();
            let rel = (s.intensity_of_segregation / expected_is - 1.0).abs();
            assert!(
                rel < 0.03,
                "IS {} vs {expected_is} (p {p}, k {k})",
                s.intensity_of_segregation
            );
            let expected_m = 1.0 - 1.0 / (k + 1) as f64;
            assert!((s.lacey_index - expected_m).abs() < 0.02, "{s:?}");
            assert!(s.lacey_index > 0.78, "a random mixture is near the mixed end");
            assert!((s.relative_standard_deviation - s.intensity_of_segregation / p_real).abs() < 0.01);
        }
    }

    #[test]
    fn volume_reading_weights_concentrations_and_samples_by_volume() {
        // Two particles, far from everything else: A with 3 units of volume, B with 1. Each sample (k = 1) is the
        // pair, so both local concentrations are 3/4 and P = 3/4.
        let positions = vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(D_M, 0.0, 0.0)];
        let s = mixing_state(&positions, &[3e-9, 1e-9], &[true, false], 1, Concentration::Volume);
        assert!((s.fraction_a - 0.75).abs() < 1e-15);
        assert!(s.intensity_of_segregation < 1e-15, "{s:?}");
        // Alone in its sample (k = 0), each particle is pure: c = (1, 0) with weights (1, 1/3), c̄ = 3/4 and
        // σ² = (1/16 + 1/3 · 9/16)/(4/3 − 2/3) = 3/8 (= P(1 − P) N/(N − 1): the segregated limit).
        let s = mixing_state(&positions, &[3e-9, 1e-9], &[true, false], 0, Concentration::Volume);
        assert!((s.intensity_of_segregation - 0.375f64.sqrt()).abs() < 1e-15, "{s:?}");
        // By number the same pair is one A and one B: P = 1/2, and pure samples give σ² = 1/2.
        let s = mixing_state(&positions, &[3e-9, 1e-9], &[true, false], 0, Concentration::Number);
        assert_eq!(s.fraction_a, 0.5);
        assert!((s.intensity_of_segregation - 0.5f64.sqrt()).abs() < 1e-15);
    }

    /// A 2:1 size pair: large beads (diameter 2 D_M) on a lattice of spacing 2 D_M in x < 0, small ones (D_M) on a
    /// lattice of spacing D_M in x > 0, each half 48 D_M long and 12 D_M square, the two touching at x = 0. Eight
    /// small beads per large one, equal volumes of each.
    fn size_pair_in_halves() -> (Vec<Vec3>, Vec<f64>, Vec<bool>) {
        let (large_m3, small_m3) = (8e-9, 1e-9);
        let mut positions = Vec::new();
        let mut volumes = Vec::new();
        let mut is_large = Vec::new();
        for (spacing_m, count, volume_m3, large) in [(2.0 * D_M, 6, large_m3, true), (D_M, 12, small_m3, false)] {
            for z in 0..count {
                for y in 0..count {
                    for x in 0..4 * count {
                        let x_m = if large { -(x as f64 + 0.5) } else { x as f64 + 0.5 } * spacing_m;
                        positions.push(Vec3::new(
                            x_m,
                            (y as f64 + 0.5) * spacing_m,
                            (z as f64 + 0.5) * spacing_m,
                        ));
                        volumes.push(volume_m3);
                        is_large.push(large);
                    }
                }
            }
        }
        (positions, volumes, is_large)
    }

    #[test]
    fn size_pair_in_halves_reads_segregated_by_number_and_by_volume() {
        // Only the samples at the interface are mixed: M stays near 0 read either way (the large beads' first layer,
        // 1/24 of them, take mostly small neighbours: about 0.04 by number), while one unweighted sample per
        // particle by volume (89 % of the samples on small beads) would read about 0.6.
        let (positions, volumes, is_large) = size_pair_in_halves();
        let by_number = mixing_state(
            &positions,
            &volumes,
            &is_large,
            SEED_000_NEIGHBOURS,
            Concentration::Number,
        );
        assert!((by_number.fraction_a - 1.0 / 9.0).abs() < 1e-15, "{by_number:?}");
        assert!(by_number.lacey_index.abs() < 0.06, "{by_number:?}");
        let by_volume = mixing_state(
            &positions,
            &volumes,
            &is_large,
            SEED_000_NEIGHBOURS,
            Concentration::Volume,
        );
        assert!((by_volume.fraction_a - 0.5).abs() < 1e-12, "{by_volume:?}");
        assert!(by_volume.lacey_index.abs() < 0.06, "{by_volume:?}");
    }

    #[test]
    fn random_size_pair_gives_the_binomial_variance_by_number_and_its_weighted_moments_by_volume() {
        // Species independent of position, A eight times B's volume, number fraction p. By number each sample is
        // binomial: Var c = p(1 − p)/(k + 1). By volume, a sample with a A beads of k + 1 has c = 8a/(8a + k + 1 − a),
        // weighted by its own particle's volume (8 if A, 1 if B): the expected weighted variance follows from
        // a = [own is A] + Binomial(k, p).
        let (n, k, p) = (40_000, SEED_000_NEIGHBOURS, 0.2);
        let (positions, is_a) = random_mixture(n, p, 17);
        let volumes: Vec<f64> = is_a.iter().map(|&a| if a { 8e-9 } else { 1e-9 }).collect();
        let s = mixing_state(&positions, &volumes, &is_a, k, Concentration::Number);
        let p_real = s.fraction_a;
        let expected_is = (p_real * (1.0 - p_real) / (k + 1) as f64).sqrt();
        assert!((s.intensity_of_segregation / expected_is - 1.0).abs() < 0.03, "{s:?}");
        assert!((s.lacey_index - (1.0 - 1.0 / (k + 1) as f64)).abs() < 0.02, "{s:?}");

        let choose = |n: usize, r: usize| (0..r).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64);
        let (mut w, mut wc, mut wcc) = (0.0, 0.0, 0.0);
        for own_a in [true, false] {
            let (p_own, weight) = if own_a { (p_real, 8.0) } else { (1.0 - p_real, 1.0) };
            for others in 0..=k {
                let prob =
                    p_own * choose(k, others) * p_real.powi(others as i32) * (1.0 - p_real).powi((k - others) as i32);
                let a = others + own_a as usize;
                let c = 8.0 * a as f64 / (8.0 * a as f64 + (k + 1 - a) as f64);
                w += prob * weight;
                wc += prob * weight * c;
                wcc += prob * weight * c * c;
            }
        }
        let expected_variance = wcc / w - (wc / w) * (wc / w);
        let v = mixing_state(&positions, &volumes, &is_a, k, Concentration::Volume);
        let p_volume = 8.0 * p_real / (8.0 * p_real + 1.0 - p_real);
        assert!((v.fraction_a - p_volume).abs() < 1e-12, "{v:?}");
        let is_volume = expected_variance.sqrt();
        assert!(
            (v.intensity_of_segregation / is_volume - 1.0).abs() < 0.03,
            "{v:?} against {is_volume}"
        );
        let expected_m = (p_volume * (1.0 - p_volume) - expected_variance) / (p_volume * (1.0 - p_volume));
        assert!((v.lacey_index - expected_m).abs() < 0.03, "{v:?} against {expected_m}");
        assert!(
            v.lacey_index < s.lacey_index - 0.05,
            "by volume a random size pair reads lower"
        );
    }

    #[test]
    fn equal_sizes_read_the_same_by_number_and_by_volume() {
        let (positions, is_a) = random_mixture(5000, 0.4, 23);
        let volumes = vec![4.0 / 3.0 * std::f64::consts::PI * 1e-9; 5000];
        let a = mixing_state(&positions, &volumes, &is_a, SEED_000_NEIGHBOURS, Concentration::Number);
        let b = mixing_state(&positions, &volumes, &is_a, SEED_000_NEIGHBOURS, Concentration::Volume);
        assert!((a.lacey_index - b.lacey_index).abs() < 1e-12, "{a:?} {b:?}");
        assert!((a.intensity_of_segregation - b.intensity_of_segregation).abs() < 1e-12);
    }

    #[test]
    fn degenerate_beds_give_defined_values() {
        let empty = mixing_state(&[], &[], &[], 10, Concentration::Number);
        assert_eq!(
            empty,
            MixingState {
                fraction_a: 0.0,
                intensity_of_segregation: 0.0,
                lacey_index: 1.0,
                relative_standard_deviation: 0.0,
                samples: 0
            }
        );
        let (positions, _) = random_mixture(50, 0.5, 3);
        let volumes = vec![1e-9; 50];
        for all_a in [true, false] {
            let s = mixing_state(&positions, &volumes, &[all_a; 50], 10, Concentration::Number);
            assert_eq!(s.fraction_a, if all_a { 1.0 } else { 0.0 });
            assert_eq!(
                (s.intensity_of_segregation, s.lacey_index, s.relative_standard_deviation),
                (0.0, 1.0, 0.0)
            );
        }
        // Both species present but no volume at all.
        let alternate: Vec<bool> = (0..50).map(|i| i % 2 == 0).collect();
        let s = mixing_state(&positions, &[0.0; 50], &alternate, 10, Concentration::Volume);
        assert_eq!((s.fraction_a, s.lacey_index), (0.0, 1.0));

        // Fewer particles than one sample: every sample is the bed, c_i = P, M = N/(N − 1).
        let s = mixing_state(
            &positions[..3],
            &volumes[..3],
            &[true, false, false],
            10,
            Concentration::Number,
        );
        assert!((s.fraction_a - 1.0 / 3.0).abs() < 1e-15);
        assert!(s.intensity_of_segregation < 1e-15);
        assert!((s.lacey_index - 1.5).abs() < 1e-12, "{s:?}");
        // A single particle.
        let s = mixing_state(&positions[..1], &volumes[..1], &[true], 10, Concentration::Number);
        assert_eq!((s.intensity_of_segregation, s.lacey_index, s.samples), (0.0, 1.0, 1));

        // A broken position does not make the indices NaN.
        let mut broken = positions.clone();
        broken[4] = Vec3::new(f64::NAN, 0.0, 0.0);
        let is_a: Vec<bool> = (0..50).map(|i| i % 2 == 0).collect();
        let s = mixing_state(&broken, &volumes, &is_a, 10, Concentration::Number);
        assert!(s.intensity_of_segregation.is_finite() && s.lacey_index.is_finite());
    }

    #[test]
    fn height_index_is_three_segregated_and_one_mixed() {
        // A uniform column of 1000 heights on y = 0.
        let n = 1000;
        let heights: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) * D_M).collect();
        let family = above_median_height(&heights);
        assert_eq!(family.iter().filter(|&&f| f).count(), n / 2);
        assert!(family[n / 2] && !family[n / 2 - 1]);
        assert!((height_mixing_index(&heights, &family) - 3.0).abs() < 1e-12);
        // Families interleaved: h̄1/h̄2 = (n/2 − 1/2)/(n/2 + 1/2) → 1.
        let alternate: Vec<bool> = (0..n).map(|i| i % 2 == 0).collect();
        let expected = (n as f64 / 2.0 - 0.5) / (n as f64 / 2.0 + 0.5);
        assert!((height_mixing_index(&heights, &alternate) - expected).abs() < 1e-12);
        // The index follows the particles, not their slots: swap the halves and it inverts.
        let reversed: Vec<bool> = family.iter().map(|f| !f).collect();
        assert!((height_mixing_index(&heights, &reversed) - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn height_index_edge_cases() {
        assert_eq!(height_mixing_index(&[], &[]), 1.0);
        assert_eq!(height_mixing_index(&[1.0, 2.0], &[true, true]), 1.0);
        assert_eq!(height_mixing_index(&[1.0, 0.0], &[true, false]), f64::INFINITY);
        assert_eq!(height_mixing_index(&[0.0, 0.0], &[true, false]), 1.0);
        // Median of an odd count and ties at the median: those at the median are in family 1.
        assert_eq!(above_median_height(&[3.0, 1.0, 2.0]), vec![true, false, true]);
        assert_eq!(
            above_median_height(&[1.0, 2.0, 2.0, 2.0]),
            vec![false, true, true, true]
        );
        assert_eq!(above_median_height(&[f64::NAN, 1.0, 2.0]), vec![false, false, true]);
        assert!(above_median_height(&[]).is_empty());
    }

    /// `cargo test --release --lib analysis::mixing::tests::timing_100k -- --ignored --nocapture`
    #[test]
    #[ignore = "timing; run in release"]
    fn timing_100k() {
        let n = 100_000;
        let (positions, is_a) = random_mixture(n, 0.5, 5);
        let volumes = vec![1e-9; n];
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..5 {
            let start = std::time::Instant::now();
            let s = mixing_state(&positions, &volumes, &is_a, SEED_000_NEIGHBOURS, Concentration::Number);
            times.push(start.elapsed());
            if let Some(previous) = last {
                assert_eq!(previous, s, "deterministic");
            }
            last = Some(s);
        }
        times.sort();
        println!(
            "mixing_state: {n} particles, k = 10: median {:?} (min {:?}, max {:?})",
            times[2], times[0], times[4]
        );
        assert!(times[2] < std::time::Duration::from_millis(500), "well under a second");
    }
}
