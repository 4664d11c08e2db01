//! The walls of a scenario: the box's planes, named planes and drums (with their glued beads; drums with baffles), validated
//! (each error names the key) and turned into the engine's [`Wall`]s in the order the engine indexes them.

use std::f64::consts::PI;

use super::Checker;
use crate::engine::Vec3;
use crate::engine::geometry::{Domain, RotatingFrame, Wall, WallShape};
use crate::engine::particles::SpeciesTable;
use crate::scenario::ConfigError;
use crate::scenario::spec::{BaffleSpec, DrumSpec, GluedBeadsSpec, PlaneBeadsSpec, ScenarioSpec, WallSpec};

/// The scenario's walls: per `walls` entry, a box's planes (one per non-periodic face), a plane, or a drum followed
/// by its glued-bead sub-lattices and its baffle plates.
pub(super) fn build_walls(
    c: &Checker,
    spec: &ScenarioSpec,
    species: &SpeciesTable,
    domain: &Domain,
) -> Result<Vec<Wall>, ConfigError> {
    let mut walls = Vec::new();
    for (k, w) in spec.walls.iter().enumerate() {
        match w {
            WallSpec::Box { species: s } => {
                let id = c.species(&format!("walls[{k}].box.species"), species, s)?;
                for axis in 0..3 {
                    if domain.periodic[axis] {
                        continue;
                    }
                    let axis_name = ["x", "y", "z"][axis];
                    for (side, point, sign) in [("lo", domain.lo_m, 1.0), ("hi", domain.hi_m, -1.0)] {
                        let mut normal = Vec3::zeros();
                        normal[axis] = sign;
                        walls.push(Wall::new(
                            format!("box_{axis_name}_{side}"),
                            id,
                            WallShape::Plane { point_m: point, normal },
                        ));
                    }
                }
            }
            WallSpec::Plane {
                name,
                species: s,
                point_m,
                normal,
                glued_beads,
            } => {
                let id = c.species(&format!("walls[{k}].plane.species"), species, s)?;
                c.finite3(&format!("walls[{k}].plane.point_m"), point_m)?;
                let n = c.unit3(&format!("walls[{k}].plane.normal"), normal)?;
                walls.push(Wall::new(
                    name.clone(),
                    id,
                    WallShape::Plane {
                        point_m: Vec3::from(*point_m),
                        normal: n,
                    },
                ));
                if let Some(beads) = glued_beads {
                    walls.extend(plane_bead_walls(
                        c,
                        spec,
                        domain,
                        k,
                        name,
                        Vec3::from(*point_m),
                        n,
                        beads,
                        id,
                    )?);
                }
            }
            WallSpec::Drum(d) => {
                let key = |f: &str| format!("walls[{k}].drum.{f}");
                let id = c.species(&key("species"), species, &d.species)?;
                c.finite3(&key("axis_point_m"), &d.axis_point_m)?;
                let axis = c.unit3(&key("axis"), &d.axis)?;
                c.positive(&key("radius_m"), d.radius_m)?;
                // The drum's cross-section must lie in the box on every non-periodic axis across its axis: outside
                // the box a particle is lost, so a drum larger than the domain fails the run instead of confining it.
                // (Along an axis the drum's axis is not perpendicular to, the cylinder is unbounded and the box
                // caps it.)
                for a in 0..3 {
                    if domain.periodic[a] || axis[a].abs() > 1e-9 {
                        continue;
                    }
                    let (lo, hi) = (d.axis_point_m[a] - d.radius_m, d.axis_point_m[a] + d.radius_m);
                    if lo < domain.lo_m[a] || hi > domain.hi_m[a] {
                        let axis_name = ["x", "y", "z"][a];
                        return Err(c.fail(
                            key("radius_m"),
                            format!(
                                "expected the drum inside the domain along {axis_name} ({} to {} m), got {lo} to {hi} m (axis point {} m, radius {} m)",
                                domain.lo_m[a], domain.hi_m[a], d.axis_point_m[a], d.radius_m
                            ),
                        ));
                    }
                }
                if !d.rotation_rpm.is_finite() {
                    return Err(c.fail(
                        key("rotation_rpm"),
                        format!("expected a finite number, got {}", d.rotation_rpm),
                    ));
                }
                let omega = d.rotation_rpm * 2.0 * PI / 60.0;
                let frame = RotatingFrame::new(Vec3::from(d.axis_point_m), axis, omega);
                walls.push(Wall::new(
                    d.name.clone(),
                    id,
                    WallShape::RotatingCylinder {
                        frame,
                        radius_m: d.radius_m,
                    },
                ));
                if let Some(beads) = &d.glued_beads {
                    walls.extend(glued_bead_walls(c, spec, domain, k, d, beads, frame, id)?);
                }
                for (b, baffle) in d.baffles.iter().enumerate() {
                    let bkey = |f: &str| format!("walls[{k}].drum.baffles[{b}].{f}");
                    for (s, (start, end), half) in baffle_segments(c, baffle, d.radius_m, &bkey)? {
                        // A plate must stay inside the drum (a wall baffle's foot sits on the wall itself).
                        let farthest_m = start[0].hypot(start[1]).max(end[0].hypot(end[1]));
                        if farthest_m.is_nan() || farthest_m > d.radius_m * (1.0 + 1e-9) {
                            return Err(c.fail(
                                format!("walls[{k}].drum.baffles[{b}]"),
                                format!(
                                    "plate {s} reaches {farthest_m} m from the axis: outside the drum radius {} m",
                                    d.radius_m
                                ),
                            ));
                        }
                        walls.push(Wall::new(
                            format!("{}_baffle_{b}_{s}", d.name),
                            id,
                            WallShape::Baffle {
                                frame,
                                start_m: start,
                                end_m: end,
                                half_thickness_m: half,
                            },
                        ));
                    }
                }
            }
        }
    }
    if walls.len() > u16::MAX as usize {
        return Err(c.fail("walls", format!("at most {} walls, got {}", u16::MAX, walls.len())));
    }
    Ok(walls)
}

type Segment = ([f64; 2], [f64; 2]);

/// The plates of one baffle entry as (index, segment, half-thickness).
fn baffle_segments(
    c: &Checker,
    baffle: &BaffleSpec,
    drum_radius_m: f64,
    key: &dyn Fn(&str) -> String,
) -> Result<Vec<(usize, Segment, f64)>, ConfigError> {
    let mut out = Vec::new();
    match *baffle {
        BaffleSpec::Traditional {
            count,
            length_m,
            half_thickness_m,
            tilt_deg,
        } => {
            c.positive(&key("length_m"), length_m)?;
            c.positive(&key("half_thickness_m"), half_thickness_m)?;
            if count == 0 {
                return Err(c.fail(key("count"), "expected at least 1"));
            }
            if length_m >= drum_radius_m {
                return Err(c.fail(
                    key("length_m"),
                    format!("a wall baffle must be shorter than the drum radius {drum_radius_m} m"),
                ));
            }
            if !(tilt_deg.is_finite() && tilt_deg.abs() < 80.0) {
                return Err(c.fail(key("tilt_deg"), format!("expected |tilt| < 80°, got {tilt_deg}")));
            }
            let tilt = tilt_deg.to_radians();
            for k in 0..count as usize {
                let phi = 2.0 * PI * k as f64 / count as f64;
                let base = [drum_radius_m * phi.cos(), drum_radius_m * phi.sin()];
                // Inward radial direction turned by the tilt.
                let dir_angle = phi + PI + tilt;
                let tip = [
                    base[0] + length_m * dir_angle.cos(),
                    base[1] + length_m * dir_angle.sin(),
                ];
                out.push((k, (base, tip), half_thickness_m));
            }
        }
        BaffleSpec::Axial {
            count,
            length_m,
            half_thickness_m,
            inner_radius_m,
        } => {
            c.positive(&key("length_m"), length_m)?;
            c.positive(&key("half_thickness_m"), half_thickness_m)?;
            c.non_negative(&key("inner_radius_m"), inner_radius_m)?;
            if count == 0 {
                return Err(c.fail(key("count"), "expected at least 1"));
            }
            // CHOICE: seed 000 shows the axial baffles only in Fig. 23, whose geometry the text does not give.
            // One plate is a bar centred on the axis; several are spokes from inner_radius_m outwards.
            if count == 1 {
                let h = 0.5 * length_m;
                if h >= drum_radius_m {
                    return Err(c.fail(key("length_m"), "the axial bar must fit inside the drum"));
                }
                out.push((0, ([-h, 0.0], [h, 0.0]), half_thickness_m));
            } else {
                if inner_radius_m + length_m >= drum_radius_m {
                    return Err(c.fail(
                        key("length_m"),
                        "inner_radius_m + length_m must be less than the drum radius",
                    ));
                }
                for k in 0..count as usize {
                    let phi = 2.0 * PI * k as f64 / count as f64;
                    let (s, co) = phi.sin_cos();
                    let a = [inner_radius_m * co, inner_radius_m * s];
                    let b = [(inner_radius_m + length_m) * co, (inner_radius_m + length_m) * s];
                    out.push((k, (a, b), half_thickness_m));
                }
            }
        }
        BaffleSpec::Segment {
            start_m,
            end_m,
            half_thickness_m,
        } => {
            c.positive(&key("half_thickness_m"), half_thickness_m)?;
            if !start_m.iter().chain(&end_m).all(|v| v.is_finite()) {
                return Err(c.fail(key("start_m"), "expected finite coordinates"));
            }
            out.push((0, (start_m, end_m), half_thickness_m));
        }
    }
    Ok(out)
}

/// The walls a wall's name in the scenario stands for: the wall of that name and, for a drum or a plane with glued
/// beads, its four bead sub-lattices (the walls [`Wall::glued_to`] it), which are part of it: a heated drum heats
/// through its beads too, and `cohesion_off` for a wall holds for its beads. `None` when no wall has the name.
pub(in crate::scenario) fn walls_named(walls: &[Wall], name: &str) -> Option<Vec<usize>> {
    let own = walls.iter().position(|w| w.name == name)?;
    let beads = walls
        .iter()
        .enumerate()
        .filter(|(_, w)| w.glued_to.as_deref() == Some(name));
    Some(std::iter::once(own).chain(beads.map(|(k, _)| k)).collect())
}

/// The four interleaved sub-lattices of a drum's glued beads, as walls `<drum>_beads_<k parity><j parity>`.
///
/// Seed 000 §3.4 builds its tumbler wall from particles "loaded along a cylindrical geometry": a bumpy wall on
/// which the bed's outer layer cannot roll. A smooth cylinder cannot do this for free-rolling spheres: the outer
/// layer turns like the balls of a bearing, at half the wall's speed, and the bed slides instead of lifting
/// (research/f1-smooth-drum-slip). Each sub-lattice holds every other bead around and along the drum, so a
/// particle touches at most one bead of each when the same-parity beads are at least a bead and a particle radius
/// apart on both sides of it: then every wall keeps one contact history per particle, as the engine requires.
#[allow(clippy::too_many_arguments)]
fn glued_bead_walls(
    c: &Checker,
    spec: &ScenarioSpec,
    domain: &Domain,
    k: usize,
    d: &DrumSpec,
    beads: &GluedBeadsSpec,
    frame: RotatingFrame,
    species: crate::engine::particles::SpeciesId,
) -> Result<Vec<Wall>, ConfigError> {
    let key = |f: &str| format!("walls[{k}].drum.glued_beads.{f}");
    c.positive(&key("radius_m"), beads.radius_m)?;
    c.positive(&key("axial_spacing_m"), beads.axial_spacing_m)?;
    if beads.radius_m >= 0.5 * d.radius_m {
        return Err(c.fail(
            key("radius_m"),
            format!(
                "expected a bead radius below half the drum radius {} m, got {} m",
                d.radius_m, beads.radius_m
            ),
        ));
    }
    if beads.count_around < 4 || !beads.count_around.is_multiple_of(2) {
        return Err(c.fail(
            key("count_around"),
            format!(
                "expected an even number of beads around the drum, at least 4, got {}",
                beads.count_around
            ),
        ));
    }
    let reach_m = beads.radius_m + largest_fill_radius_m(spec);
    let same_parity_around_m = 2.0 * d.radius_m * (2.0 * PI / f64::from(beads.count_around)).sin();
    if same_parity_around_m < 2.0 * reach_m {
        return Err(c.fail(
            key("count_around"),
            format!(
                "{} beads around leave {same_parity_around_m:.6} m between every other bead, less than twice a bead \
                 and the largest particle radius ({:.6} m): use fewer beads (at most {})",
                beads.count_around,
                2.0 * reach_m,
                max_even_count(d.radius_m, reach_m)
            ),
        ));
    }
    if beads.axial_spacing_m < reach_m {
        return Err(c.fail(
            key("axial_spacing_m"),
            format!(
                "expected at least a bead and the largest particle radius ({reach_m} m) between rings, got {} m",
                beads.axial_spacing_m
            ),
        ));
    }
    let axis = Vec3::from(d.axis).normalize();
    check_periodic_spacing(c, domain, axis, beads.axial_spacing_m, &key("axial_spacing_m"), "rings")?;
    Ok((0..4u8)
        .map(|p| {
            Wall::new(
                format!("{}_beads_{}{}", d.name, p / 2, p % 2),
                species,
                WallShape::GluedBeads {
                    frame,
                    radius_m: d.radius_m,
                    bead_radius_m: beads.radius_m,
                    count_around: beads.count_around,
                    axial_spacing_m: beads.axial_spacing_m,
                    parity: [p / 2, p % 2],
                },
            )
            .glued_to(&d.name)
        })
        .collect())
}

/// The most beads around a drum of radius `radius_m` (an even number) whose every other bead is `2 reach_m` apart.
fn max_even_count(radius_m: f64, reach_m: f64) -> u32 {
    let ratio = (reach_m / radius_m).min(1.0);
    let n = (2.0 * PI / ratio.asin()).floor() as u32;
    n - n % 2
}

/// The largest radius of the particles the fills place: a particle may touch only one bead of each sub-lattice.
fn largest_fill_radius_m(spec: &ScenarioSpec) -> f64 {
    spec.fill
        .iter()
        .filter_map(|f| spec.species.iter().find(|s| s.name == f.species()))
        .map(|s| s.radius_m)
        .fold(0.0_f64, f64::max)
}

/// Along a periodic axis a bead lattice must repeat with the domain, an even number of `what` per period so that the
/// sub-lattices keep their parities across the periodic side; a lattice direction must then lie along that axis.
fn check_periodic_spacing(
    c: &Checker,
    domain: &Domain,
    direction: Vec3,
    spacing_m: f64,
    key: &str,
    what: &str,
) -> Result<(), ConfigError> {
    for a in 0..3 {
        if !domain.periodic[a] || direction[a].abs() <= 1e-9 {
            continue;
        }
        let axis_name = ["x", "y", "z"][a];
        if direction[a].abs() < 1.0 - 1e-12 {
            return Err(c.fail(
                key,
                format!("glued beads along a periodic axis ({axis_name}) need their lattice along it or across it"),
            ));
        }
        let period_m = domain.hi_m[a] - domain.lo_m[a];
        let count = period_m / spacing_m;
        if (count - count.round()).abs() > 1e-9 * count || count.round() as i64 % 2 != 0 {
            return Err(c.fail(
                key,
                format!(
                    "expected an even number of {what} in the periodic length {period_m} m along {axis_name}, got \
                     {count} {what} of {spacing_m} m"
                ),
            ));
        }
    }
    Ok(())
}

/// The four interleaved sub-lattices of a plane's glued beads, as walls `<plane>_beads_<i parity><j parity>` (seed
/// 000 §3.2's "particle-roughened walls"; see [`glued_bead_walls`] for why four).
#[allow(clippy::too_many_arguments)]
fn plane_bead_walls(
    c: &Checker,
    spec: &ScenarioSpec,
    domain: &Domain,
    k: usize,
    name: &str,
    point_m: Vec3,
    normal: Vec3,
    beads: &PlaneBeadsSpec,
    species: crate::engine::particles::SpeciesId,
) -> Result<Vec<Wall>, ConfigError> {
    let key = |f: &str| format!("walls[{k}].plane.glued_beads.{f}");
    c.positive(&key("radius_m"), beads.radius_m)?;
    for s in beads.spacing_m {
        c.positive(&key("spacing_m"), s)?;
    }
    let reach_m = beads.radius_m + largest_fill_radius_m(spec);
    if beads.spacing_m.iter().any(|&s| s < reach_m) {
        return Err(c.fail(
            key("spacing_m"),
            format!(
                "expected spacings of at least a bead and the largest particle radius ({reach_m} m), got {:?} m",
                beads.spacing_m
            ),
        ));
    }
    // e1: the first coordinate axis not along the normal, made normal to it; e2 = normal × e1.
    let reference = [Vec3::x(), Vec3::y(), Vec3::z()]
        .into_iter()
        .find(|a| a.dot(&normal).abs() < 0.9)
        .expect("a unit normal is along at most one axis");
    let e1 = (reference - normal * normal.dot(&reference)).normalize();
    let e2 = normal.cross(&e1);
    check_periodic_spacing(c, domain, e1, beads.spacing_m[0], &key("spacing_m"), "beads")?;
    check_periodic_spacing(c, domain, e2, beads.spacing_m[1], &key("spacing_m"), "beads")?;
    Ok((0..4u8)
        .map(|p| {
            Wall::new(
                format!("{name}_beads_{}{}", p / 2, p % 2),
                species,
                WallShape::PlaneBeads {
                    point_m,
                    normal,
                    e1,
                    e2,
                    bead_radius_m: beads.radius_m,
                    spacing_m: beads.spacing_m,
                    parity: [p / 2, p % 2],
                },
            )
            .glued_to(name)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::particles::SpeciesId;

    /// A drum's name stands for the drum and its four bead sub-lattices, not for another wall whose name begins
    /// alike; a plane without beads for itself alone.
    #[test]
    fn a_wall_name_stands_for_the_wall_and_its_glued_beads() {
        let frame = RotatingFrame::new(Vec3::zeros(), Vec3::z(), 1.0);
        let plane = |name: &str| {
            Wall::new(
                name.into(),
                SpeciesId(0),
                WallShape::Plane {
                    point_m: Vec3::zeros(),
                    normal: Vec3::y(),
                },
            )
        };
        let bead = |p: u8| {
            Wall::new(
                format!("drum_beads_{}{}", p / 2, p % 2),
                SpeciesId(0),
                WallShape::GluedBeads {
                    frame,
                    radius_m: 0.1,
                    bead_radius_m: 0.001,
                    count_around: 200,
                    axial_spacing_m: 0.002,
                    parity: [p / 2, p % 2],
                },
            )
            .glued_to("drum")
        };
        let mut walls = vec![
            plane("floor"),
            Wall::new(
                "drum".into(),
                SpeciesId(0),
                WallShape::RotatingCylinder { frame, radius_m: 0.1 },
            ),
        ];
        walls.extend((0..4).map(bead));
        walls.push(plane("drum_beads_lid"));
        walls.push(plane("drum2"));
        assert_eq!(walls_named(&walls, "drum"), Some(vec![1, 2, 3, 4, 5]));
        assert_eq!(walls_named(&walls, "floor"), Some(vec![0]));
        assert_eq!(walls_named(&walls, "drum2"), Some(vec![7]));
        assert_eq!(walls_named(&walls, "drum_beads_01"), Some(vec![3]));
        assert_eq!(walls_named(&walls, "lid"), None);
    }
}
