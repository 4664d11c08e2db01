//! Velocity Verlet for translation and rotation of spheres, as LIGGGHTS/LAMMPS `nve/sphere` does it:
//! half kick → drift → forces (with half-step velocities) → half kick.
//!
//! The first half kick, the drift, the lost-particle check and the neighbour-list displacement check are one pass
//! over the particles ([`kick_drift`]); the second half kick is fused into the force pass (`pair_pass.rs`). The
//! integrator is memory-bound, so passes, not arithmetic, set its cost. Each particle is updated independently, so the parallel loops are
//! trivially deterministic.

use super::Vec3;
use super::geometry::Domain;
use super::heat::HeatConfig;
use super::particles::Particles;
use super::team::Team;

const CHUNK: usize = 2048;

/// Inverse masses and moments of inertia, derived once from the particle arrays (never checkpointed: they follow
/// from `mass_kg` and `inertia_kg_m2` exactly), so that each half kick multiplies instead of dividing. Without
/// rotation the inverse moments of inertia are zero: every torque then leaves the angular velocity as it is.
#[derive(Debug, Clone, Default)]
pub struct InverseInertia {
    pub inv_mass_per_kg: Vec<f64>,
    pub inv_inertia_per_kg_m2: Vec<f64>,
    /// 1/(m c_p), the temperature step per joule, K/J (empty without heat transfer).
    pub inv_thermal_mass_per_j_k: Vec<f64>,
}

impl InverseInertia {
    pub fn new(p: &Particles, rotation: bool, heat: Option<&HeatConfig>) -> Self {
        InverseInertia {
            inv_thermal_mass_per_j_k: heat.map_or_else(Vec::new, |h| h.inverse_thermal_mass(p)),
            inv_mass_per_kg: p.mass_kg.iter().map(|m| 1.0 / m).collect(),
            inv_inertia_per_kg_m2: p
                .inertia_kg_m2
                .iter()
                .map(|i| if rotation { 1.0 / i } else { 0.0 })
                .collect(),
        }
    }
}

/// v += ½dt (F/m + g), ω += ½dt T/I (the LIGGGHTS dtf/m form).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn half_kick_one(
    v: &mut Vec3,
    w: &mut Vec3,
    f: &Vec3,
    t: &Vec3,
    inv_m: f64,
    inv_inertia: f64,
    g_half_dt: &Vec3,
    half_dt: f64,
) {
    *v += f * (half_dt * inv_m) + g_half_dt;
    *w += t * (half_dt * inv_inertia);
}

/// First half of a step: half kick and drift (wrapped on periodic axes). Returns the largest squared displacement
/// of a particle in this drift (the simulation sums their roots into a bound on how far any particle has moved since
/// the neighbour list was built). With a `team` of several
/// threads, chunks run on it; with one, on the calling thread (per-particle arithmetic, so the same bits).
///
/// No checks here: velocities were checked finite by the kick that made them (`pair_pass.rs`), so positions stay
/// finite, and lost particles are looked for when the neighbour list is rebuilt (a particle cannot leave the box
/// by a radius without moving more than half the skin).
#[allow(clippy::too_many_arguments)]
pub fn kick_drift(
    p: &mut Particles,
    inverse: &InverseInertia,
    gravity: &Vec3,
    dt_s: f64,
    pseudo_2d: bool,
    domain: &Domain,
    team: &Team,
) -> f64 {
    let half_dt = 0.5 * dt_s;
    let g_half_dt = gravity * half_dt;
    let chunk =
        |_c: usize, x: &mut [Vec3], v: &mut [Vec3], w: &mut [Vec3], f: &[Vec3], t: &[Vec3], inv: (&[f64], &[f64])| {
            let mut max_d2 = 0.0f64;
            let particles = x
                .iter_mut()
                .zip(v.iter_mut())
                .zip(w.iter_mut())
                .zip(f.iter().zip(t))
                .zip(inv.0.iter().zip(inv.1));
            for ((((x, v), w), (f, t)), (&inv_m, &inv_i)) in particles {
                half_kick_one(v, w, f, t, inv_m, inv_i, &g_half_dt, half_dt);
                if pseudo_2d {
                    v.z = 0.0;
                    w.x = 0.0;
                    w.y = 0.0;
                }
                let dx = *v * dt_s;
                *x += dx;
                domain.wrap(x);
                max_d2 = max_d2.max(dx.norm_squared());
            }
            max_d2
        };
    if team.size() == 1 {
        // One chunk covering every particle: the same per-particle arithmetic, and the maximum of the chunk maxima
        // is the maximum.
        return chunk(
            0,
            &mut p.position_m,
            &mut p.velocity_m_per_s,
            &mut p.angular_velocity_rad_per_s,
            &p.force_n,
            &p.torque_n_m,
            (&inverse.inv_mass_per_kg, &inverse.inv_inertia_per_kg_m2),
        );
    }
    let parts: Vec<_> = p
        .position_m
        .chunks_mut(CHUNK)
        .zip(p.velocity_m_per_s.chunks_mut(CHUNK))
        .zip(p.angular_velocity_rad_per_s.chunks_mut(CHUNK))
        .zip(p.force_n.chunks(CHUNK).zip(p.torque_n_m.chunks(CHUNK)))
        .zip(
            inverse
                .inv_mass_per_kg
                .chunks(CHUNK)
                .zip(inverse.inv_inertia_per_kg_m2.chunks(CHUNK)),
        )
        .collect();
    team.map_parts(parts, |c, ((((x, v), w), (f, t)), inv)| chunk(c, x, v, w, f, t, inv))
        .into_iter()
        .fold(0.0, f64::max)
}

/// The first particle outside the box by more than `tolerance_m` on a non-periodic axis, or not finite; the
/// particles are scanned in chunks on `team`.
pub fn find_lost(position: &[Vec3], domain: &Domain, tolerance_m: f64, team: &Team) -> Option<usize> {
    let lost = |x: &Vec3| !(x.x + x.y + x.z).is_finite() || domain.is_lost(x, tolerance_m);
    team.map_chunks(position.len(), CHUNK, |particles| {
        let lo = particles.start;
        position[particles].iter().position(lost).map(|k| lo + k)
    })
    .into_iter()
    .flatten()
    .next()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first lost or non-finite particle is found wherever it is, also when a later chunk (which a helper thread
    /// may scan first) holds another.
    #[test]
    fn find_lost_reports_the_first_lost_particle_on_any_team() {
        let domain = Domain::new(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [true, false, false]);
        let n = 5 * CHUNK + 17;
        let inside: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(2.5, (i as f64 + 0.5) / n as f64, 0.5))
            .collect();
        for team in [Team::new(1), Team::new(2), Team::new(3)] {
            assert_eq!(find_lost(&inside, &domain, 0.01, &team), None, "x is periodic");
            let mut x = inside.clone();
            x[4 * CHUNK + 3].y = -0.02;
            assert_eq!(find_lost(&x, &domain, 0.01, &team), Some(4 * CHUNK + 3));
            x[CHUNK + 1].z = f64::NAN;
            assert_eq!(find_lost(&x, &domain, 0.01, &team), Some(CHUNK + 1));
            x[2].z = 1.005;
            assert_eq!(
                find_lost(&x, &domain, 0.01, &team),
                Some(CHUNK + 1),
                "within the tolerance"
            );
        }
    }
}
