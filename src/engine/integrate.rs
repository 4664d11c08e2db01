//! Velocity Verlet for translation and rotation of spheres, as LIGGGHTS/LAMMPS `nve/sphere` does it:
//! half kick → drift → forces (with half-step velocities) → half kick.
//!
//! Each particle is updated independently, so the parallel loops are trivially deterministic. The kicks also detect
//! non-finite values and the drift detects particles leaving the box; what failed is reported by the caller with
//! the step and particle.

use rayon::prelude::*;

use super::Vec3;
use super::geometry::Domain;
use super::particles::Particles;

const CHUNK: usize = 2048;

/// v += ½dt (F/m + g), ω += ½dt T/I. Returns the index of the first particle whose new velocity or angular
/// velocity is not finite, if any.
pub fn half_kick(p: &mut Particles, gravity: &Vec3, dt_s: f64, pseudo_2d: bool) -> Option<usize> {
    let half_dt = 0.5 * dt_s;
    let g = *gravity;
    let bad = p
        .velocity_m_per_s
        .par_chunks_mut(CHUNK)
        .zip(p.angular_velocity_rad_per_s.par_chunks_mut(CHUNK))
        .zip(p.force_n.par_chunks(CHUNK))
        .zip(p.torque_n_m.par_chunks(CHUNK))
        .zip(
            p.mass_kg
                .par_chunks(CHUNK)
                .zip(p.inertia_kg_m2.par_chunks(CHUNK)),
        )
        .enumerate()
        .map(|(c, ((((v, w), f), t), (m, inertia)))| {
            let mut bad = None;
            for k in 0..v.len() {
                v[k] += (f[k] / m[k] + g) * half_dt;
                w[k] += t[k] * (half_dt / inertia[k]);
                if pseudo_2d {
                    v[k].z = 0.0;
                    w[k].x = 0.0;
                    w[k].y = 0.0;
                }
                if bad.is_none()
                    && !(v[k].iter().all(|x| x.is_finite()) && w[k].iter().all(|x| x.is_finite()))
                {
                    bad = Some(c * CHUNK + k);
                }
            }
            bad
        })
        .reduce(|| None, |a, b| a.min(b).or(a).or(b));
    bad
}

/// x += v dt, wrapped on periodic axes. Returns the first particle that is non-finite or outside the box.
pub fn drift(
    p: &mut Particles,
    domain: &Domain,
    dt_s: f64,
    lost_tolerance_m: f64,
) -> Option<usize> {
    p.position_m
        .par_chunks_mut(CHUNK)
        .zip(p.velocity_m_per_s.par_chunks(CHUNK))
        .enumerate()
        .map(|(c, (x, v))| {
            let mut bad = None;
            for k in 0..x.len() {
                x[k] += v[k] * dt_s;
                domain.wrap(&mut x[k]);
                if bad.is_none()
                    && (!x[k].iter().all(|a| a.is_finite())
                        || domain.is_lost(&x[k], lost_tolerance_m))
                {
                    bad = Some(c * CHUNK + k);
                }
            }
            bad
        })
        .reduce(|| None, |a, b| a.min(b).or(a).or(b))
}
