//! How the parallel pair pass cuts the particles into ranges: bounds balanced by measured cost, and per range the
//! boundary layer of pairs it shares with later ranges. Any plan gives the same results (bit for bit); a plan only
//! spreads the work. What does not live here: the pass itself (`pair_pass.rs`).

use std::sync::atomic::{AtomicU64, Ordering};

use super::neighbor::{BUILD_CHUNK, NeighborList};
use super::team::Team;

/// How the parallel pass cuts the particles: range bounds, and per range where its cross-range pairs start.
///
/// The cut is balanced by measured time: every range records how long its share of the pass took, and the next
/// plan scales each particle's estimated cost by its old range's measured time per unit of estimate. Any bounds give
/// the same results (bit for bit); they only spread the work.
#[derive(Debug, Default)]
pub struct RangePlan {
    /// `ranges + 1` bounds from 0 to n.
    pub bounds: Vec<usize>,
    /// Per range: the first particle with a partner beyond the range (the range end if none).
    pub cross_from: Vec<usize>,
    /// Cross-range slots `(slot, partner)` whose partner lies in range r are
    /// `incoming[incoming_start[r]..incoming_start[r + 1]]`, in the serial order (ascending first particle).
    pub(crate) incoming: Vec<(u32, u32)>,
    pub(crate) incoming_start: Vec<usize>,
    /// Per range: estimated cost when the plan was made.
    estimate: Vec<f64>,
    /// Per range: nanoseconds spent in the range's serial loop since the plan was made.
    pub(crate) busy_ns: Vec<AtomicU64>,
}

impl RangePlan {
    /// The cost shares of one thread's ranges, front to back: one large range and two small ones at the back.
    ///
    /// A thread works through its own ranges from the front and, when done, takes the other threads' unstarted
    /// ranges from their backs (`Team::map_parts`). The virtual machine makes a thread's time for the same work
    /// vary from step to step (a median 3 %, 13 % at the 90th percentile), so the two threads finish phase B on
    /// average 10 % of the phase apart; small ranges at the back of each block let the thread that finishes first
    /// take over the other's last few percent. Equal ranges cannot do that: a range large enough to keep the
    /// boundary pairs few is larger than the usual lead. This layout took 3-5 % less time than two equal ranges
    /// per thread (the measurements: `docs/performance.md`, "The parallel pass's range layout").
    pub const BLOCK: [f64; 3] = [0.8, 0.12, 0.08];

    /// The cost shares of the ranges that `threads` threads work on: `block` (one thread's ranges, front to back)
    /// once per thread; one range, the serial pass, on one thread.
    pub fn shares_for(threads: usize, block: &[f64]) -> Vec<f64> {
        if threads <= 1 || block.is_empty() {
            vec![1.0]
        } else {
            (0..threads).flat_map(|_| block.iter().copied()).collect()
        }
    }

    /// Estimated relative cost of particle i: one unit for the particle, a quarter per candidate pair, two per
    /// touching contact.
    fn particle_cost(list: &NeighborList, touching: &[bool], i: usize) -> f64 {
        Self::span_estimate(list, touching, i..i + 1)
    }

    /// The summed [`RangePlan::particle_cost`] of consecutive `particles`, from their slot range alone (their slots
    /// are consecutive): a count of touching flags, which the compiler vectorises, instead of a loop per particle.
    #[inline]
    fn span_estimate(list: &NeighborList, touching: &[bool], particles: std::ops::Range<usize>) -> f64 {
        let slots = list.start[particles.start] as usize..list.start[particles.end] as usize;
        let contacts: usize = touching[slots.clone()].iter().map(|&t| t as usize).sum();
        particles.len() as f64 + 0.25 * slots.len() as f64 + 2.0 * contacts as f64
    }

    /// Calls `f(i, cost)` for each particle i of `particles` in order: its estimated cost scaled by the measured
    /// speed of the range of `old` (bounds and relative time per unit) that held it.
    #[inline]
    fn visit_costs(
        list: &NeighborList,
        touching: &[bool],
        old: Option<(&[usize], &[f64])>,
        particles: std::ops::Range<usize>,
        mut f: impl FnMut(usize, f64),
    ) {
        let mut old_range = old.map_or(0, |(bounds, _)| bounds.partition_point(|&b| b <= particles.start) - 1);
        for i in particles {
            let estimate = Self::particle_cost(list, touching, i);
            let cost = match old {
                Some((bounds, speed)) => {
                    while i >= bounds[old_range + 1] {
                        old_range += 1;
                    }
                    estimate * speed[old_range]
                }
                None => estimate,
            };
            f(i, cost);
        }
    }

    /// A plan of one range per entry of `shares`, each holding that share of the cost (equal shares if any is not
    /// positive and finite), where the cost of each particle is its estimate scaled by the measured time per unit of
    /// estimate of the range that held it in `previous` (when that plan has timings).
    ///
    /// Made at every neighbour-list rebuild, so it must cost little next to a step: one pass over every pair slot,
    /// in chunks on `team`, gives each chunk's summed cost and the furthest partner of its particles (each from the
    /// chunk's slot range as a whole: a vectorised count of touching flags and a maximum, not a loop per particle,
    /// which made plans 0.8 % of a two-thread run); the bounds and the first particle of each range with a partner
    /// beyond it then need only the chunk sums and a scan of the few chunks where a bound falls, and each range's
    /// estimate one count over its slots.
    pub fn balanced(
        list: &NeighborList,
        touching: &[bool],
        shares: &[f64],
        previous: Option<&RangePlan>,
        team: &Team,
    ) -> RangePlan {
        let n = list.start.len().saturating_sub(1);
        let ranges = shares.len().clamp(1, n.max(1));
        let shares = if ranges == shares.len() && shares.iter().all(|&w| w.is_finite() && w > 0.0) {
            shares.to_vec()
        } else {
            vec![1.0; ranges]
        };
        // The summed shares of the ranges before range k.
        let share_before: Vec<f64> = std::iter::once(0.0)
            .chain(shares.iter().scan(0.0, |sum, &w| {
                *sum += w;
                Some(*sum)
            }))
            .collect();
        let share_sum = share_before[ranges];
        if ranges == 1 {
            // The serial pass: nothing to balance or to cross.
            return RangePlan {
                bounds: vec![0, n],
                cross_from: vec![n],
                incoming: Vec::new(),
                incoming_start: vec![0, 0],
                estimate: vec![n as f64],
                busy_ns: vec![AtomicU64::new(0)],
            };
        }
        let speed: Option<Vec<f64>> = previous.filter(|p| *p.bounds.last().unwrap_or(&0) == n).and_then(|p| {
            let per_unit: Vec<f64> = p
                .busy_ns
                .iter()
                .zip(&p.estimate)
                .map(|(t, e)| t.load(Ordering::Relaxed) as f64 / e.max(1.0))
                .collect();
            let mean = per_unit.iter().sum::<f64>() / per_unit.len().max(1) as f64;
            (mean > 0.0 && per_unit.iter().all(|&u| u > 0.0)).then(|| per_unit.iter().map(|u| u / mean).collect())
        });
        let old = speed.as_deref().zip(previous).map(|(speed, p)| (&p.bounds[..], speed));
        let last_partner = |i: usize| list.pairs_of(i).next_back().map_or(0, |k| list.partner[k] as usize);
        struct ChunkCost {
            cost: f64,
            /// The largest partner index of the chunk's particles (0: none; a partner is never particle 0).
            last_partner: usize,
        }
        let chunks: Vec<ChunkCost> = team.map_chunks(n, BUILD_CHUNK, |particles| {
            let slots = list.start[particles.start] as usize..list.start[particles.end] as usize;
            // Partners are ascending per particle, so the largest partner of any slot is the largest last partner.
            let last_partner = list.partner[slots].iter().copied().max().map_or(0, |j| j as usize);
            // The chunk's pieces in each range of the old plan, each scaled by that range's speed.
            let cost = match old {
                Some((bounds, speed)) => {
                    let mut cost = 0.0;
                    let (mut lo, mut r) = (particles.start, bounds.partition_point(|&b| b <= particles.start) - 1);
                    while lo < particles.end {
                        let hi = bounds[r + 1].min(particles.end);
                        cost += Self::span_estimate(list, touching, lo..hi) * speed[r];
                        (lo, r) = (hi, r + 1);
                    }
                    cost
                }
                None => Self::span_estimate(list, touching, particles),
            };
            ChunkCost { cost, last_partner }
        });
        let chunk_of = |c: usize| c * BUILD_CHUNK..((c + 1) * BUILD_CHUNK).min(n);

        // Bound k is the first particle before which the summed cost reaches the first k ranges' share of the total.
        let total: f64 = chunks.iter().map(|c| c.cost).sum();
        let target = |k: usize| total * share_before[k] / share_sum;
        let mut bounds = vec![0usize];
        let (mut running, mut next) = (0.0, 1);
        for (c, chunk) in chunks.iter().enumerate() {
            if next >= ranges {
                break;
            }
            if running + chunk.cost < target(next) {
                running += chunk.cost;
                continue;
            }
            Self::visit_costs(list, touching, old, chunk_of(c), |i, cost| {
                while next < ranges && running >= target(next) {
                    bounds.push(i);
                    next += 1;
                }
                running += cost;
            });
        }
        while bounds.len() < ranges {
            bounds.push(n);
        }
        bounds.push(n);

        let cross_from: Vec<usize> = (0..ranges)
            .map(|r| {
                let (lo, hi) = (bounds[r], bounds[r + 1]);
                if lo >= hi {
                    return hi;
                }
                (lo / BUILD_CHUNK..=(hi - 1) / BUILD_CHUNK)
                    .filter(|&c| chunks[c].last_partner >= hi)
                    .find_map(|c| {
                        let particles = chunk_of(c);
                        (lo.max(particles.start)..hi.min(particles.end)).find(|&i| last_partner(i) >= hi)
                    })
                    .unwrap_or(hi)
            })
            .collect();
        let estimate = (0..ranges)
            .map(|r| Self::span_estimate(list, touching, bounds[r]..bounds[r + 1]))
            .collect();
        // Ranges are scanned in ascending order and each range's particles ascending, so every target range gets
        // its incoming slots in ascending first particle.
        let mut per_target: Vec<Vec<(u32, u32)>> = vec![Vec::new(); ranges];
        for r in 0..ranges {
            let hi = bounds[r + 1];
            for i in cross_from[r]..hi {
                for k in list.pairs_of(i) {
                    let j = list.partner[k] as usize;
                    if j >= hi {
                        let target = bounds.partition_point(|&b| b <= j) - 1;
                        per_target[target].push((k as u32, j as u32));
                    }
                }
            }
        }
        let mut incoming_start = vec![0];
        for t in &per_target {
            incoming_start.push(incoming_start.last().copied().unwrap_or(0) + t.len());
        }
        RangePlan {
            bounds,
            cross_from,
            incoming: per_target.concat(),
            incoming_start,
            estimate,
            busy_ns: (0..ranges).map(|_| AtomicU64::new(0)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A list of `n` particles whose partners are mostly near in index (as in a spatially sorted bed), with now and
    /// then one far away (as across a periodic axis), and a touching flag per slot.
    fn random_list(n: usize, seed: u64) -> (NeighborList, Vec<bool>) {
        let mut state = seed;
        let mut next = move |m: usize| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % m as u64) as usize
        };
        let mut list = NeighborList::default();
        list.start.push(0);
        list.wall_start.resize(n + 1, 0);
        let mut touching = Vec::new();
        for i in 0..n {
            let count = next(6);
            let mut partners: Vec<u32> = (0..count).map(|_| (i + 1 + next(200)) as u32).collect();
            if next(50) == 0 {
                partners.push((i + 1 + next(n)) as u32);
            }
            partners.retain(|&j| (j as usize) < n);
            partners.sort_unstable();
            partners.dedup();
            touching.extend(partners.iter().map(|_| next(3) == 0));
            list.partner.extend(partners);
            list.start.push(list.partner.len() as u32);
        }
        (list, touching)
    }

    /// The plan made from chunk sums equals what its definition gives particle by particle: bound k is the first
    /// particle before which the summed (speed-scaled) cost reaches the first k ranges' share of the total,
    /// `cross_from` the first particle of a range with a partner beyond it, `incoming` every slot whose partner lies
    /// in a later range; on one thread and on two, with equal and unequal shares.
    #[test]
    fn balanced_plan_matches_its_definition_particle_by_particle() {
        let block = RangePlan::shares_for(2, &RangePlan::BLOCK);
        for (n, shares, seed) in [
            (5000, vec![1.0; 4], 1),
            (3000, vec![1.0; 7], 2),
            (1500, vec![1.0; 2], 3),
            (40, vec![1.0; 4], 4),
            (4000, block.clone(), 5),
            (3000, vec![0.5, 3.0, 0.25, 1.0, 0.1], 6),
        ] {
            let ranges = shares.len();
            let (list, touching) = random_list(n, seed);
            let first = RangePlan::balanced(&list, &touching, &shares, None, &Team::new(1));
            // Give the first plan unequal timings, so that the next is scaled by speed.
            for (r, busy) in first.busy_ns.iter().enumerate() {
                busy.store(
                    1000 * (r as u64 + 1) * (first.bounds[r + 1] - first.bounds[r]) as u64 + 1,
                    Ordering::Relaxed,
                );
            }
            for team in [Team::new(1), Team::new(2)] {
                let plan = RangePlan::balanced(&list, &touching, &shares, Some(&first), &team);
                let per_unit: Vec<f64> = first
                    .busy_ns
                    .iter()
                    .zip(&first.estimate)
                    .map(|(t, e)| t.load(Ordering::Relaxed) as f64 / e.max(1.0))
                    .collect();
                let mean = per_unit.iter().sum::<f64>() / per_unit.len() as f64;
                let old_range = |i: usize| first.bounds.partition_point(|&b| b <= i) - 1;
                let cost: Vec<f64> = (0..n)
                    .map(|i| RangePlan::particle_cost(&list, &touching, i) * per_unit[old_range(i)] / mean)
                    .collect();
                let total: f64 = cost.iter().sum();
                assert_eq!(plan.bounds.len(), ranges + 1);
                assert_eq!((plan.bounds[0], plan.bounds[ranges]), (0, n));
                for k in 1..ranges {
                    let b = plan.bounds[k];
                    let before: f64 = cost[..b].iter().sum();
                    let target = total * shares[..k].iter().sum::<f64>() / shares.iter().sum::<f64>();
                    assert!(before >= target * (1.0 - 1e-12), "bound {k} = {b} comes too early");
                    assert!(
                        b == 0 || before - cost[b - 1] < target * (1.0 + 1e-12),
                        "bound {k} = {b} comes too late"
                    );
                }
                let last_partner = |i: usize| list.pairs_of(i).next_back().map_or(0, |k| list.partner[k] as usize);
                let mut incoming = vec![Vec::new(); ranges];
                for r in 0..ranges {
                    let (lo, hi) = (plan.bounds[r], plan.bounds[r + 1]);
                    let expected = (lo..hi).find(|&i| last_partner(i) >= hi).unwrap_or(hi);
                    assert_eq!(plan.cross_from[r], expected, "range {r} of {ranges}");
                    let estimate: f64 = (lo..hi).map(|i| RangePlan::particle_cost(&list, &touching, i)).sum();
                    assert!((plan.estimate[r] - estimate).abs() <= 1e-9 * estimate.max(1.0));
                    for i in lo..hi {
                        for k in list.pairs_of(i) {
                            let j = list.partner[k] as usize;
                            if j >= hi {
                                let target = plan.bounds.partition_point(|&b| b <= j) - 1;
                                incoming[target].push((k as u32, j as u32));
                            }
                        }
                    }
                }
                for (r, slots) in incoming.iter().enumerate() {
                    let got = &plan.incoming[plan.incoming_start[r]..plan.incoming_start[r + 1]];
                    assert_eq!(got, slots.as_slice(), "incoming slots of range {r}");
                }
            }
        }
    }
}
