//! Contact forces and torques on every particle, accumulated in one fixed order whatever the thread count.
//!
//! The order for particle p is: first its contacts as the *second* particle of a pair (ascending first particle),
//! then as the first particle (ascending partner), then its walls (ascending wall index). On one thread the pair loop
//! scatters directly (f_i += F, f_j −= F), which produces exactly that order; on several threads each pair's result
//! is written to a per-slot buffer in parallel and then gathered per particle in that same order. Both paths run
//! the same per-contact kernel, so one and N threads give bit-identical forces.
//!
//! The second half kick of velocity Verlet is fused into this pass: a particle's force is complete when its own
//! iteration ends (its contacts as second particle came earlier), and no later pair reads its velocity, so it is
//! kicked right there instead of in another sweep over memory.

use std::cell::Cell;

use rayon::prelude::*;

use super::Vec3;
use super::contacts::{AlignedHistory, ColumnsMut};
use super::geometry::Wall;
use super::integrate::{InverseInertia, half_kick_one};
use super::models::{ContactKinematics, ContactLaw, PairTable};
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
        // Multiply first: the division happens only for a new worst, not for every contact.
        if overlap_m <= self.ratio * smaller_radius_m {
            return;
        }
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

/// The second half kick, applied to each particle as soon as its force is complete.
#[derive(Debug, Clone, Copy)]
pub struct HalfKick {
    pub gravity: Vec3,
    pub dt_s: f64,
}

/// Read access to velocities: plain slices while nothing writes them, cells while the serial loop kicks in place.
trait Velocities {
    fn v(&self, i: usize) -> Vec3;
    fn w(&self, i: usize) -> Vec3;
}

struct Plain<'a> {
    v: &'a [Vec3],
    w: &'a [Vec3],
}

impl Velocities for Plain<'_> {
    #[inline(always)]
    fn v(&self, i: usize) -> Vec3 {
        self.v[i]
    }
    #[inline(always)]
    fn w(&self, i: usize) -> Vec3 {
        self.w[i]
    }
}

struct Cells<'a> {
    v: &'a [Cell<Vec3>],
    w: &'a [Cell<Vec3>],
}

impl Velocities for Cells<'_> {
    #[inline(always)]
    fn v(&self, i: usize) -> Vec3 {
        self.v[i].get()
    }
    #[inline(always)]
    fn w(&self, i: usize) -> Vec3 {
        self.w[i].get()
    }
}

/// Everything one contact evaluation needs that does not change during the pass.
struct Context<'a> {
    config: &'a SimConfig,
    law: &'a ContactLaw,
    table: &'a PairTable,
    p: &'a Particles,
    inverse: &'a InverseInertia,
    wall_angle: &'a [f64],
    dt_s: f64,
    kick: Option<HalfKick>,
}

/// Result of one particle–particle contact: force on i, torques on i and j.
#[derive(Clone, Copy)]
struct PairResult {
    force: Vec3,
    torque_i: Vec3,
    torque_j: Vec3,
}

impl Context<'_> {
    /// Evaluates the pair (i, j) in local history slot `k` if it overlaps; otherwise releases the slot.
    #[inline(always)]
    fn pair<const WB: bool, const TH: bool>(
        &self,
        i: usize,
        j: usize,
        vel: &impl Velocities,
        hist: &mut ColumnsMut,
        k: usize,
        worst: &mut WorstOverlap,
    ) -> Option<PairResult> {
        let p = self.p;
        let d = self.config.domain.separation(&p.position_m[i], &p.position_m[j]);
        let dist2 = d.norm_squared();
        let (ri, rj) = (p.radius_m[i], p.radius_m[j]);
        let reach = ri + rj;
        if dist2 >= reach * reach {
            hist.release(k);
            return None;
        }
        let dist = dist2.sqrt();
        let n = d * (1.0 / dist);
        let overlap = reach - dist;
        worst.note(overlap, ri.min(rj), i, j as u32);
        let (wi, wj) = (vel.w(i), vel.w(j));
        let (mi, mj) = (p.mass_kg[i], p.mass_kg[j]);
        let kin = ContactKinematics {
            normal: n,
            overlap_m: overlap,
            effective_radius_m: ri * rj / reach,
            effective_mass_kg: mi * mj / (mi + mj),
            contact_velocity: vel.v(i) - vel.v(j) - (wi * ri + wj * rj).cross(&n),
            relative_angular_velocity: wi - wj,
        };
        let mat = self.table.get(p.species[i], p.species[j]);
        let mut h = hist.load_as::<WB, TH>(k);
        let out = self.law.evaluate(mat, &kin, self.dt_s, &mut h);
        hist.save_as::<WB, TH>(k, &h);
        let nxft = n.cross(&out.tangential_force);
        Some(PairResult {
            force: out.force,
            torque_i: -(nxft * ri) + out.rolling_torque,
            torque_j: -(nxft * rj) - out.rolling_torque,
        })
    }

    /// Adds the wall contacts of particle i (velocity `vi`, angular velocity `wi`) to (f, t), in ascending wall
    /// order; `hist` holds exactly i's wall slots.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn walls<const WB: bool, const TH: bool>(
        &self,
        i: usize,
        vi: Vec3,
        wi: Vec3,
        wall_ids: &[u16],
        hist: &mut ColumnsMut,
        first_slot: usize,
        f: &mut Vec3,
        t: &mut Vec3,
        worst: &mut WorstOverlap,
    ) {
        let p = self.p;
        let x = p.position_m[i];
        let ri = p.radius_m[i];
        for (offset, &w) in wall_ids.iter().enumerate() {
            let k = first_slot + offset;
            let wall = &self.config.walls[w as usize];
            let prox = wall.proximity(&x, self.wall_angle[w as usize]);
            let overlap = ri - prox.gap_m;
            if overlap <= 0.0 {
                hist.release(k);
                continue;
            }
            worst.note(overlap, ri, i, u32::MAX - w as u32);
            let n = prox.normal;
            let kin = ContactKinematics {
                normal: n,
                overlap_m: overlap,
                effective_radius_m: ri,
                effective_mass_kg: p.mass_kg[i],
                contact_velocity: vi - (wi * ri).cross(&n) - prox.wall_velocity,
                relative_angular_velocity: wi - prox.wall_angular_velocity,
            };
            let mat = self.table.get(p.species[i], wall.species);
            let mut h = hist.load_as::<WB, TH>(k);
            let out = self.law.evaluate(mat, &kin, self.dt_s, &mut h);
            hist.save_as::<WB, TH>(k, &h);
            *f += out.force;
            *t += -(n.cross(&out.tangential_force) * ri) + out.rolling_torque;
        }
    }

    /// Finishes particle i once its force and torque are complete: pseudo-2-D projection, then the half kick.
    /// Returns the kicked (v, ω).
    #[inline(always)]
    fn finish(&self, i: usize, f: &mut Vec3, t: &mut Vec3, v: Vec3, w: Vec3) -> (Vec3, Vec3) {
        if self.config.pseudo_2d {
            f.z = 0.0;
            t.x = 0.0;
            t.y = 0.0;
        }
        match self.kick {
            None => (v, w),
            Some(k) => {
                let half_dt = 0.5 * k.dt_s;
                let (mut v, mut w) = (v, w);
                half_kick_one(
                    &mut v,
                    &mut w,
                    f,
                    t,
                    self.inverse.inv_mass_per_kg[i],
                    self.inverse.inv_inertia_per_kg_m2[i],
                    &(k.gravity * half_dt),
                    half_dt,
                );
                if self.config.pseudo_2d {
                    v.z = 0.0;
                    w.x = 0.0;
                    w.y = 0.0;
                }
                (v, w)
            }
        }
    }
}

/// A vector is finite when the sum of its components is (a NaN or infinity anywhere propagates).
#[inline(always)]
fn finite(v: &Vec3) -> bool {
    (v.x + v.y + v.z).is_finite()
}

/// The first index (offset by `base`) whose velocity or angular velocity is not finite, looked for only when
/// `sum` (of all their components) is not finite.
fn first_non_finite(sum: f64, v: &[Vec3], w: &[Vec3], base: usize) -> Option<usize> {
    if sum.is_finite() {
        return None;
    }
    v.iter()
        .zip(w)
        .position(|(v, w)| !(finite(v) && finite(w)))
        .map(|k| base + k)
}

/// What the force pass reports.
#[derive(Debug, Clone, Copy)]
pub struct ForcePass {
    pub worst_overlap: WorstOverlap,
    /// First particle whose kicked velocity or angular velocity is not finite.
    pub non_finite: Option<usize>,
}

/// Computes contact forces and torques into `p.force_n` and `p.torque_n_m` and, with `kick`, applies the second
/// half kick to every particle.
#[allow(clippy::too_many_arguments)]
pub fn compute_contact_forces(
    config: &SimConfig,
    p: &mut Particles,
    inverse: &InverseInertia,
    wall_angle: &[f64],
    dt_s: f64,
    list: &NeighborList,
    history: &mut AlignedHistory,
    buffers: &mut PairBuffers,
    threads: usize,
    kick: Option<HalfKick>,
) -> ForcePass {
    let mut force = std::mem::take(&mut p.force_n);
    let mut torque = std::mem::take(&mut p.torque_n_m);
    let mut velocity = std::mem::take(&mut p.velocity_m_per_s);
    let mut omega = std::mem::take(&mut p.angular_velocity_rad_per_s);
    let ctx = Context {
        config,
        law: &config.contact_law,
        table: &config.pair_table,
        p,
        inverse,
        wall_angle,
        dt_s,
        kick,
    };
    // One instantiation per history layout: the layout decides which history fields exist, and knowing it at
    // compile time lets the kernels' unused fields vanish from the loop.
    let layout = config.contact_law.history_layout();
    macro_rules! run {
        ($wb:literal, $th:literal) => {
            if threads <= 1 {
                serial::<$wb, $th>(
                    &ctx,
                    list,
                    history,
                    &mut force,
                    &mut torque,
                    &mut velocity,
                    &mut omega,
                )
            } else {
                parallel::<$wb, $th>(
                    &ctx,
                    list,
                    history,
                    buffers,
                    &mut force,
                    &mut torque,
                    &mut velocity,
                    &mut omega,
                )
            }
        };
    }
    let pass = match (layout.walton_braun, layout.thornton) {
        (false, false) => run!(false, false),
        (true, false) => run!(true, false),
        (false, true) => run!(false, true),
        (true, true) => run!(true, true),
    };
    p.force_n = force;
    p.torque_n_m = torque;
    p.velocity_m_per_s = velocity;
    p.angular_velocity_rad_per_s = omega;
    pass
}

fn serial<const WB: bool, const TH: bool>(
    ctx: &Context,
    list: &NeighborList,
    history: &mut AlignedHistory,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
) -> ForcePass {
    let n = ctx.p.len();
    let mut worst = WorstOverlap::NONE;
    // A NaN or infinity in any kicked velocity propagates into this sum; the culprit is looked for only then.
    let mut velocity_sum = 0.0f64;
    force.fill(Vec3::zeros());
    torque.fill(Vec3::zeros());
    let vel = Cells {
        v: Cell::from_mut(velocity).as_slice_of_cells(),
        w: Cell::from_mut(omega).as_slice_of_cells(),
    };
    let mut pairs = history.pair.view();
    let mut walls = history.wall.view();
    for i in 0..n {
        let slots = list.pairs_of(i);
        for (k, &j) in slots.clone().zip(&list.partner[slots]) {
            let j = j as usize;
            if let Some(r) = ctx.pair::<WB, TH>(i, j, &vel, &mut pairs, k, &mut worst) {
                force[i] += r.force;
                force[j] -= r.force;
                torque[i] += r.torque_i;
                torque[j] += r.torque_j;
            }
        }
        let wall_slots = list.walls_of(i);
        let (mut f, mut t) = (force[i], torque[i]);
        let (vi, wi) = (vel.v(i), vel.w(i));
        ctx.walls::<WB, TH>(
            i,
            vi,
            wi,
            &list.wall_partner[wall_slots.clone()],
            &mut walls,
            wall_slots.start,
            &mut f,
            &mut t,
            &mut worst,
        );
        let (v_new, w_new) = ctx.finish(i, &mut f, &mut t, vi, wi);
        velocity_sum += (v_new.x + v_new.y + v_new.z) + (w_new.x + w_new.y + w_new.z);
        vel.v[i].set(v_new);
        vel.w[i].set(w_new);
        force[i] = f;
        torque[i] = t;
    }
    ForcePass {
        worst_overlap: worst,
        non_finite: first_non_finite(velocity_sum, velocity, omega, 0),
    }
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

#[allow(clippy::too_many_arguments)]
fn parallel<const WB: bool, const TH: bool>(
    ctx: &Context,
    list: &NeighborList,
    history: &mut AlignedHistory,
    buffers: &mut PairBuffers,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
) -> ForcePass {
    let n = ctx.p.len();
    let n_slots = list.pair_count();
    buffers.force_on_i.resize(n_slots, Vec3::zeros());
    buffers.torque_on_i.resize(n_slots, Vec3::zeros());
    buffers.torque_on_j.resize(n_slots, Vec3::zeros());
    let chunk_bounds: Vec<usize> = (1..=n.div_ceil(CHUNK)).map(|c| (c * CHUNK).min(n)).collect();

    // Pass 1: every pair slot, in parallel by chunks of first particles; velocities are only read.
    let pair_ends: Vec<usize> = chunk_bounds.iter().map(|&hi| list.start[hi] as usize).collect();
    let hist_parts = history.pair.split(&pair_ends);
    let f_parts = split_by_offsets(&mut buffers.force_on_i, &pair_ends);
    let ti_parts = split_by_offsets(&mut buffers.torque_on_i, &pair_ends);
    let tj_parts = split_by_offsets(&mut buffers.torque_on_j, &pair_ends);
    let vel = Plain { v: velocity, w: omega };
    let worst_pairs = hist_parts
        .into_par_iter()
        .zip(f_parts)
        .zip(ti_parts.into_par_iter().zip(tj_parts))
        .enumerate()
        .map(|(c, ((mut hist, fb), (tib, tjb)))| {
            let lo = c * CHUNK;
            let hi = chunk_bounds[c];
            let base = list.start[lo] as usize;
            let mut worst = WorstOverlap::NONE;
            for i in lo..hi {
                for k in list.pairs_of(i) {
                    let j = list.partner[k] as usize;
                    let local = k - base;
                    if let Some(r) = ctx.pair::<WB, TH>(i, j, &vel, &mut hist, local, &mut worst) {
                        fb[local] = r.force;
                        tib[local] = r.torque_i;
                        tjb[local] = r.torque_j;
                    }
                }
            }
            worst
        })
        .reduce(|| WorstOverlap::NONE, WorstOverlap::max);

    // Pass 2: gather per particle in the serial order, then walls, then the kick.
    let pair_touching = &history.pair.touching;
    let wall_ends: Vec<usize> = chunk_bounds.iter().map(|&hi| list.wall_start[hi] as usize).collect();
    let wall_parts = history.wall.split(&wall_ends);
    let (worst_walls, non_finite) = force
        .par_chunks_mut(CHUNK)
        .zip(torque.par_chunks_mut(CHUNK))
        .zip(velocity.par_chunks_mut(CHUNK).zip(omega.par_chunks_mut(CHUNK)))
        .zip(wall_parts)
        .enumerate()
        .map(|(c, (((fc, tc), (vc, wc)), mut wall_hist))| {
            let lo = c * CHUNK;
            let wall_base = list.wall_start[lo] as usize;
            let mut worst = WorstOverlap::NONE;
            let mut velocity_sum = 0.0f64;
            for offset in 0..fc.len() {
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
                let (vi, wi) = (vc[offset], wc[offset]);
                ctx.walls::<WB, TH>(
                    p,
                    vi,
                    wi,
                    &list.wall_partner[walls.clone()],
                    &mut wall_hist,
                    walls.start - wall_base,
                    &mut f,
                    &mut t,
                    &mut worst,
                );
                let (v_new, w_new) = ctx.finish(p, &mut f, &mut t, vi, wi);
                velocity_sum += (v_new.x + v_new.y + v_new.z) + (w_new.x + w_new.y + w_new.z);
                vc[offset] = v_new;
                wc[offset] = w_new;
                fc[offset] = f;
                tc[offset] = t;
            }
            (worst, first_non_finite(velocity_sum, vc, wc, lo))
        })
        .reduce(
            || (WorstOverlap::NONE, None),
            |a, b| (a.0.max(b.0), a.1.min(b.1).or(a.1).or(b.1)),
        );
    ForcePass {
        worst_overlap: worst_pairs.max(worst_walls),
        non_finite,
    }
}
