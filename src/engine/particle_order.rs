//! Particles sorted by place: the order of the particle arrays that keeps neighbours close in memory and cuts the
//! parallel pair pass's ranges into compact slabs (`neighbor.sort_every_steps`).
//!
//! The pair pass sums every particle's forces in an order fixed by the particle indices, and splits its work into
//! contiguous index ranges (`range_plan.rs`). Particles filled on a lattice start in spatial order, but a bed that
//! mixes (a bubbling or spouted bed, a drum) scatters them: after a few seconds neighbours in space are anywhere in
//! the arrays, nearly every pair crosses a range boundary, and the two threads spend the step moving each other's
//! cache lines (seed 002's central-jet bed of 2,400 beads ran its contact pass 1.75× *slower* on two threads than on
//! one; `docs/performance.md`). LAMMPS and LIGGGHTS sort their atoms by cell every 1000 steps for the same reason
//! (`atom_modify sort`).
//!
//! A sort is a pure function of the state: cells of one largest diameter, numbered with the particles' longest
//! extent slowest (so that contiguous ranges are slabs across it) and ties kept in the present order. It happens at
//! the end of every step whose number is a multiple of the period, so a run resumed from a checkpoint sorts at the
//! same steps as one that never stopped, whatever the thread count. It changes the bits of a run (sums are formed in
//! another order), not its physics: a contact's history moves with its pair, and where the pair's two particles
//! change places its vectors, which are particle i's side of the contact, change sign ([`ContactHistory::mirrored`]).

use super::Vec3;
use super::contacts::ContactStore;
use super::models::ContactHistory;
use super::particles::ParticleId;
use super::state::SimState;

/// The order that sorts particles at `position_m` by place: entry k is the present index of the particle that
/// becomes particle k. Cells are cubes of edge `cell_m` from the lowest particle position; the axis along which the
/// particles spread furthest varies slowest, the narrowest fastest; particles of one cell keep their present order.
pub fn spatial_order(position_m: &[Vec3], cell_m: f64) -> Vec<usize> {
    let n = position_m.len();
    if n == 0 {
        return Vec::new();
    }
    let (mut lo, mut hi) = (position_m[0], position_m[0]);
    for x in position_m {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let extent = hi - lo;
    // Slowest axis first: the widest spread (ties by axis number, so the order is a function of the positions).
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&a, &b| extent[b].total_cmp(&extent[a]).then(a.cmp(&b)));
    let inv_cell = if cell_m > 0.0 && cell_m.is_finite() {
        1.0 / cell_m
    } else {
        0.0
    };
    // Cell coordinates are at most (extent / cell) and saturate at u32::MAX (an absurd spread only coarsens the
    // order; it never fails).
    let cell = |x: &Vec3, a: usize| ((x[a] - lo[a]) * inv_cell) as u32;
    let mut keys: Vec<([u32; 3], u32)> = position_m
        .iter()
        .enumerate()
        .map(|(i, x)| ([cell(x, axes[0]), cell(x, axes[1]), cell(x, axes[2])], i as u32))
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(|(_, i)| i as usize).collect()
}

/// `state` with its particles in `order` (entry k: the present index of the particle that becomes particle k): the
/// particle arrays, the contact records (re-keyed by the new indices, each pair under its lower index, mirrored
/// where its particles change places) and the gas's per-particle held-drag state. Everything else in the state is
/// not per particle. `order` must be a permutation of the particle indices.
pub fn reorder_state(state: &mut SimState, order: &[usize]) {
    let n = state.particles.len();
    assert_eq!(order.len(), n, "a particle order covers every particle");
    let mut new_index = vec![u32::MAX; n];
    for (k, &i) in order.iter().enumerate() {
        new_index[i] = k as u32;
    }
    assert!(
        new_index.iter().all(|&k| k != u32::MAX),
        "a particle order is a permutation"
    );
    state.particles = state.particles.permuted(order);
    state.contacts = reorder_contacts(&state.contacts, &new_index);
    if let Some(held) = state.gas.as_mut().and_then(|g| g.held_drag.as_mut()) {
        let gather = |column: &[Vec3]| order.iter().map(|&i| column[i]).collect::<Vec<_>>();
        held.position_m = gather(&held.position_m);
        held.velocity_m_per_s = gather(&held.velocity_m_per_s);
        held.velocity_sum_m_per_s = gather(&held.velocity_sum_m_per_s);
    }
}

/// The records of `store` under the indices `new_index[old]`, in key order again.
fn reorder_contacts(store: &ContactStore, new_index: &[u32]) -> ContactStore {
    let mut pairs: Vec<(ParticleId, ParticleId, ContactHistory)> = store
        .pairs
        .iter()
        .map(|&(i, j, h)| {
            let (a, b) = (new_index[i.index()], new_index[j.index()]);
            if a < b {
                (ParticleId(a), ParticleId(b), h)
            } else {
                (ParticleId(b), ParticleId(a), h.mirrored())
            }
        })
        .collect();
    pairs.sort_unstable_by_key(|&(i, j, _)| (i, j));
    let mut walls: Vec<_> = store
        .walls
        .iter()
        .map(|&(i, w, h)| (ParticleId(new_index[i.index()]), w, h))
        .collect();
    walls.sort_unstable_by_key(|&(i, w, _)| (i, w));
    ContactStore { pairs, walls }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_order_is_slabs_across_the_widest_spread_and_keeps_ties_in_place() {
        // Spread 0.9 m along y, 0.15 m along x, nothing along z: y varies slowest.
        let x = vec![
            Vec3::new(0.10, 0.80, 0.0),
            Vec3::new(0.01, 0.00, 0.0),
            Vec3::new(0.15, 0.01, 0.0),
            Vec3::new(0.0, 0.90, 0.0),
            Vec3::new(0.012, 0.001, 0.0),
        ];
        // Cells of 0.05 m: particles 1, 4 share cell (x 0, y 0); 2 is (x 3, y 0); 3 is (x 0, y 18); 0 is (x 2, y 16).
        assert_eq!(spatial_order(&x, 0.05), vec![1, 4, 2, 0, 3]);
        // The same positions in another order give the same places, ties in their present order.
        assert_eq!(spatial_order(&[x[4], x[1]], 0.05), vec![0, 1]);
        assert!(spatial_order(&[], 0.05).is_empty());
        // A non-finite or zero cell puts every particle in one cell: the present order.
        assert_eq!(spatial_order(&x, 0.0), vec![0, 1, 2, 3, 4]);
    }

    #[test]
    fn contacts_follow_their_particles_and_mirror_when_the_pair_turns_round() {
        let shear = Vec3::new(1.0e-6, -2.0e-6, 3.0e-6);
        let mut h = ContactHistory::INACTIVE;
        h.active = true;
        h.tangential.shear = shear;
        h.cohesion.bridge_volume_m3 = 1.0e-12;
        let store = ContactStore {
            pairs: vec![(ParticleId(0), ParticleId(2), h), (ParticleId(1), ParticleId(2), h)],
            walls: vec![(ParticleId(0), super::super::contacts::WallId(3), h)],
        };
        // Particle 2 becomes 0, 0 becomes 1, 1 becomes 2.
        let reordered = reorder_contacts(&store, &[1, 2, 0]);
        let pairs: Vec<_> = reordered
            .pairs
            .iter()
            .map(|&(i, j, h)| (i.0, j.0, h.tangential.shear))
            .collect();
        assert_eq!(pairs, vec![(0, 1, -shear), (0, 2, -shear)]);
        assert!(
            reordered
                .pairs
                .iter()
                .all(|(_, _, r)| r.cohesion.bridge_volume_m3 == 1.0e-12 && r.active)
        );
        assert_eq!(reordered.walls[0].0, ParticleId(1));
        assert_eq!(reordered.walls[0].2.tangential.shear, shear);
    }
}
