//! Conduction through a liquid bridge (seed 000 §7.2.1, eqs 7.8–7.11): H_l = k_l ⟨A_l⟩/d = k_l V/d², d the
//! bridge's length along the line of centres, d = h_i + h_j + S (7.11), h the heights of the wetted caps, S the gap.
//! The seed takes the caps from the parabolic bridge of §6.2 at every gap ("the full profile history"), which is
//! [`ParabolicBridge::solve`]; solving it costs milliseconds, so each species pair gets a table of d/R_i over the
//! bridge volume and the gap, built when the run starts (about 2 s per pair on two cores; within about 1 % of the
//! parabola between its nodes).
//!
//! CHOICE (the seed does not say): an overlap (a soft-sphere artefact) does not shorten the bridge: d is the bridge's
//! at contact; where the parabola no longer fits (for small contact angles it pinches off before Lian's rupture gap,
//! `liquid_transfer.rs`), the length at the largest gap where it does is held until the bridge breaks.
//!
//! What does not live here: which pairs have a bridge and its volume (`engine::liquid`), adding H_l ΔT to the
//! particles' heat (the pair pass).

use super::capillary::lian_rupture_gap_m;
use super::liquid_transfer::ParabolicBridge;

/// Volumes: V̂ = V/R_i³ log-spaced from 1e-6 to 1, five per decade.
const VOLUME_DECADES: (i32, i32) = (-6, 0);
const VOLUMES_PER_DECADE: usize = 5;
/// Gaps: S/S_c = (m/10)², m = 0..10 (S_c Lian's rupture gap of the volume): dense near contact, where the caps
/// change fastest with the gap.
const GAP_FRACTIONS: usize = 11;

/// d/R_i of one species pair over (ln V̂, S/S_c): ln(d/R_i) interpolated bilinearly (a small bridge's d grows as
/// √V, which that interpolates exactly; linear in V̂ it would be 0.7 % long between nodes) and held constant beyond
/// the ends.
#[derive(Debug, Clone, PartialEq)]
pub struct BridgeLengthTable {
    radius_i_m: f64,
    /// (θ_i + θ_j), for Lian's rupture gap.
    contact_angle_i_rad: f64,
    contact_angle_j_rad: f64,
    /// ln(d/R_i), row-major: volume k, gap fraction m at `k * GAP_FRACTIONS + m`.
    ln_length_over_radius: Vec<f64>,
}

impl BridgeLengthTable {
    /// The table of spheres i and j (a wall: `radius_j_m` infinite, taken as 10⁴ R_i), built in parallel. `None`
    /// if no parabolic bridge fits at any node (it always does for the angles and volumes of pendular bridges).
    pub fn new(radius_i_m: f64, radius_j_m: f64, contact_angle_i_rad: f64, contact_angle_j_rad: f64) -> Option<Self> {
        use rayon::prelude::*;
        let radius_j_m = if radius_j_m.is_finite() {
            radius_j_m
        } else {
            1e4 * radius_i_m
        };
        let volumes = Self::volumes();
        let rows: Vec<Vec<Option<f64>>> = (0..volumes)
            .into_par_iter()
            .map(|k| {
                let volume_m3 = Self::volume_hat(k) * radius_i_m.powi(3);
                let rupture_m = lian_rupture_gap_m(volume_m3, contact_angle_i_rad, contact_angle_j_rad);
                (0..GAP_FRACTIONS)
                    .map(|m| {
                        let root = m as f64 / (GAP_FRACTIONS - 1) as f64;
                        let gap_m = rupture_m * root * root;
                        ParabolicBridge::solve(
                            radius_i_m,
                            radius_j_m,
                            contact_angle_i_rad,
                            contact_angle_j_rad,
                            volume_m3,
                            gap_m,
                        )
                        .map(|b| b.d_m / radius_i_m)
                    })
                    .collect()
            })
            .collect();
        // Along each row, a gap without a bridge takes the length at the largest smaller gap that has one; a row
        // without any takes the nearest row's.
        let filled: Vec<Option<Vec<f64>>> = rows
            .iter()
            .map(|row| {
                let mut last = row[0]?;
                Some(
                    row.iter()
                        .map(|v| {
                            if let Some(v) = v {
                                last = *v;
                            }
                            last
                        })
                        .collect(),
                )
            })
            .collect();
        let mut ln_length_over_radius = Vec::with_capacity(volumes * GAP_FRACTIONS);
        for k in 0..volumes {
            let row = (0..volumes)
                .flat_map(|d| [k.checked_sub(d), Some(k + d)])
                .flatten()
                .find_map(|m| filled.get(m).cloned().flatten())?;
            ln_length_over_radius.extend(row.iter().map(|d| d.ln()));
        }
        Some(BridgeLengthTable {
            radius_i_m,
            contact_angle_i_rad,
            contact_angle_j_rad,
            ln_length_over_radius,
        })
    }

    fn volumes() -> usize {
        (VOLUME_DECADES.1 - VOLUME_DECADES.0) as usize * VOLUMES_PER_DECADE + 1
    }

    fn ln_step() -> f64 {
        std::f64::consts::LN_10 / VOLUMES_PER_DECADE as f64
    }

    fn ln_lo() -> f64 {
        VOLUME_DECADES.0 as f64 * std::f64::consts::LN_10
    }

    fn volume_hat(k: usize) -> f64 {
        (Self::ln_lo() + k as f64 * Self::ln_step()).exp()
    }

    /// The largest V̂/(d/R_i)² over the nodes: H_l/(k_l R_i) of the most conductive bridge tabulated.
    pub fn largest_volume_over_length_squared_per_radius(&self) -> f64 {
        (0..Self::volumes())
            .flat_map(|k| (0..GAP_FRACTIONS).map(move |m| (k, m)))
            .map(|(k, m)| Self::volume_hat(k) * (-2.0 * self.ln_length_over_radius[k * GAP_FRACTIONS + m]).exp())
            .fold(0.0, f64::max)
    }

    /// d of a bridge of `volume_m3` at surface gap `gap_m` (negative: overlapping, taken as contact), m.
    pub fn length_m(&self, volume_m3: f64, gap_m: f64) -> f64 {
        let rupture_m = lian_rupture_gap_m(volume_m3, self.contact_angle_i_rad, self.contact_angle_j_rad);
        let x = ((volume_m3 / self.radius_i_m.powi(3)).ln() - Self::ln_lo()) / Self::ln_step();
        let y = (gap_m.max(0.0) / rupture_m).sqrt() * (GAP_FRACTIONS - 1) as f64;
        let (k, s) = split(x, Self::volumes() - 1);
        let (m, t) = split(y, GAP_FRACTIONS - 1);
        let at = |k: usize, m: usize| self.ln_length_over_radius[k * GAP_FRACTIONS + m];
        let (k1, m1) = ((k + 1).min(Self::volumes() - 1), (m + 1).min(GAP_FRACTIONS - 1));
        let low = at(k, m) * (1.0 - t) + at(k, m1) * t;
        let high = at(k1, m) * (1.0 - t) + at(k1, m1) * t;
        (low * (1.0 - s) + high * s).exp() * self.radius_i_m
    }
}

/// The cell of a table coordinate and the fraction into it, clamped to [0, last].
fn split(x: f64, last: usize) -> (usize, f64) {
    if x.is_nan() || x <= 0.0 {
        (0, 0.0)
    } else if x >= last as f64 {
        (last, 0.0)
    } else {
        let k = x.floor() as usize;
        (k, x - k as f64)
    }
}

/// H_l = k_l V/d² (eq. 7.10), W/K.
pub fn bridge_conductance_w_per_k(liquid_conductivity_w_per_m_k: f64, volume_m3: f64, length_m: f64) -> f64 {
    liquid_conductivity_w_per_m_k * volume_m3 / (length_m * length_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Off the table's nodes, its length agrees with the parabola solved there to 1.5 % (H_l to 3 %), for equal
    /// and unequal spheres and for a sphere and a wall.
    #[test]
    fn the_table_follows_the_parabolic_bridge_between_its_nodes() {
        let deg = |d: f64| d.to_radians();
        for (ri, rj, ti, tj) in [
            (1e-3, 1e-3, deg(0.0), deg(0.0)),
            (1e-3, 0.8e-3, deg(20.0), deg(40.0)),
            (1e-3, f64::INFINITY, deg(10.0), deg(10.0)),
        ] {
            let start = std::time::Instant::now();
            let table = BridgeLengthTable::new(ri, rj, ti, tj).expect("bridges fit");
            println!("table built in {:.2} s", start.elapsed().as_secs_f64());
            let rj_solved = if rj.is_finite() { rj } else { 1e4 * ri };
            let mut worst: f64 = 0.0;
            for volume_hat in [3e-4, 2e-3, 0.013] {
                let volume = volume_hat * ri * ri * ri;
                let rupture = lian_rupture_gap_m(volume, ti, tj);
                for fraction in [0.0, 0.05, 0.33] {
                    let gap = fraction * rupture;
                    let Some(exact) = ParabolicBridge::solve(ri, rj_solved, ti, tj, volume, gap) else {
                        continue;
                    };
                    let d = table.length_m(volume, gap);
                    worst = worst.max((d / exact.d_m - 1.0).abs());
                    assert!(
                        (d / exact.d_m - 1.0).abs() < 0.015,
                        "R_j {rj}, V̂ {volume_hat}, S/S_c {fraction}: table {d:e}, parabola {:e}",
                        exact.d_m
                    );
                }
            }
            println!("R_j {rj}: largest table error in d {worst:.2e}");
        }
    }

    /// A small bridge between touching equal spheres (θ = 0), filling angle α: the parabola through the contact
    /// circles (radius R α, a distance d = 2 R (1 − cos α) ≈ R α² apart, end slopes ∓cot α) is
    /// y = R α (1 − ξ + ξ²) with ξ = x/d, so V = π R³ α⁴ (7/10 − 1/2) (the solid minus both caps) and
    /// H_l = k_l V/d² → (π/5) k_l R whatever the volume. (A toroidal meniscus fills the wedge out to the contact
    /// circle, V ≈ (π/2) R³ α⁴, and would conduct 2.5 times more: the parabola is the seed's profile.)
    #[test]
    fn a_small_bridge_at_contact_conducts_pi_over_five_k_r() {
        let r = 1e-3;
        let table = BridgeLengthTable::new(r, r, 0.0, 0.0).unwrap();
        for volume_hat in [1e-6, 1e-5] {
            let v = volume_hat * r * r * r;
            let h = bridge_conductance_w_per_k(0.6, v, table.length_m(v, 0.0));
            let limit = std::f64::consts::PI / 5.0 * 0.6 * r;
            println!("V̂ {volume_hat}: H_l / (π/5 k_l R) = {}", h / limit);
            assert!((h / limit - 1.0).abs() < 0.1, "{}", h / limit);
        }
    }
}
