//! The capillary force of bridges between unequal particles — different radii or contact angles — read from a
//! table of exact Young–Laplace bridges (seed 000 eqs 6.5–6.28; PHYSICS §2: "a precomputed lookup table over
//! (R_i/R_j, θ_i, θ_j, V̂, Ŝ) built by a numerical solver that ships with the code").
//!
//! One table per pair of species, so R_i/R_j, θ_i and θ_j are fixed per table and it spans (V̂, Ŝ): rows of fixed
//! gap Ŝ = S/R₁ (0, then geometric from 1e-4 to 1), each holding the pendular bridges of filling angle β₁ from 1.3
//! rad down to 2e-3 rad on sphere 1 ([`SpherePair::bridge_near`], each bridge's Δp the guess for the next, until
//! the family ends), as (ln V̂, F̂) pairs with V̂ = V/R₁³ and F̂ = F/(γR₁), kept from the smallest volume up (the
//! stable branch). Lookups interpolate F̂ linearly in ln V̂ within the two rows around Ŝ, then ln F̂ linearly in Ŝ
//! (the force decays about exponentially with the gap). Past the last row that holds the volume (the bridge's last
//! pendular profile) that row's force is held: a bridge pulls until it breaks, which it does at Lian's gap
//! (`cohesion.rs`). Built in parallel at first use (1–3 s per pair of unlike species on two cores) and cached on disk
//! (`capillary_cache.rs`).

use super::young_laplace::SpherePair;

/// Rows: Ŝ = 0 and GAP_ROWS geometric gaps from SMALLEST_GAP to LARGEST_GAP.
const GAP_ROWS: usize = 48;
const SMALLEST_GAP: f64 = 1e-4;
const LARGEST_GAP: f64 = 1.0;
/// Columns: filling angles β₁, geometric.
const FILLING_ANGLES: usize = 72;
const SMALLEST_FILLING_ANGLE_RAD: f64 = 2e-3;
const LARGEST_FILLING_ANGLE_RAD: f64 = 1.3;

/// The bridges of one gap: ln V̂ strictly increasing, F̂ beside it.
#[derive(Debug, Clone, PartialEq)]
struct Row {
    ln_volume: Vec<f64>,
    force: Vec<f64>,
}

impl Row {
    /// F̂ at ln V̂ (held at the largest tabulated volume beyond it); `None` below the smallest volume that spans
    /// this gap.
    fn force_at(&self, ln_volume: f64) -> Option<f64> {
        let n = self.ln_volume.len();
        if n == 0 || ln_volume < self.ln_volume[0] {
            return None;
        }
        if ln_volume >= self.ln_volume[n - 1] {
            return Some(self.force[n - 1]);
        }
        let k = self.ln_volume.partition_point(|&v| v <= ln_volume) - 1;
        let w = (ln_volume - self.ln_volume[k]) / (self.ln_volume[k + 1] - self.ln_volume[k]);
        Some(self.force[k] + w * (self.force[k + 1] - self.force[k]))
    }
}

/// Exact capillary forces for one pair of particle kinds.
#[derive(Debug, Clone, PartialEq)]
pub struct CapillaryTable {
    /// R₁, the length unit of the table, m.
    radius_1_m: f64,
    rows: Vec<Row>,
}

fn gap_of_row(k: usize) -> f64 {
    if k == 0 {
        0.0
    } else {
        SMALLEST_GAP * (LARGEST_GAP / SMALLEST_GAP).powf((k - 1) as f64 / (GAP_ROWS - 1) as f64)
    }
}

impl CapillaryTable {
    /// Solves the table for spheres of radii R₁, R₂ and contact angles θ₁, θ₂.
    pub fn new(radius_1_m: f64, radius_2_m: f64, contact_angle_1_rad: f64, contact_angle_2_rad: f64) -> Self {
        use rayon::prelude::*;
        let rows = (0..=GAP_ROWS)
            .into_par_iter()
            .map(|k| {
                let pair = SpherePair {
                    radius_ratio: radius_2_m / radius_1_m,
                    gap: gap_of_row(k),
                    contact_angle_1_rad,
                    contact_angle_2_rad,
                };
                // Follow the family from the largest filling angle down, each bridge's Δp the next one's guess.
                let mut solved: Vec<(f64, f64)> = Vec::new();
                let mut guess = None;
                for c in (0..FILLING_ANGLES).rev() {
                    let beta = SMALLEST_FILLING_ANGLE_RAD
                        * (LARGEST_FILLING_ANGLE_RAD / SMALLEST_FILLING_ANGLE_RAD)
                            .powf(c as f64 / (FILLING_ANGLES - 1) as f64);
                    match pair
                        .bridge_near(beta, guess)
                        .filter(|b| b.volume > 0.0 && b.force.is_finite())
                    {
                        Some(b) => {
                            guess = Some(b.pressure);
                            solved.push((b.volume.ln(), b.force));
                        }
                        // The pendular family ends here (below, only profiles hugging sphere 1 meet sphere 2).
                        None if guess.is_some() => break,
                        None => {}
                    }
                }
                solved.reverse();
                // Across a gap the volume first falls with β₁ (thin necks: the unstable branch) and then grows:
                // keep the stable branch from the smallest volume on.
                let start = solved
                    .iter()
                    .enumerate()
                    .min_by(|a, b| a.1.0.total_cmp(&b.1.0))
                    .map_or(0, |(k, _)| k);
                let mut row = Row {
                    ln_volume: Vec::new(),
                    force: Vec::new(),
                };
                for &(ln_v, force) in &solved[start..] {
                    if row.ln_volume.last().is_none_or(|&last| ln_v > last) {
                        row.ln_volume.push(ln_v);
                        row.force.push(force);
                    }
                }
                row
            })
            .collect();
        CapillaryTable { radius_1_m, rows }
    }

    /// The rows as (ln V̂, F̂) columns, for the cache (`capillary_cache.rs`).
    pub fn rows(&self) -> Vec<(Vec<f64>, Vec<f64>)> {
        self.rows
            .iter()
            .map(|r| (r.ln_volume.clone(), r.force.clone()))
            .collect()
    }

    /// A table from rows [`CapillaryTable::rows`] gave, in R₁ = `radius_1_m`.
    pub fn from_rows(radius_1_m: f64, rows: Vec<(Vec<f64>, Vec<f64>)>) -> Self {
        let rows = rows
            .into_iter()
            .map(|(ln_volume, force)| Row { ln_volume, force })
            .collect();
        CapillaryTable { radius_1_m, rows }
    }

    /// F/(γR₁) for a bridge of V̂ = V/R₁³ = `volume` across Ŝ = S/R₁ = `gap` (overlap counts as contact).
    pub fn dimensionless_force(&self, volume: f64, gap: f64) -> f64 {
        let ln_v = volume.ln();
        let gap = gap.max(0.0);
        let (k, w) = if gap >= LARGEST_GAP {
            (GAP_ROWS - 1, 1.0)
        } else if gap < SMALLEST_GAP {
            (0, gap / SMALLEST_GAP)
        } else {
            let step = (LARGEST_GAP / SMALLEST_GAP).ln() / (GAP_ROWS - 1) as f64;
            let s = (gap / SMALLEST_GAP).ln() / step;
            let k = (s.floor() as usize).min(GAP_ROWS - 2);
            (
                k + 1,
                (gap - gap_of_row(k + 1)) / (gap_of_row(k + 2) - gap_of_row(k + 1)),
            )
        };
        // The force decays about exponentially with the gap (Mikami's form): interpolate its logarithm. Where the
        // far row is past the bridge's last profile, hold the near row's force (a bridge pulls until it breaks).
        match (self.rows[k].force_at(ln_v), self.rows[k + 1].force_at(ln_v)) {
            (Some(near), Some(far)) if near > 0.0 && far > 0.0 => near * (far / near).powf(w),
            (Some(near), Some(far)) => (near + w * (far - near)).max(0.0),
            (Some(near), None) => near.max(0.0),
            (None, Some(far)) => far.max(0.0),
            (None, None) => 0.0,
        }
    }

    /// The attractive force of a bridge of `volume_m3` across the surface gap `gap_m`, N.
    #[inline]
    pub fn force_n(&self, volume_m3: f64, gap_m: f64, surface_tension_n_per_m: f64) -> f64 {
        let r = self.radius_1_m;
        surface_tension_n_per_m * r * self.dimensionless_force(volume_m3 / (r * r * r), gap_m / r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::models::capillary::mikami_dimensionless_force;
    use std::f64::consts::PI;

    /// Between its nodes the table stays within 1 % of the direct solve of the bridge (relative to the force at
    /// contact: near the end of its pendular profiles a bridge's force falls steeply to a few thousandths of
    /// that), for unequal radii and contact angles, over the volumes and gaps a wet bed sees.
    #[test]
    fn the_table_matches_direct_solves_between_its_nodes() {
        let (t1, t2) = (20.0f64.to_radians(), 50.0f64.to_radians());
        let table = CapillaryTable::new(1.0, 1.6, t1, t2);
        let pair = |gap: f64| SpherePair {
            radius_ratio: 1.6,
            gap,
            contact_angle_1_rad: t1,
            contact_angle_2_rad: t2,
        };
        let mut compared = 0;
        for volume in [2e-4f64, 3e-3, 0.02] {
            let at_contact = pair(0.0).bridge(volume).expect("a bridge at contact").force;
            let rupture = volume.cbrt() * (1.0 + 0.25 * (t1 + t2));
            for fraction in [0.0, 0.13, 0.37, 0.61] {
                let gap = fraction * rupture;
                let Some(exact) = pair(gap).bridge(volume) else {
                    continue;
                };
                let tabulated = table.dimensionless_force(volume, gap);
                assert!(
                    (tabulated - exact.force).abs() < 0.01 * at_contact,
                    "V {volume} S {gap}: table {tabulated} vs {} (at contact {at_contact})",
                    exact.force
                );
                compared += 1;
            }
        }
        assert!(compared >= 10, "only {compared} bridges solved");
    }

    /// VALIDATION B2 through the table: equal spheres at θ = 0 are within 5 % of Mikami's fit (F = πRγF̂, the
    /// reading settled in `capillary.rs`) over V̂ 1e-3–5e-2 and gaps up to 0.2 R and 0.4 V̂^⅓ (closer to
    /// rupture the fit falls below the exact bridge: 0.61 against 0.82 at V̂ = 1e-3, Ŝ = 0.05).
    #[test]
    fn b2_the_table_agrees_with_mikami_in_the_equal_wetting_limit() {
        let table = CapillaryTable::new(1.0, 1.0, 0.0, 0.0);
        for volume in [1e-3f64, 1e-2, 5e-2] {
            for gap in [0.0, 0.02, 0.05, 0.1, 0.2] {
                if gap > 0.4 * volume.cbrt() {
                    continue;
                }
                let tabulated = table.dimensionless_force(volume, gap);
                let fit = PI * mikami_dimensionless_force(volume, gap, 0.0);
                assert!(
                    (fit / tabulated - 1.0).abs() < 0.05,
                    "V {volume} S {gap}: Mikami {fit} vs table {tabulated}"
                );
            }
        }
    }

    /// Units: a table built for R₁ = 1 mm gives γR₁F̂ in newtons, and the force falls with the gap.
    #[test]
    fn forces_scale_with_surface_tension_and_radius_and_fall_with_the_gap() {
        let table = CapillaryTable::new(1e-3, 2e-3, 0.1, 0.3);
        let v = 1e-3 * 1e-9;
        let f0 = table.force_n(v, 0.0, 0.07);
        assert!((f0 / (0.07 * 1e-3 * table.dimensionless_force(1e-3, 0.0)) - 1.0).abs() < 1e-12);
        let f1 = table.force_n(v, 2e-5, 0.07);
        let f2 = table.force_n(v, 6e-5, 0.07);
        assert!(f0 > f1 && f1 > f2 && f2 > 0.0, "{f0} {f1} {f2}");
        assert_eq!(table.force_n(v, -1e-6, 0.07), f0);
    }
}
