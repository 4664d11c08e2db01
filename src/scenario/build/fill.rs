//! The fills of a scenario (`fill:`): lattices (optionally jittered, or only the points inside a drum) and random
//! sequential insertion, each particle kept only where it touches no wall and lies in the box; validated at each
//! entry's key.

use std::f64::consts::PI;

use rand::RngExt;

use super::{Checker, MAX_LATTICE_POINTS, lattice_points, lattice_range};
use crate::engine::Vec3;
use crate::engine::geometry::{Domain, Wall, WallShape};
use crate::engine::particles::{Particles, SpeciesId, SpeciesTable};
use crate::scenario::ConfigError;
use crate::scenario::spec::{FillSpec, ScenarioSpec};

/// True when a particle at `x` of radius `r` touches no wall and lies in the box.
fn fits(x: &Vec3, r: f64, walls: &[Wall], domain: &Domain) -> bool {
    (0..3).all(|a| domain.periodic[a] || (x[a] - r >= domain.lo_m[a] && x[a] + r <= domain.hi_m[a]))
        && walls.iter().all(|w| w.proximity(x, 0.0).gap_m >= r)
}

pub(super) fn drum_named<'a>(c: &Checker, key: &str, walls: &'a [Wall], name: &str) -> Result<&'a Wall, ConfigError> {
    walls
        .iter()
        .find(|w| w.name == name && matches!(w.shape(), WallShape::RotatingCylinder { .. }))
        .ok_or_else(|| c.fail(key, format!("no drum named '{name}'")))
}

pub(super) fn fill(
    c: &Checker,
    spec: &ScenarioSpec,
    species: &SpeciesTable,
    domain: &Domain,
    walls: &[Wall],
    rng: &mut rand_chacha::ChaCha8Rng,
) -> Result<(Particles, Vec<usize>), ConfigError> {
    let mut particles = Particles::default();
    let mut fill_ends = Vec::with_capacity(spec.fill.len());
    if spec.fill.is_empty() {
        return Err(c.fail("fill", "expected at least one fill entry"));
    }
    for (k, f) in spec.fill.iter().enumerate() {
        match f {
            FillSpec::Lattice {
                species: s,
                spacing_m,
                lo_m,
                hi_m,
                origin_m,
                inside_drum,
                jitter_m,
                temperature_k: _,
            } => {
                let key = |f: &str| format!("fill[{k}].lattice.{f}");
                let id = c.species(&key("species"), species, s)?;
                let sp = species.get(id);
                c.positive(&key("spacing_m"), *spacing_m)?;
                c.finite3(&key("lo_m"), lo_m)?;
                c.finite3(&key("hi_m"), hi_m)?;
                c.finite3(&key("origin_m"), origin_m)?;
                if *spacing_m < 2.0 * sp.radius_m {
                    return Err(c.fail(
                        key("spacing_m"),
                        format!(
                            "lattice spacing {spacing_m} m is smaller than the particle diameter {} m",
                            2.0 * sp.radius_m
                        ),
                    ));
                }
                if let Some(d) = inside_drum {
                    drum_named(c, &key("inside_drum"), walls, d)?;
                }
                let jitter_m = *jitter_m;
                c.non_negative(&key("jitter_m"), jitter_m)?;
                // (The 1e-9 spacing slack lets "half the gap" be written as a decimal: 0.003 − 0.0027 ≠ 0.0003.)
                if 2.0 * jitter_m > spacing_m - 2.0 * sp.radius_m + 1e-9 * spacing_m {
                    return Err(c.fail(
                        key("jitter_m"),
                        format!(
                            "jitter {jitter_m} m could make neighbours overlap: at most half the gap between them, (spacing − diameter)/2 = {} m",
                            0.5 * (spacing_m - 2.0 * sp.radius_m)
                        ),
                    ));
                }
                let range = lattice_range(*spacing_m, lo_m, hi_m, origin_m);
                let count = lattice_points(&range);
                if count > MAX_LATTICE_POINTS {
                    return Err(c.fail(
                        key("spacing_m"),
                        format!("the lattice would hold {count} points (limit {MAX_LATTICE_POINTS})"),
                    ));
                }
                let before = particles.len();
                for iz in range[2].0..=range[2].1 {
                    for iy in range[1].0..=range[1].1 {
                        for ix in range[0].0..=range[0].1 {
                            let mut x = Vec3::new(
                                origin_m[0] + ix as f64 * spacing_m,
                                origin_m[1] + iy as f64 * spacing_m,
                                origin_m[2] + iz as f64 * spacing_m,
                            );
                            if (0..3).any(|a| x[a] < lo_m[a] || x[a] >= hi_m[a]) {
                                continue;
                            }
                            if jitter_m > 0.0 {
                                for a in 0..3 {
                                    if range[a].1 > range[a].0 {
                                        x[a] += rng.random_range(-jitter_m..=jitter_m);
                                    }
                                }
                            }
                            if fits(&x, sp.radius_m, walls, domain) {
                                particles.push(id, sp, sp.radius_m, x);
                            }
                        }
                    }
                }
                if particles.len() == before {
                    return Err(c.fail(
                        format!("fill[{k}].lattice"),
                        "no particle fits: the lattice region lies outside the walls or the box",
                    ));
                }
            }
            FillSpec::Explicit {
                species: s,
                positions_m,
                velocities_m_per_s,
                angular_velocities_rad_per_s,
                temperature_k: _,
            } => {
                let key = |f: &str| format!("fill[{k}].explicit.{f}");
                let id = c.species(&key("species"), species, s)?;
                let sp = species.get(id);
                if positions_m.is_empty() {
                    return Err(c.fail(key("positions_m"), "expected at least one position"));
                }
                for (name, list) in [
                    ("velocities_m_per_s", velocities_m_per_s),
                    ("angular_velocities_rad_per_s", angular_velocities_rad_per_s),
                ] {
                    if !list.is_empty() && list.len() != positions_m.len() {
                        return Err(c.fail(
                            key(name),
                            format!(
                                "expected {} entries (one per position) or none, got {}",
                                positions_m.len(),
                                list.len()
                            ),
                        ));
                    }
                }
                for (n, x) in positions_m.iter().enumerate() {
                    c.finite3(&key(&format!("positions_m[{n}]")), x)?;
                    let x = Vec3::from(*x);
                    // CHOICE: explicit particles may start pressed into a wall by up to 1 % of their radius (a
                    // particle resting at its static overlap); anything more is an input error.
                    if !fits(&x, 0.99 * sp.radius_m, walls, domain) {
                        return Err(c.fail(
                            key(&format!("positions_m[{n}]")),
                            "the particle overlaps a wall or leaves the box",
                        ));
                    }
                    let id = particles.push(id, sp, sp.radius_m, x);
                    if let Some(v) = velocities_m_per_s.get(n) {
                        c.finite3(&key(&format!("velocities_m_per_s[{n}]")), v)?;
                        particles.velocity_m_per_s[id.index()] = Vec3::from(*v);
                    }
                    if let Some(w) = angular_velocities_rad_per_s.get(n) {
                        c.finite3(&key(&format!("angular_velocities_rad_per_s[{n}]")), w)?;
                        if !spec.rotation && w.iter().any(|&a| a != 0.0) {
                            return Err(c.fail(
                                key(&format!("angular_velocities_rad_per_s[{n}]")),
                                "particles that do not rotate (`rotation: false`) cannot start spinning",
                            ));
                        }
                        particles.angular_velocity_rad_per_s[id.index()] = Vec3::from(*w);
                    }
                }
            }
            FillSpec::Random {
                species: s,
                count,
                lo_m,
                hi_m,
                inside_drum,
                temperature_k: _,
            } => {
                let key = |f: &str| format!("fill[{k}].random.{f}");
                let id = c.species(&key("species"), species, s)?;
                let sp = species.get(id);
                c.finite3(&key("lo_m"), lo_m)?;
                c.finite3(&key("hi_m"), hi_m)?;
                if *count == 0 {
                    return Err(c.fail(key("count"), "expected at least 1"));
                }
                if let Some(d) = inside_drum {
                    drum_named(c, &key("inside_drum"), walls, d)?;
                }
                let r = sp.radius_m;
                // Centres confined to a plane (a pseudo-2-D layer) still fill a slab one diameter thick.
                let region_volume: f64 = (0..3).map(|a| (hi_m[a] - lo_m[a]).max(2.0 * r)).product();
                let solid = *count as f64 * 4.0 / 3.0 * PI * r.powi(3);
                if solid > 0.6 * region_volume {
                    return Err(c.fail(
                        key("count"),
                        format!(
                            "{count} particles of radius {r} m need {solid:.3e} m³ of solid, more than random insertion can place in the {region_volume:.3e} m³ region (at most ~60 % packing)"
                        ),
                    ));
                }
                let placed = random_insert(&mut particles, id, sp, *count as usize, lo_m, hi_m, walls, domain, rng);
                if placed == 0 {
                    return Err(c.fail(
                        format!("fill[{k}].random"),
                        "no particle fits: the region lies outside the walls or the box",
                    ));
                }
                if placed < *count as usize {
                    return Err(c.fail(
                        key("count"),
                        format!("could place only {placed} of {count} particles without overlap in the region; enlarge it or lower the count"),
                    ));
                }
            }
        }
        fill_ends.push(particles.len());
    }
    Ok((particles, fill_ends))
}

/// Random sequential insertion with rejection of overlaps (against all particles placed so far).
#[allow(clippy::too_many_arguments)]
fn random_insert(
    particles: &mut Particles,
    id: SpeciesId,
    sp: &crate::engine::particles::Species,
    count: usize,
    lo: &[f64; 3],
    hi: &[f64; 3],
    walls: &[Wall],
    domain: &Domain,
    rng: &mut rand_chacha::ChaCha8Rng,
) -> usize {
    use std::collections::BTreeMap;
    let r = sp.radius_m;
    let cell = 2.0 * particles.max_radius_m().max(r);
    let key = |x: &Vec3| -> [i64; 3] { [0, 1, 2].map(|a| (x[a] / cell).floor() as i64) };
    // Lookup only (never iterated), so the map's order cannot leak into results; BTreeMap keeps it obviously so.
    let mut grid: BTreeMap<[i64; 3], Vec<usize>> = BTreeMap::new();
    for i in 0..particles.len() {
        grid.entry(key(&particles.position_m[i])).or_default().push(i);
    }
    let mut placed = 0;
    let max_attempts = 1000 * count;
    let mut attempts = 0;
    while placed < count && attempts < max_attempts {
        attempts += 1;
        let x = Vec3::new(
            rng.random_range(lo[0]..=hi[0]),
            rng.random_range(lo[1]..=hi[1]),
            rng.random_range(lo[2]..=hi[2]),
        );
        if !fits(&x, r, walls, domain) {
            continue;
        }
        let k = key(&x);
        let mut clear = true;
        if domain.periodic.iter().any(|&p| p) {
            // The grid does not wrap; periodic images are checked by brute force (fills are built once).
            clear = (0..particles.len()).all(|j| {
                let reach = r + particles.radius_m[j];
                domain.separation(&x, &particles.position_m[j]).norm_squared() >= reach * reach
            });
        } else {
            'search: for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        if let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            for &j in list {
                                let reach = r + particles.radius_m[j];
                                if domain.separation(&x, &particles.position_m[j]).norm_squared() < reach * reach {
                                    clear = false;
                                    break 'search;
                                }
                            }
                        }
                    }
                }
            }
        }
        if clear {
            let i = particles.len();
            particles.push(id, sp, r, x);
            grid.entry(k).or_default().push(i);
            placed += 1;
        }
    }
    placed
}
