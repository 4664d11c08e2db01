//! Contact forces and torques on every particle, accumulated in one fixed order whatever the thread count.
//!
//! The order for particle p is: first its contacts as the *second* particle of a pair (ascending first particle),
//! then as the first particle (ascending partner), then its walls (ascending wall index). On one thread the pair loop
//! scatters directly (f_i += F, f_j −= F), which produces exactly that order; on several threads each pair's result
//! is written to a per-slot buffer in parallel and then gathered per particle in that same order. Both paths run
//! the same per-contact kernel, so one and N threads give bit-identical forces.

use rayon::prelude::*;

use super::Vec3;
use super::contacts::AlignedHistory;
use super::geometry::Wall;
use super::models::{ContactHistory, ContactKinematics, ContactLaw, PairTable};
use super::neighbor::NeighborList;
use super::particles::{ParticleId, Particles};
use super::simulation::SimConfig;

/// Particles per parallel work item.
const CHUNK: usize = 1024;

/// Per-slot results of the pair pass (multi-threaded path only).
#[derive(Debug, Default, Clone)]
pub struct PairBuffers {
    force_on_i: Vec<Vec3>,
    torque_on_i: Vec<Vec3>,
    torque_on_j: Vec<Vec3>,
}

impl PairBuffers {
    pub fn heap_bytes(&self) -> usize {
        (self.force_on_i.capacity() + self.torque_on_i.capacity() + self.torque_on_j.capacity())
            * std::mem::size_of::<Vec3>()
    }
}

/// The largest overlap found, relative to the smaller radius, and where.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorstOverlap {
    pub ratio: f64,
    pub overlap_m: f64,
    pub particle: u32,
    /// Particle index, or `u32::MAX - wall` for a wall.
    pub partner: u32,
}

impl WorstOverlap {
    const NONE: WorstOverlap = WorstOverlap {
        ratio: 0.0,
        overlap_m: 0.0,
        particle: 0,
        partner: 0,
    };

    #[inline]
    fn note(&mut self, overlap_m: f64, smaller_radius_m: f64, particle: usize, partner: u32) {
        let ratio = overlap_m / smaller_radius_m;
        if ratio > self.ratio {
            *self = WorstOverlap {
                ratio,
                overlap_m,
                particle: particle as u32,
                partner,
            };
        }
    }

    fn max(self, other: WorstOverlap) -> WorstOverlap {
        // Ties resolve to the lower particle index so the report does not depend on the thread count.
        if other.ratio > self.ratio || (other.ratio == self.ratio && other.particle < self.particle) {
            other
        } else {
            self
        }
    }

    pub fn partner_name(&self, walls: &[Wall]) -> String {
        if self.partner >= u32::MAX - walls.len() as u32 {
            format!("wall '{}'", walls[(u32::MAX - self.partner) as usize].name)
        } else {
            format!("particle {}", ParticleId(self.partner).0)
        }
    }
}

/// Everything one contact evaluation needs that does not change during the pass.
struct Context<'a> {
    config: &'a SimConfig,
    law: &'a ContactLaw,
    table: &'a PairTable,
    p: &'a Particles,
    wall_angle: &'a [f64],
    dt_s: f64,
}

/// Result of one particle–particle contact: force on i, torques on i and j.
#[derive(Clone, Copy)]
struct PairResult {
    force: Vec3,
    torque_i: Vec3,
    torque_j: Vec3,
}

impl Context<'_> {
    /// Evaluates the pair (i, j) if it overlaps; otherwise clears its history.
    #[inline(always)]
    fn pair(
        &self,
        i: usize,
        j: usize,
        touching: &mut bool,
        hist: &mut ContactHistory,
        worst: &mut WorstOverlap,
    ) -> Option<PairResult> {
        let p = self.p;
        let d = self.config.domain.separation(&p.position_m[i], &p.position_m[j]);
        let dist2 = d.norm_squared();
        let (ri, rj) = (p.radius_m[i], p.radius_m[j]);
        let reach = ri + rj;
        if dist2 >= reach * reach {
            if *touching {
                *touching = false;
                *hist = ContactHistory::INACTIVE;
            }
            return None;
        }
        *touching = true;
        let dist = dist2.sqrt();
        let n = d / dist;
        let overlap = reach - dist;
        worst.note(overlap, ri.min(rj), i, j as u32);
        let (wi, wj) = (p.angular_velocity_rad_per_s[i], p.angular_velocity_rad_per_s[j]);
        let (mi, mj) = (p.mass_kg[i], p.mass_kg[j]);
        let k = ContactKinematics {
            normal: n,
            overlap_m: overlap,
            effective_radius_m: ri * rj / reach,
            effective_mass_kg: mi * mj / (mi + mj),
            contact_velocity: p.velocity_m_per_s[i] - p.velocity_m_per_s[j] - (wi * ri + wj * rj).cross(&n),
            relative_angular_velocity: wi - wj,
        };
        let mat = self.table.get(p.species[i], p.species[j]);
        let out = self.law.evaluate(mat, &k, self.dt_s, hist);
        let nxft = n.cross(&out.tangential_force);
        Some(PairResult {
            force: out.force,
            torque_i: -(nxft * ri) + out.rolling_torque,
            torque_j: -(nxft * rj) - out.rolling_torque,
        })
    }

    /// Adds the wall contacts of particle i to (f, t), in ascending wall order.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn walls(
        &self,
        i: usize,
        wall_ids: &[u16],
        touching: &mut [bool],
        hist: &mut [ContactHistory],
        f: &mut Vec3,
        t: &mut Vec3,
        worst: &mut WorstOverlap,
    ) {
        let p = self.p;
        let x = p.position_m[i];
        let ri = p.radius_m[i];
        for ((h, on), &w) in hist.iter_mut().zip(touching.iter_mut()).zip(wall_ids) {
            let wall = &self.config.walls[w as usize];
            let prox = wall.proximity(&x, self.wall_angle[w as usize]);
            let overlap = ri - prox.gap_m;
            if overlap <= 0.0 {
                if *on {
                    *on = false;
                    *h = ContactHistory::INACTIVE;
                }
                continue;
            }
            *on = true;
            worst.note(overlap, ri, i, u32::MAX - w as u32);
            let n = prox.normal;
            let wi = p.angular_velocity_rad_per_s[i];
            let k = ContactKinematics {
                normal: n,
                overlap_m: overlap,
                effective_radius_m: ri,
                effective_mass_kg: p.mass_kg[i],
                contact_velocity: p.velocity_m_per_s[i] - (wi * ri).cross(&n) - prox.wall_velocity,
                relative_angular_velocity: wi - prox.wall_angular_velocity,
            };
            let mat = self.table.get(p.species[i], wall.species);
            let out = self.law.evaluate(mat, &k, self.dt_s, h);
            *f += out.force;
            *t += -(n.cross(&out.tangential_force) * ri) + out.rolling_torque;
        }
    }
}

/// Computes contact forces and torques into `p.force_n` and `p.torque_n_m`. Returns the worst overlap.
#[allow(clippy::too_many_arguments)]
pub fn compute_contact_forces(
    config: &SimConfig,
    p: &mut Particles,
    wall_angle: &[f64],
    dt_s: f64,
    list: &NeighborList,
    history: &mut AlignedHistory,
    buffers: &mut PairBuffers,
    threads: usize,
) -> WorstOverlap {
    let mut force = std::mem::take(&mut p.force_n);
    let mut torque = std::mem::take(&mut p.torque_n_m);
    let ctx = Context {
        config,
        law: &config.contact_law,
        table: &config.pair_table,
        p,
        wall_angle,
        dt_s,
    };
    let worst = if threads <= 1 {
        serial(&ctx, list, history, &mut force, &mut torque)
    } else {
        parallel(&ctx, list, history, buffers, &mut force, &mut torque)
    };
    if config.pseudo_2d {
        for (f, t) in force.iter_mut().zip(torque.iter_mut()) {
            f.z = 0.0;
            t.x = 0.0;
            t.y = 0.0;
        }
    }
    p.force_n = force;
    p.torque_n_m = torque;
    worst
}

fn serial(
    ctx: &Context,
    list: &NeighborList,
    history: &mut AlignedHistory,
    force: &mut [Vec3],
    torque: &mut [Vec3],
) -> WorstOverlap {
    let n = ctx.p.len();
    let mut worst = WorstOverlap::NONE;
    force.fill(Vec3::zeros());
    torque.fill(Vec3::zeros());
    for i in 0..n {
        let slots = list.pairs_of(i);
        for (k, &j) in slots.clone().zip(&list.partner[slots]) {
            let j = j as usize;
            if let Some(r) = ctx.pair(i, j, &mut history.pair_touching[k], &mut history.pair[k], &mut worst) {
                force[i] += r.force;
                force[j] -= r.force;
                torque[i] += r.torque_i;
                torque[j] += r.torque_j;
            }
        }
        let walls = list.walls_of(i);
        let (mut f, mut t) = (force[i], torque[i]);
        ctx.walls(
            i,
            &list.wall_partner[walls.clone()],
            &mut history.wall_touching[walls.clone()],
            &mut history.wall[walls],
            &mut f,
            &mut t,
            &mut worst,
        );
        force[i] = f;
        torque[i] = t;
    }
    worst
}

/// Splits `data` into consecutive mutable pieces ending at the given offsets.
fn split_by_offsets<'a, T>(mut data: &'a mut [T], ends: &[usize]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(ends.len());
    let mut consumed = 0;
    for &end in ends {
        let (head, tail) = data.split_at_mut(end - consumed);
        out.push(head);
        data = tail;
        consumed = end;
    }
    out
}

fn parallel(
    ctx: &Context,
    list: &NeighborList,
    history: &mut AlignedHistory,
    buffers: &mut PairBuffers,
    force: &mut [Vec3],
    torque: &mut [Vec3],
) -> WorstOverlap {
    let n = ctx.p.len();
    let n_slots = list.pair_count();
    buffers.force_on_i.resize(n_slots, Vec3::zeros());
    buffers.torque_on_i.resize(n_slots, Vec3::zeros());
    buffers.torque_on_j.resize(n_slots, Vec3::zeros());
    let chunk_bounds: Vec<usize> = (1..=n.div_ceil(CHUNK)).map(|c| (c * CHUNK).min(n)).collect();

    // Pass 1: every pair slot, in parallel by chunks of first particles.
    let pair_ends: Vec<usize> = chunk_bounds.iter().map(|&hi| list.start[hi] as usize).collect();
    let hist_parts = split_by_offsets(&mut history.pair, &pair_ends);
    let touching_parts = split_by_offsets(&mut history.pair_touching, &pair_ends);
    let f_parts = split_by_offsets(&mut buffers.force_on_i, &pair_ends);
    let ti_parts = split_by_offsets(&mut buffers.torque_on_i, &pair_ends);
    let tj_parts = split_by_offsets(&mut buffers.torque_on_j, &pair_ends);
    let worst_pairs = hist_parts
        .into_par_iter()
        .zip(touching_parts)
        .zip(f_parts.into_par_iter().zip(ti_parts.into_par_iter().zip(tj_parts)))
        .enumerate()
        .map(|(c, ((hist, touching), (fb, (tib, tjb))))| {
            let lo = c * CHUNK;
            let hi = chunk_bounds[c];
            let base = list.start[lo] as usize;
            let mut worst = WorstOverlap::NONE;
            for i in lo..hi {
                for k in list.pairs_of(i) {
                    let j = list.partner[k] as usize;
                    let local = k - base;
                    if let Some(r) = ctx.pair(i, j, &mut touching[local], &mut hist[local], &mut worst) {
                        fb[local] = r.force;
                        tib[local] = r.torque_i;
                        tjb[local] = r.torque_j;
                    }
                }
            }
            worst
        })
        .reduce(|| WorstOverlap::NONE, WorstOverlap::max);

    // Pass 2: gather per particle in the serial order, then walls.
    let pair_touching = &history.pair_touching;
    let wall_ends: Vec<usize> = chunk_bounds.iter().map(|&hi| list.wall_start[hi] as usize).collect();
    let wall_hist_parts = split_by_offsets(&mut history.wall, &wall_ends);
    let wall_touching_parts = split_by_offsets(&mut history.wall_touching, &wall_ends);
    let worst_walls = force
        .par_chunks_mut(CHUNK)
        .zip(torque.par_chunks_mut(CHUNK))
        .zip(wall_hist_parts.into_par_iter().zip(wall_touching_parts))
        .enumerate()
        .map(|(c, ((fc, tc), (wall_hist, wall_touching)))| {
            let lo = c * CHUNK;
            let wall_base = list.wall_start[lo] as usize;
            let mut worst = WorstOverlap::NONE;
            for (offset, (f_out, t_out)) in fc.iter_mut().zip(tc.iter_mut()).enumerate() {
                let p = lo + offset;
                let mut f = Vec3::zeros();
                let mut t = Vec3::zeros();
                let rev = list.reverse_start[p] as usize..list.reverse_start[p + 1] as usize;
                for &slot in &list.reverse_slot[rev] {
                    let slot = slot as usize;
                    if pair_touching[slot] {
                        f -= buffers.force_on_i[slot];
                        t += buffers.torque_on_j[slot];
                    }
                }
                for k in list.pairs_of(p) {
                    if pair_touching[k] {
                        f += buffers.force_on_i[k];
                        t += buffers.torque_on_i[k];
                    }
                }
                let walls = list.walls_of(p);
                let local = walls.start - wall_base..walls.end - wall_base;
                ctx.walls(
                    p,
                    &list.wall_partner[walls],
                    &mut wall_touching[local.clone()],
                    &mut wall_hist[local],
                    &mut f,
                    &mut t,
                    &mut worst,
                );
                *f_out = f;
                *t_out = t;
            }
            worst
        })
        .reduce(|| WorstOverlap::NONE, WorstOverlap::max);
    worst_pairs.max(worst_walls)
}
