//! The wall-to-bed heat transfer coefficient h_w of a heated rotating drum (seed 000 §5.2.4, eqs 5.16–5.21) and the
//! two readings of the bed it is computed from: the core temperature ⟨T_c(t)⟩ and the arc of wall the bed touches.
//!
//! h_w comes from the slope of ln((T_w − ⟨T_c⟩)/(T_w − T_0)) against t (eq. 5.19, Ito et al.):
//! h_w = c_p w (1 − e^{slope·t_c})/(A t_c) (eq. 5.21), w the bed's mass, A = θ_arc R L the wall area the bed
//! touches and t_c the time a point of the wall stays under the bed. The seed prints t_c = l_arc/(2πΩ) (eq. 5.18),
//! whose units work with l_arc the arc's angle θ_arc (rad) and Ω in rev/s: t_c = θ_arc/(2πΩ) = θ_arc/ω.
//!
//! CHOICE (the seed leaves them open): the core is a disc in the drum's cross-section around the bed's centroid,
//! of radius `radius_fraction` × the centroid's distance to the wall (the seed's "small core region", Fig. 69:
//! another size gives another h_w); the arc is the span of the largest run of wall contacts around the drum; the
//! slope is a least-squares line with a free intercept (the core warms only once heat has reached it, so the
//! line through the origin of eq. 5.20 would be bent by that delay).
//!
//! Pure functions of values passed in, like the rest of `analysis`.

use crate::engine::Vec3;

/// A drum's axis and radius, the frame of its cross-section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrumAxis {
    pub axis_point_m: Vec3,
    /// Unit vector.
    pub axis: Vec3,
    pub radius_m: f64,
}

impl DrumAxis {
    /// The part of `x − axis_point` across the axis: the position in the cross-section.
    fn across(&self, x: &Vec3) -> Vec3 {
        let d = x - self.axis_point_m;
        d - self.axis * d.dot(&self.axis)
    }
}

/// The bed's core at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoreReading {
    /// The mass-weighted mean temperature of the particles whose centres lie in the core, K (NaN if none).
    pub temperature_k: f64,
    pub particles: usize,
    /// The core disc's radius, m.
    pub radius_m: f64,
}

/// The core of the bed ([module docs](self)): the particles whose centres lie within `radius_fraction` × (R −
/// |c|) of the bed's mass centroid c in the cross-section.
pub fn bed_core(
    drum: &DrumAxis,
    positions_m: &[Vec3],
    masses_kg: &[f64],
    temperatures_k: &[f64],
    radius_fraction: f64,
) -> CoreReading {
    let mass_kg: f64 = masses_kg.iter().sum();
    let centroid = positions_m
        .iter()
        .zip(masses_kg)
        .fold(Vec3::zeros(), |s, (x, m)| s + drum.across(x) * *m)
        / mass_kg;
    let radius_m = radius_fraction * (drum.radius_m - centroid.norm()).max(0.0);
    let (mut heat, mut mass, mut particles) = (0.0, 0.0, 0);
    for ((x, m), t) in positions_m.iter().zip(masses_kg).zip(temperatures_k) {
        if (drum.across(x) - centroid).norm() < radius_m {
            heat += m * t;
            mass += m;
            particles += 1;
        }
    }
    CoreReading {
        temperature_k: if particles > 0 { heat / mass } else { f64::NAN },
        particles,
        radius_m,
    }
}

/// Two wall contacts further apart round the drum than this many particle diameters belong to different runs.
const ARC_GAP_DIAMETERS: f64 = 4.0;

/// The angle of wall the bed touches, rad: the particles whose surface reaches the drum (centre beyond R − r, or
/// beyond R − r − r_b on a wall of glued beads of radius `bead_radius_m` = r_b, whose centres lie on the cylinder:
/// within reach of a bead) are sorted by their angle round the axis and cut into runs where neighbours are more
/// than four diameters apart; the span of the run with the most particles (a stray particle elsewhere on the wall
/// does not widen it). 0 without contacts.
pub fn wall_contact_arc_rad(drum: &DrumAxis, positions_m: &[Vec3], radii_m: &[f64], bead_radius_m: f64) -> f64 {
    // Any unit vector across the axis as the angle's origin.
    let e1 = drum
        .axis
        .cross(&Vec3::x())
        .try_normalize(1e-6)
        .unwrap_or_else(|| drum.axis.cross(&Vec3::y()).normalize());
    let e2 = drum.axis.cross(&e1);
    let mut angles: Vec<f64> = positions_m
        .iter()
        .zip(radii_m)
        .filter_map(|(x, r)| {
            let d = drum.across(x);
            (d.norm() > drum.radius_m - r - bead_radius_m).then(|| d.dot(&e2).atan2(d.dot(&e1)))
        })
        .collect();
    if angles.is_empty() {
        return 0.0;
    }
    angles.sort_by(f64::total_cmp);
    let diameter_m = 2.0 * radii_m.iter().fold(0.0, |a: f64, &r| a.max(r));
    let gap_rad = ARC_GAP_DIAMETERS * diameter_m / drum.radius_m;
    let n = angles.len();
    // Start the runs after the widest gap (wrapping round), so that no run is split at ±π.
    let step = |k: usize| {
        let next = angles[(k + 1) % n];
        let d = next - angles[k];
        if k + 1 == n { d + std::f64::consts::TAU } else { d }
    };
    let widest = (0..n).max_by(|&a, &b| step(a).total_cmp(&step(b))).expect("not empty");
    if n == 1 || step(widest) <= gap_rad {
        // One particle, or contacts all round the wall.
        return if n == 1 {
            0.0
        } else {
            std::f64::consts::TAU - step(widest)
        };
    }
    let (mut best_count, mut best_span) = (0, 0.0);
    let (mut count, mut span) = (1, 0.0);
    for m in 1..=n {
        let k = (widest + m) % n;
        if m == n || step(k) > gap_rad {
            if count > best_count {
                (best_count, best_span) = (count, span);
            }
            (count, span) = (1, 0.0);
        } else {
            count += 1;
            span += step(k);
        }
    }
    best_span
}

/// What h_w is computed from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallHeatInputs {
    /// The wall's temperature T_w, K.
    pub wall_temperature_k: f64,
    /// The core's temperature when the wall starts heating, T_0, K.
    pub initial_core_temperature_k: f64,
    /// c_p of the bed, J/(kg K).
    pub heat_capacity_j_per_kg_k: f64,
    /// w, kg.
    pub bed_mass_kg: f64,
    /// R, m.
    pub drum_radius_m: f64,
    /// L, the drum's length along its axis, m.
    pub drum_length_m: f64,
    /// θ_arc, rad.
    pub contact_arc_rad: f64,
    /// ω, rad/s (its size).
    pub angular_speed_rad_per_s: f64,
}

/// The fit and h_w.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallHeatFit {
    /// d/dt ln((T_w − ⟨T_c⟩)/(T_w − T_0)), 1/s (negative while the core warms).
    pub slope_per_s: f64,
    pub r_squared: f64,
    /// t_c = θ_arc/ω, s.
    pub contact_time_s: f64,
    /// A = θ_arc R L, m².
    pub contact_area_m2: f64,
    /// h_w (eq. 5.21), W/(m² K).
    pub coefficient_w_per_m2_k: f64,
    /// The fitted line's value at t = 0: ln((T_w − ⟨T_c⟩)/(T_w − T_0)) = intercept + slope · t.
    pub intercept: f64,
    /// T_w and T_0 of the fit, K.
    pub wall_temperature_k: f64,
    pub initial_core_temperature_k: f64,
    /// The first and last sample times the fit used, s.
    pub span_s: (f64, f64),
}

impl WallHeatFit {
    /// The core temperature the fitted line gives at `t_s`, K.
    pub fn core_temperature_k(&self, t_s: f64) -> f64 {
        let (tw, t0) = (self.wall_temperature_k, self.initial_core_temperature_k);
        tw - (tw - t0) * (self.intercept + self.slope_per_s * t_s).exp()
    }
}

/// Fits ln((T_w − ⟨T_c⟩)/(T_w − T_0)) over the samples (t, ⟨T_c⟩) (non-finite ones and ones at or above T_w
/// skipped) and turns the slope into h_w. `None` with fewer than 3 usable samples, no spread in time, or a drum
/// that does not turn or touch the bed.
pub fn wall_heat_transfer_coefficient(t_s: &[f64], core_k: &[f64], inputs: &WallHeatInputs) -> Option<WallHeatFit> {
    let WallHeatInputs {
        wall_temperature_k: tw,
        initial_core_temperature_k: t0,
        ..
    } = *inputs;
    let (t, y): (Vec<f64>, Vec<f64>) = t_s
        .iter()
        .zip(core_k)
        .filter(|(t, c)| t.is_finite() && c.is_finite() && **c < tw)
        .map(|(&t, &c)| (t, ((tw - c) / (tw - t0)).ln()))
        .filter(|(_, y)| y.is_finite())
        .unzip();
    if t.len() < 3 {
        return None;
    }
    // The line's arithmetic is `fit_line`'s (the same sums in the same order).
    let line = super::fit::fit_line(&t, &y)?;
    let (slope, r_squared) = (line.slope, line.r_squared);
    let contact_time_s = inputs.contact_arc_rad / inputs.angular_speed_rad_per_s;
    let contact_area_m2 = inputs.contact_arc_rad * inputs.drum_radius_m * inputs.drum_length_m;
    if !(contact_time_s.is_finite() && contact_time_s > 0.0 && contact_area_m2 > 0.0) {
        return None;
    }
    let coefficient = inputs.heat_capacity_j_per_kg_k * inputs.bed_mass_kg * -(slope * contact_time_s).exp_m1()
        / (contact_area_m2 * contact_time_s);
    Some(WallHeatFit {
        slope_per_s: slope,
        r_squared,
        contact_time_s,
        contact_area_m2,
        coefficient_w_per_m2_k: coefficient,
        intercept: line.intercept,
        wall_temperature_k: tw,
        initial_core_temperature_k: t0,
        span_s: (t[0], t[t.len() - 1]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const DRUM: DrumAxis = DrumAxis {
        axis_point_m: Vec3::new(0.0, 0.0, 0.0),
        axis: Vec3::new(0.0, 0.0, 1.0),
        radius_m: 0.1,
    };

    /// Ito's relation (eq. 5.19) run forward: a core that follows ln((T_w − T_c)/(T_w − T_0)) = (t/t_c) ln(1 −
    /// h_w A t_c/(c_p w)) gives back h_w, whatever the delay before the line starts.
    #[test]
    fn the_fit_returns_the_coefficient_of_itos_relation() {
        let inputs = WallHeatInputs {
            wall_temperature_k: 400.0,
            initial_core_temperature_k: 300.0,
            heat_capacity_j_per_kg_k: 800.0,
            bed_mass_kg: 0.2,
            drum_radius_m: 0.068,
            drum_length_m: 0.0124,
            contact_arc_rad: 2.4,
            angular_speed_rad_per_s: 15.0 * std::f64::consts::TAU / 60.0,
        };
        let h_w = 120.0;
        let t_c = inputs.contact_arc_rad / inputs.angular_speed_rad_per_s;
        let area = inputs.contact_arc_rad * inputs.drum_radius_m * inputs.drum_length_m;
        let rate = (1.0 - h_w * area * t_c / (800.0 * 0.2)).ln() / t_c;
        let t: Vec<f64> = (0..50).map(|k| 1.0 + 0.2 * k as f64).collect();
        let core: Vec<f64> = t
            .iter()
            .map(|t| 400.0 - 100.0 * (rate * (t - 1.0) - 0.01).exp())
            .collect();
        let fit = wall_heat_transfer_coefficient(&t, &core, &inputs).unwrap();
        assert!((fit.coefficient_w_per_m2_k - h_w).abs() < 1e-9 * h_w, "{fit:?}");
        assert!((fit.r_squared - 1.0).abs() < 1e-12);
        assert!((fit.contact_time_s - t_c).abs() < 1e-15);
    }

    #[test]
    fn the_core_is_a_disc_round_the_bed_centroid() {
        // Nine particles in a 3 × 3 block round (0, -0.05): the centroid is their middle one, 0.05 from the wall.
        let mut x = Vec::new();
        for i in -1..=1 {
            for j in -1..=1 {
                x.push(Vec3::new(
                    0.01 * i as f64,
                    -0.05 + 0.01 * j as f64,
                    0.003 * (i + j) as f64,
                ));
            }
        }
        let m = vec![1.0; 9];
        let t: Vec<f64> = (0..9).map(|k| 300.0 + k as f64).collect();
        // Radius 0.4 × 0.05 = 0.02: all but the four corners (0.0141 is inside, the corners 0.0141 too) -> all 9.
        let all = bed_core(&DRUM, &x, &m, &t, 0.4);
        assert_eq!((all.particles, all.radius_m), (9, 0.4 * 0.05));
        // Radius 0.15 × 0.05 = 0.0075: the middle one only (the axis component does not count).
        let middle = bed_core(&DRUM, &x, &m, &t, 0.15);
        assert_eq!(middle.particles, 1);
        assert_eq!(middle.temperature_k, 304.0);
    }

    #[test]
    fn the_arc_is_the_span_of_the_largest_run_of_wall_contacts() {
        let r = 0.0015;
        let at = |deg: f64| {
            let a = deg.to_radians();
            Vec3::new(0.0995 * a.cos(), 0.0995 * a.sin(), 0.0)
        };
        // A run from -150° to -30° every 3°, and one stray contact at +90°.
        let mut x: Vec<Vec3> = (0..=40).map(|k| at(-150.0 + 3.0 * k as f64)).collect();
        x.push(at(90.0));
        // Particles away from the wall do not count.
        x.push(Vec3::new(0.0, -0.05, 0.0));
        let radii = vec![r; x.len()];
        let arc = wall_contact_arc_rad(&DRUM, &x, &radii, 0.0);
        assert!((arc - 120f64.to_radians()).abs() < 1e-12, "{}", arc.to_degrees());
        // A run across ±180° is not split.
        let across: Vec<Vec3> = (0..=20).map(|k| at(150.0 + 3.0 * k as f64)).collect();
        let arc = wall_contact_arc_rad(&DRUM, &across, &vec![r; across.len()], 0.0);
        assert!((arc - 60f64.to_radians()).abs() < 1e-12, "{}", arc.to_degrees());
        assert_eq!(wall_contact_arc_rad(&DRUM, &[Vec3::zeros()], &[r], 0.0), 0.0);
        // On glued beads of radius r the bed's outer layer sits up to a bead radius further in (here at R − 1.4 r,
        // in the hollows between beads): it touches the beads, not the cylinder.
        let hollow = |deg: f64| {
            let a = deg.to_radians();
            Vec3::new((0.1 - 1.4 * r) * a.cos(), (0.1 - 1.4 * r) * a.sin(), 0.0)
        };
        let layer: Vec<Vec3> = (0..=30).map(|k| hollow(-120.0 + 2.0 * k as f64)).collect();
        let radii = vec![r; layer.len()];
        assert_eq!(wall_contact_arc_rad(&DRUM, &layer, &radii, 0.0), 0.0);
        let arc = wall_contact_arc_rad(&DRUM, &layer, &radii, r);
        assert!((arc - 60f64.to_radians()).abs() < 1e-12, "{}", arc.to_degrees());
    }
}
