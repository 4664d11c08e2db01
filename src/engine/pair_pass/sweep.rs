//! The drivers of the pair pass: [`serial`] runs the pair loop over every particle on the calling thread,
//! scattering into both partners; [`parallel`] runs the same loop over contiguous particle ranges on the team, the
//! pairs that cross a range boundary computed first and merged in the serial order, so that any thread count gives
//! the serial pass's bits. The per-range sweep is compiled twice on x86-64 (baseline and x86-64-v3) and picked at
//! run time.

use std::sync::atomic::Ordering;
use std::time::Instant;

use super::super::Vec3;
use super::super::channels::{ChannelsMut, ParticleChannels, ScalarFlows};
use super::super::contacts::{AlignedHistory, ColumnsMut, split_at_ends};
use super::super::heat_ledger::FixedPointSum;
use super::super::models::{ContactLaw, PairTable};
use super::super::neighbor::NeighborList;
use super::super::particles::SpeciesId;
use super::super::range_plan::RangePlan;
use super::super::simulation::SimConfig;
use super::super::team::Team;
use super::{Cells, Context, ForcePass, PairBuffers, PassKind, Plain, Tally, WorstOverlap, first_non_finite};

#[allow(clippy::too_many_arguments)]
pub(super) fn serial<P: PassKind>(
    ctx: &Context,
    list: &NeighborList,
    history: &mut AlignedHistory,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
    temperature: &mut [f64],
    channels: &mut ParticleChannels,
) -> ForcePass {
    let ctx = *ctx;
    let n = ctx.radius_m.len();
    if !ctx.accumulators_zeroed {
        force.fill(Vec3::zeros());
        torque.fill(Vec3::zeros());
    }
    let window = ListWindow::new(list, 0, n);
    let motion = (&mut *position, &mut *velocity, &mut *omega, temperature);
    let no_buffers = PairBuffers::default();
    let (pairs, walls) = (history.pair.view(), history.wall.view());
    let tally = sweep::<P, false>(
        ctx,
        &window,
        0,
        0..n,
        motion,
        force,
        torque,
        channels.view(),
        pairs,
        walls,
        &no_buffers,
    );
    ForcePass {
        worst_overlap: tally.worst,
        non_finite: first_non_finite(tally.velocity_sum, velocity, omega, 0),
        max_displacement2_m2: tally.max_displacement2,
        well_crossings: tally.well_crossings,
        wall_heat_flow_w: tally.wall_heat_flow_w.value(),
    }
}

/// Several threads: the particles are cut into contiguous ranges, [`RangePlan::BLOCK`] per thread, which the
/// team shares out with work stealing (`Team::map_parts`).
///
/// Phase A computes, in parallel, only the pairs whose partner lies in a later range (the pairs two ranges share),
/// into per-slot buffers. Phase B runs, in parallel, the serial loop over each range: each particle first receives
/// its contributions from earlier ranges (ascending first particle, from the buffers), then the range is processed
/// exactly as the serial loop does, taking the buffered results for its cross-range pairs. Every particle's sum is
/// thus formed in the serial order, and only a boundary layer of pairs goes through memory twice. Which thread runs
/// a range never matters: a range's results depend only on the plan.
#[allow(clippy::too_many_arguments)]
pub(super) fn parallel<P: PassKind>(
    ctx: &Context,
    list: &NeighborList,
    history: &mut AlignedHistory,
    buffers: &mut PairBuffers,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
    temperature: &mut [f64],
    channels: &mut ParticleChannels,
    plan: &RangePlan,
    team: &Team,
) -> ForcePass {
    let bounds = &plan.bounds;
    let particle_ends = &bounds[1..];
    let pair_ends: Vec<usize> = particle_ends.iter().map(|&b| list.start[b] as usize).collect();
    let wall_ends: Vec<usize> = particle_ends.iter().map(|&b| list.wall_start[b] as usize).collect();
    let n_slots = list.pair_count();
    buffers.force_on_i.resize(n_slots, Vec3::zeros());
    buffers.torque_on_i.resize(n_slots, Vec3::zeros());
    buffers.torque_on_j.resize(n_slots, Vec3::zeros());
    buffers.acted.resize(n_slots, false);
    if ctx.channels {
        buffers.scalars_on_i.resize(n_slots, ScalarFlows::ZERO);
    }

    // Phase A: cross-range pairs, velocities only read.
    let (worst_cross, crossings_cross) = {
        let hist_parts = history.pair.split(&pair_ends);
        let f_parts = split_at_ends(&mut buffers.force_on_i, &pair_ends);
        let ti_parts = split_at_ends(&mut buffers.torque_on_i, &pair_ends);
        let tj_parts = split_at_ends(&mut buffers.torque_on_j, &pair_ends);
        let on_parts = split_at_ends(&mut buffers.acted, &pair_ends);
        let scalar_parts = split_at_ends(&mut buffers.scalars_on_i, &pair_ends);
        let vel = Plain {
            x: position,
            v: velocity,
            w: omega,
            t: temperature,
        };
        let parts: Vec<_> = hist_parts
            .into_iter()
            .zip(f_parts)
            .zip(
                ti_parts
                    .into_iter()
                    .zip(tj_parts.into_iter().zip(on_parts.into_iter().zip(scalar_parts))),
            )
            .collect();
        team.map_parts(parts, |r, ((mut hist, fb), (tib, (tjb, (onb, sb))))| {
            let ctx = *ctx;
            let (lo, hi) = (bounds[r], bounds[r + 1]);
            let base = list.start[lo] as usize;
            let (mut worst, mut crossings) = (WorstOverlap::NONE, 0u64);
            for i in plan.cross_from[r]..hi {
                let bi = ctx.body(i, &vel);
                for k in list.pairs_of(i) {
                    let j = list.partner[k] as usize;
                    if j < hi {
                        continue;
                    }
                    let local = k - base;
                    let mut flows = ScalarFlows::ZERO;
                    match ctx.pair::<P>(
                        i,
                        &bi,
                        j,
                        &vel,
                        &mut hist,
                        local,
                        k,
                        &mut worst,
                        &mut crossings,
                        &mut flows,
                    ) {
                        Some(res) => {
                            fb[local] = res.force;
                            tib[local] = res.torque_i;
                            tjb[local] = res.torque_j;
                            onb[local] = true;
                        }
                        None => onb[local] = false,
                    }
                    if P::HEAT && ctx.channels {
                        sb[local] = flows;
                    }
                }
            }
            (worst, crossings)
        })
        .into_iter()
        .fold((WorstOverlap::NONE, 0), |a, b| (a.0.max(b.0), a.1 + b.1))
    };

    // Phase B: each range in the serial order.
    let buffers = &*buffers;
    let hist_parts = history.pair.split(&pair_ends);
    let wall_parts = history.wall.split(&wall_ends);
    let f_parts = split_at_ends(force, particle_ends);
    let t_parts = split_at_ends(torque, particle_ends);
    let x_parts = split_at_ends(position, particle_ends);
    let v_parts = split_at_ends(velocity, particle_ends);
    let w_parts = split_at_ends(omega, particle_ends);
    let temperature_parts = split_at_ends(temperature, particle_ends);
    let channel_parts = channels.split(particle_ends);
    let parts: Vec<_> = f_parts
        .into_iter()
        .zip(t_parts)
        .zip(
            x_parts
                .into_iter()
                .zip(v_parts.into_iter().zip(w_parts.into_iter().zip(temperature_parts))),
        )
        .zip(hist_parts.into_iter().zip(wall_parts.into_iter().zip(channel_parts)))
        .collect();
    let (worst_ranges, non_finite, max_d2, crossings_ranges, wall_heat) = team
        .map_parts(
            parts,
            |r, (((force, torque), (x, (v, (w, temperature)))), (pairs, (walls, channels)))| {
                let started = Instant::now();
                let range = RangeData {
                    ctx,
                    plan,
                    list,
                    buffers,
                };
                let tally = range_sweep::<P>(
                    &range,
                    ctx.config,
                    ctx.law,
                    ctx.table,
                    ctx.radius_m,
                    ctx.mass_kg,
                    ctx.species,
                    r,
                    force,
                    torque,
                    channels,
                    (x, v, w, temperature),
                    pairs,
                    walls,
                );
                plan.busy_ns[r].fetch_add(started.elapsed().as_nanos() as u64, Ordering::Relaxed);
                tally
            },
        )
        .into_iter()
        .fold(
            (WorstOverlap::NONE, None, 0.0f64, 0u64, FixedPointSum::default()),
            |mut a, b| {
                a.4.merge(b.4);
                (a.0.max(b.0), a.1.min(b.1).or(a.1).or(b.1), a.2.max(b.2), a.3 + b.3, a.4)
            },
        );
    ForcePass {
        worst_overlap: worst_cross.max(worst_ranges),
        non_finite,
        max_displacement2_m2: max_d2,
        well_crossings: crossings_cross + crossings_ranges,
        wall_heat_flow_w: wall_heat.value(),
    }
}

/// The serial loop of the force pass over `particles` of a window of the list (indices relative to the window;
/// partner indices are global and `lo` is subtracted from them): each particle's pairs, scattered to both
/// particles, then its walls and [`Context::complete`]. On one thread the whole pass, with `CROSS` false. On several,
/// each range (see [`range_sweep`]): its interior with `CROSS` false, and its boundary layer with `CROSS` true, where
/// a partner beyond the window is not evaluated but its result taken from `buffers` (phase A of [`parallel`]). One
/// function for all, so the interior of a range runs the same machine code as the one-thread pass.
///
/// Compiled twice, for the x86-64 baseline and for x86-64-v3 (AVX2, FMA, BMI), and dispatched at run time
/// ([`crate::machine::cpu_fast_path`]): the default build runs on any x86-64 machine and still uses the newer
/// instructions where they exist. Both give the same bits: Rust never fuses a multiply and an add on its own, and
/// the one explicit `mul_add` is exact either way (tests/portable_build.rs compares them).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn sweep<P: PassKind, const CROSS: bool>(
    ctx: Context,
    window: &ListWindow,
    lo: usize,
    particles: std::ops::Range<usize>,
    motion: Motion4,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    channels: ChannelsMut,
    pairs: ColumnsMut,
    walls: ColumnsMut,
    buffers: &PairBuffers,
) -> Tally {
    #[cfg(target_arch = "x86_64")]
    if crate::machine::cpu_fast_path() {
        // SAFETY: `cpu_fast_path` is true only where the CPU has every feature `sweep_x86_64_v3` is compiled for.
        return unsafe {
            sweep_x86_64_v3::<P, CROSS>(
                ctx, window, lo, particles, motion, force, torque, channels, pairs, walls, buffers,
            )
        };
    }
    sweep_body::<P, CROSS>(
        ctx, window, lo, particles, motion, force, torque, channels, pairs, walls, buffers,
    )
}

/// [`sweep_body`] compiled for x86-64-v3's instructions.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::too_many_arguments)]
#[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,movbe")]
fn sweep_x86_64_v3<P: PassKind, const CROSS: bool>(
    ctx: Context,
    window: &ListWindow,
    lo: usize,
    particles: std::ops::Range<usize>,
    motion: Motion4,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    channels: ChannelsMut,
    pairs: ColumnsMut,
    walls: ColumnsMut,
    buffers: &PairBuffers,
) -> Tally {
    sweep_body::<P, CROSS>(
        ctx, window, lo, particles, motion, force, torque, channels, pairs, walls, buffers,
    )
}

/// Positions, velocities, angular velocities and temperatures (empty without heat) of the particles a sweep moves.
type Motion4<'a> = (&'a mut [Vec3], &'a mut [Vec3], &'a mut [Vec3], &'a mut [f64]);

/// The loop of [`sweep`], inlined into each of its compilations.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn sweep_body<P: PassKind, const CROSS: bool>(
    ctx: Context,
    window: &ListWindow,
    lo: usize,
    particles: std::ops::Range<usize>,
    (x, v, w, temperature): Motion4,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    mut channels: ChannelsMut,
    mut pairs: ColumnsMut,
    mut walls: ColumnsMut,
    buffers: &PairBuffers,
) -> Tally {
    // Everything the loop touches is a local or a parameter slice (not reached through a reference to a struct),
    // which lets the compiler keep the slices' pointers in registers across the stores to `force`.
    // A pass without heat never reads temperatures: an empty slice keeps its pointer out of the loop.
    let temperature = if P::HEAT { temperature } else { &mut [] };
    let motion = &Cells::new(x, v, w, temperature, 0);
    let (pairs, walls) = (&mut pairs, &mut walls);
    let local_hi = force.len();
    let mut tally = Tally::default();
    for il in particles {
        let slots = window.pairs_of(il);
        let bi = ctx.body(il, motion);
        for (k, &j) in slots.clone().zip(&window.partner[slots]) {
            let j = j as usize - lo;
            if !CROSS || j < local_hi {
                let slot = k + window.pair_base;
                let mut flows = ScalarFlows::ZERO;
                if let Some(res) = ctx.pair::<P>(
                    il,
                    &bi,
                    j,
                    motion,
                    pairs,
                    k,
                    slot,
                    &mut tally.worst,
                    &mut tally.well_crossings,
                    &mut flows,
                ) {
                    force[il] += res.force;
                    force[j] -= res.force;
                    torque[il] += res.torque_i;
                    torque[j] += res.torque_j;
                }
                if P::WIDE && ctx.channels {
                    channels.add(il, &flows);
                    channels.add(j, &flows.for_partner());
                } else if P::HEAT && ctx.heat.is_some() {
                    channels.heat_flow_w[il] += flows.heat_flow_w;
                    channels.heat_flow_w[j] -= flows.heat_flow_w;
                }
            } else {
                let k = k + window.pair_base;
                if buffers.acted[k] {
                    force[il] += buffers.force_on_i[k];
                    torque[il] += buffers.torque_on_i[k];
                }
                if P::WIDE && ctx.channels {
                    channels.add(il, &buffers.scalars_on_i[k]);
                } else if P::HEAT && ctx.heat.is_some() {
                    channels.heat_flow_w[il] += buffers.scalars_on_i[k].heat_flow_w;
                }
            }
        }
        let wall_slots = window.walls_of(il);
        let (f, t) = ctx.complete::<P>(
            il,
            force[il],
            torque[il],
            motion,
            &window.wall_partner[wall_slots.clone()],
            walls,
            wall_slots.start,
            wall_slots.start + window.wall_base,
            &mut channels,
            &mut tally,
        );
        force[il] = f;
        torque[il] = t;
    }
    tally
}

/// The neighbour list of particles lo..hi, with particle and slot indices relative to the range (as its history
/// views are); partner indices stay global.
struct ListWindow<'a> {
    start: &'a [u32],
    pair_base: usize,
    partner: &'a [u32],
    wall_start: &'a [u32],
    wall_base: usize,
    wall_partner: &'a [u16],
}

impl<'a> ListWindow<'a> {
    fn new(list: &'a NeighborList, lo: usize, hi: usize) -> Self {
        let (pair_base, pair_end) = (list.start[lo] as usize, list.start[hi] as usize);
        let (wall_base, wall_end) = (list.wall_start[lo] as usize, list.wall_start[hi] as usize);
        ListWindow {
            start: &list.start[lo..=hi],
            pair_base,
            partner: &list.partner[pair_base..pair_end],
            wall_start: &list.wall_start[lo..=hi],
            wall_base,
            wall_partner: &list.wall_partner[wall_base..wall_end],
        }
    }

    #[inline(always)]
    fn pairs_of(&self, il: usize) -> std::ops::Range<usize> {
        self.start[il] as usize - self.pair_base..self.start[il + 1] as usize - self.pair_base
    }

    #[inline(always)]
    fn walls_of(&self, il: usize) -> std::ops::Range<usize> {
        self.wall_start[il] as usize - self.wall_base..self.wall_start[il + 1] as usize - self.wall_base
    }
}

/// What every range of phase B reads besides its own slices.
struct RangeData<'a> {
    ctx: &'a Context<'a>,
    plan: &'a RangePlan,
    list: &'a NeighborList,
    buffers: &'a PairBuffers,
}

/// Phase B of [`parallel`] for range r (particles `lo..hi`, whose slices these are): the contributions of earlier
/// ranges, then the serial loop over the range with its cross-range pairs taken from the buffers.
///
/// Written for the optimiser, which decides most of this pass's speed (instruction counts from callgrind):
/// - It is a function of its own, and the references its loops read (configuration, contact law, pair table,
///   per-particle properties) are its parameters: a parameter reference is known not to alias the arrays written
///   in the loop, while one read from a struct must be reloaded after every store (−3 % instructions).
/// - Particles with no partner beyond the range (all but a boundary layer) run [`sweep`], the one-thread pass's own
///   loop, without the cross-range test: that test's second branch alone made the whole loop 12 % slower, and a
///   copy of the loop here ran 6-9 % slower than the shared one (`docs/performance.md`).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn range_sweep<P: PassKind>(
    range: &RangeData,
    config: &SimConfig,
    law: &ContactLaw,
    table: &PairTable,
    radius_m: &[f64],
    mass_kg: &[f64],
    species: &[SpeciesId],
    r: usize,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    mut channels: ChannelsMut,
    (x, v, w, temperature): Motion4,
    mut pairs: ColumnsMut,
    mut walls: ColumnsMut,
) -> (WorstOverlap, Option<usize>, f64, u64, FixedPointSum) {
    let (plan, list, buffers) = (range.plan, range.list, range.buffers);
    let (lo, hi) = (plan.bounds[r], plan.bounds[r + 1]);
    // Everything below is indexed relative to the range: particle il is lo + il, pair slot k is pair_base + k.
    let outer = range.ctx;
    let ctx = Context {
        config,
        law,
        table,
        radius_m: &radius_m[lo..hi],
        mass_kg: &mass_kg[lo..hi],
        species: &species[lo..hi],
        inv_mass_per_kg: &outer.inv_mass_per_kg[lo..hi],
        inv_inertia_per_kg_m2: &outer.inv_inertia_per_kg_m2[lo..hi],
        inv_thermal_mass_per_j_k: outer.inv_thermal_mass_per_j_k.get(lo..hi).unwrap_or(&[]),
        ..*outer
    };
    let window = ListWindow::new(list, lo, hi);
    if !ctx.accumulators_zeroed {
        force.fill(Vec3::zeros());
        torque.fill(Vec3::zeros());
    }
    // Contributions from earlier ranges come first in the serial order (ascending first particle).
    for &(k, j) in &plan.incoming[plan.incoming_start[r]..plan.incoming_start[r + 1]] {
        let (k, j) = (k as usize, j as usize - lo);
        if buffers.acted[k] {
            force[j] -= buffers.force_on_i[k];
            torque[j] += buffers.torque_on_j[k];
        }
        if P::WIDE && ctx.channels {
            channels.add(j, &buffers.scalars_on_i[k].for_partner());
        } else if P::HEAT && ctx.heat.is_some() {
            channels.heat_flow_w[j] -= buffers.scalars_on_i[k].heat_flow_w;
        }
    }
    let local_hi = hi - lo;
    let cross_from = plan.cross_from[r] - lo;
    let interior = (&mut *x, &mut *v, &mut *w, &mut *temperature);
    let (interior_pairs, interior_walls) = (pairs.reborrow(), walls.reborrow());
    let mut tally = sweep::<P, false>(
        ctx,
        &window,
        lo,
        0..cross_from,
        interior,
        force,
        torque,
        channels.reborrow(),
        interior_pairs,
        interior_walls,
        buffers,
    );
    let layer = sweep::<P, true>(
        ctx,
        &window,
        lo,
        cross_from..local_hi,
        (x, v, w, temperature),
        force,
        torque,
        channels,
        pairs,
        walls,
        buffers,
    );
    tally.merge(layer);
    tally.worst.shift_particles(lo, config.walls.len());
    (
        tally.worst,
        first_non_finite(tally.velocity_sum, v, w, lo),
        tally.max_displacement2,
        tally.well_crossings,
        tally.wall_heat_flow_w,
    )
}
