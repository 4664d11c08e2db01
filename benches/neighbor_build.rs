//! Criterion benchmarks of the neighbour lists' two builds, on one thread and on a team of two: the cell search
//! (`NeighborList::build`, skin 0.6 mm) and the refilter of its candidates with the force pass's inner skin (0.15 mm),
//! for a settled-column-like packing of the DEM benchmark's spheres (29,160 of d = 3 mm in a 60 × 60 mm box, hexagonal
//! close-packed layers with a 0.05 % gap, slightly jittered). The ratio of the one-thread and two-thread times is the
//! list work's parallel efficiency without the force pass around it.
//!
//! Run: `cargo bench --bench neighbor_build`.

use criterion::{Criterion, criterion_group, criterion_main};
use granflow::engine::Vec3;
use granflow::engine::geometry::Domain;
use granflow::engine::neighbor::{Criteria, NeighborList, Reach};
use granflow::engine::team::Team;

const RADIUS_M: f64 = 0.0015;
const PARTICLES: usize = 29_160;
const SIDE_M: f64 = 0.06;

/// Hexagonal close-packed layers of spheres of `RADIUS_M` filling the box from the floor up, centres a little more
/// than a diameter apart, each shifted by up to 5 µm by a fixed hash so that distances are not all equal.
fn packing() -> Vec<Vec3> {
    let spacing = 2.0 * RADIUS_M * 1.0005;
    let row = spacing * 3f64.sqrt() / 2.0;
    let layer = spacing * (2.0f64 / 3.0).sqrt();
    let mut out = Vec::with_capacity(PARTICLES);
    for iz in 0.. {
        let shift_y = if iz % 2 == 1 {
            spacing / (2.0 * 3f64.sqrt())
        } else {
            0.0
        };
        for iy in 0.. {
            let y = RADIUS_M + iy as f64 * row + shift_y;
            if y > SIDE_M - RADIUS_M {
                break;
            }
            let shift_x = if (iy + iz) % 2 == 1 { spacing / 2.0 } else { 0.0 };
            for ix in 0.. {
                let x = RADIUS_M + ix as f64 * spacing + shift_x;
                if x > SIDE_M - RADIUS_M {
                    break;
                }
                let k = out.len() as u64;
                let jitter = ((k.wrapping_mul(2_654_435_761) % 1000) as f64 / 1000.0 - 0.5) * 1e-5;
                out.push(Vec3::new(x + jitter, y - jitter, RADIUS_M + iz as f64 * layer));
                if out.len() == PARTICLES {
                    return out;
                }
            }
        }
    }
    unreachable!("the loop over layers returns")
}

fn lists(c: &mut Criterion) {
    let position = packing();
    let radius = vec![RADIUS_M; position.len()];
    let domain = Domain::new(Vec3::zeros(), Vec3::new(SIDE_M, SIDE_M, 0.3), [false; 3]);
    let outer = Criteria {
        domain: &domain,
        position: &position,
        radius: &radius,
        skin_m: 6e-4,
        range: Reach::default(),
        walls: &[],
        wall_angle: &[],
        wall_turn: &[],
        pseudo_2d: false,
    };
    let inner = Criteria {
        skin_m: 1.5e-4,
        ..outer
    };
    for threads in [1, 2] {
        let team = Team::new(threads);
        let mut candidates = NeighborList::default();
        candidates.build(&outer, &team);
        let mut list = NeighborList::default();
        list.refilter(&candidates, &inner, &team);
        assert!(
            list.pair_count() > 5 * PARTICLES,
            "a dense packing has about six pairs per sphere"
        );
        c.bench_function(&format!("neighbor/cell_search/{threads}_thread"), |b| {
            b.iter(|| candidates.build(&outer, &team))
        });
        c.bench_function(&format!("neighbor/refilter/{threads}_thread"), |b| {
            b.iter(|| list.refilter(&candidates, &inner, &team))
        });
        team.rest();
    }
}

criterion_group!(benches, lists);
criterion_main!(benches);
