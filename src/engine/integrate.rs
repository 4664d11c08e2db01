//! Velocity Verlet for translation and rotation of spheres, as LIGGGHTS/LAMMPS `nve/sphere` does it:
//! half kick → drift → forces (with half-step velocities) → half kick.
//!
//! The first half kick, the drift, the lost-particle check and the neighbour-list displacement check are one pass
//! over the particles ([`kick_drift`]); the second half kick is fused into the force pass (`forces.rs`). The
//! integrator is memory-bound, so passes, not arithmetic, set its cost. Each particle is updated independently, so the parallel loops are
//! trivially deterministic.

use rayon::prelude::*;

use super::Vec3;
use super::geometry::Domain;
use super::particles::Particles;

const CHUNK: usize = 2048;

/// What went wrong with a particle during a pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BadParticle {
    NonFinite(usize),
    Lost(usize),
}

impl BadParticle {
    fn index(self) -> usize {
        match self {
            BadParticle::NonFinite(i) | BadParticle::Lost(i) => i,
        }
    }
}

fn first(a: Option<BadParticle>, b: Option<BadParticle>) -> Option<BadParticle> {
    match (a, b) {
        (Some(x), Some(y)) => Some(if x.index() <= y.index() { x } else { y }),
        (x, None) => x,
        (None, y) => y,
    }
}

/// A vector is finite when the sum of its components is (a NaN or infinity anywhere propagates).
#[inline(always)]
fn finite(v: &Vec3) -> bool {
    (v.x + v.y + v.z).is_finite()
}

/// v += ½dt (F/m + g), ω += ½dt T/I for particle k (LIGGGHTS' dtf/m form: one division per particle).
#[inline(always)]
fn half_kick_one(v: &mut Vec3, w: &mut Vec3, f: &Vec3, t: &Vec3, m: f64, inertia: f64, g_half_dt: &Vec3, half_dt: f64) {
    *v += f * (half_dt / m) + g_half_dt;
    *w += t * (half_dt / inertia);
}

/// First half of a step: half kick, drift (wrapped on periodic axes), and checks. Returns the largest squared
/// displacement from `reference` (the positions at the last neighbour-list build; empty = skip) and the first
/// particle that became non-finite or left the box.
#[allow(clippy::too_many_arguments)]
pub fn kick_drift(
    p: &mut Particles,
    gravity: &Vec3,
    dt_s: f64,
    pseudo_2d: bool,
    domain: &Domain,
    lost_tolerance_m: f64,
    reference: &[Vec3],
) -> (f64, Option<BadParticle>) {
    let half_dt = 0.5 * dt_s;
    let g_half_dt = gravity * half_dt;
    let check_displacement = reference.len() == p.len();
    p.position_m
        .par_chunks_mut(CHUNK)
        .zip(p.velocity_m_per_s.par_chunks_mut(CHUNK))
        .zip(p.angular_velocity_rad_per_s.par_chunks_mut(CHUNK))
        .zip(p.force_n.par_chunks(CHUNK).zip(p.torque_n_m.par_chunks(CHUNK)))
        .zip(p.mass_kg.par_chunks(CHUNK).zip(p.inertia_kg_m2.par_chunks(CHUNK)))
        .enumerate()
        .map(|(c, ((((x, v), w), (f, t)), (m, inertia)))| {
            let mut bad = None;
            let mut max_d2 = 0.0f64;
            for k in 0..x.len() {
                half_kick_one(
                    &mut v[k], &mut w[k], &f[k], &t[k], m[k], inertia[k], &g_half_dt, half_dt,
                );
                if pseudo_2d {
                    v[k].z = 0.0;
                    w[k].x = 0.0;
                    w[k].y = 0.0;
                }
                x[k] += v[k] * dt_s;
                domain.wrap(&mut x[k]);
                if check_displacement {
                    max_d2 = max_d2.max(domain.separation(&x[k], &reference[c * CHUNK + k]).norm_squared());
                }
                if bad.is_none() {
                    if !(finite(&x[k]) && finite(&v[k]) && finite(&w[k])) {
                        bad = Some(BadParticle::NonFinite(c * CHUNK + k));
                    } else if domain.is_lost(&x[k], lost_tolerance_m) {
                        bad = Some(BadParticle::Lost(c * CHUNK + k));
                    }
                }
            }
            (max_d2, bad)
        })
        .reduce(|| (0.0, None), |a, b| (a.0.max(b.0), first(a.1, b.1)))
}
