//! Walls: planes, the inside of a rotating cylinder (drum, kiln) and baffle plates fixed to a rotating frame.
//!
//! A wall is an infinitely large particle for the contact law (R* = R_i, m* = m_i; LAMMPS/LIGGGHTS do the same),
//! made of a species of its own; a wall of glued beads is a glued particle (R* of the pair, m* = m_i). Each wall reports, for a particle centre, the gap to its surface, the outward unit
//! normal, and the wall's velocity at the contact point. Rotating walls carry an angle that is part of the
//! simulation state (checkpointed); geometry here is otherwise immutable. Seed 000 builds its tumbler walls and
//! baffles from glued particles; `GluedBeads` and `PlaneBeads` build drums and planes that way (a smooth drum lets the
//! bed slide like a bearing: research/f1-smooth-drum-slip), baffles stay smooth plates.

use crate::engine::Vec3;
use crate::engine::particles::SpeciesId;

/// A frame rotating about an axis: e1, e2 span the plane normal to the axis, e2 = axis × e1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotatingFrame {
    pub axis_point_m: Vec3,
    pub axis: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
    pub angular_velocity_rad_per_s: f64,
}

impl RotatingFrame {
    pub fn new(axis_point_m: Vec3, axis: Vec3, angular_velocity_rad_per_s: f64) -> Self {
        let axis = axis.normalize();
        let reference = if axis.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
        let e1 = (reference - axis * axis.dot(&reference)).normalize();
        let e2 = axis.cross(&e1);
        RotatingFrame {
            axis_point_m,
            axis,
            e1,
            e2,
            angular_velocity_rad_per_s,
        }
    }

    /// Velocity of the rigid rotation at world point `p`: Ω a × (p − c).
    #[inline]
    pub fn velocity_at(&self, p: &Vec3) -> Vec3 {
        (self.axis * self.angular_velocity_rad_per_s).cross(&(p - self.axis_point_m))
    }

    /// In-plane coordinates (u, v) of world point `p` in the frame turned by an angle whose (sine, cosine) is
    /// `turn` (`angle.sin_cos()`, computed once per proximity).
    #[inline]
    fn body_coordinates(&self, p: &Vec3, (s, c): (f64, f64)) -> (f64, f64) {
        let r = p - self.axis_point_m;
        let (u, v) = (r.dot(&self.e1), r.dot(&self.e2));
        (u * c + v * s, -u * s + v * c)
    }

    /// World vector of in-plane body vector (du, dv) in the frame turned by the angle whose (sine, cosine) is `turn`.
    #[inline]
    fn world_vector(&self, du: f64, dv: f64, (s, c): (f64, f64)) -> Vec3 {
        self.e1 * (du * c - dv * s) + self.e2 * (du * s + dv * c)
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallShape {
    /// Infinite plane through `point_m` with unit `normal` pointing into the particle side.
    Plane { point_m: Vec3, normal: Vec3 },
    /// Inside surface of a cylinder of radius `radius_m` rotating with `frame`.
    RotatingCylinder { frame: RotatingFrame, radius_m: f64 },
    /// A plate of half-thickness `half_thickness_m` whose mid-section is the segment `start`–`end` (in-plane body
    /// coordinates of `frame`, m), extruded along the axis, turning with `frame`.
    Baffle {
        frame: RotatingFrame,
        start_m: [f64; 2],
        end_m: [f64; 2],
        half_thickness_m: f64,
    },
    /// One of four interleaved sub-lattices of spheres (radius `bead_radius_m`) glued to the inside of a cylinder of
    /// radius `radius_m` turning with `frame`: centres on the cylinder at body angles 2πk/`count_around` and at
    /// j·`axial_spacing_m` along the axis from the axis point, for k ≡ `parity[0]` and j ≡ `parity[1]` (mod 2).
    /// A particle sees the nearest bead of the sub-lattice; the scenario keeps same-parity beads far enough apart
    /// that it never touches two (seed 000 §3.4's wall of glued particles).
    GluedBeads {
        frame: RotatingFrame,
        radius_m: f64,
        bead_radius_m: f64,
        count_around: u32,
        axial_spacing_m: f64,
        parity: [u8; 2],
    },
    /// One of four interleaved sub-lattices of spheres (radius `bead_radius_m`) glued to a static plane: centres at
    /// `point_m + i·spacing_m[0]·e1 + j·spacing_m[1]·e2` for i ≡ `parity[0]`, j ≡ `parity[1]` (mod 2); e1, e2 unit
    /// vectors in the plane. `normal` points to the particle side (seed 000 §3.2's particle-roughened walls).
    PlaneBeads {
        point_m: Vec3,
        normal: Vec3,
        e1: Vec3,
        e2: Vec3,
        bead_radius_m: f64,
        spacing_m: [f64; 2],
        parity: [u8; 2],
    },
}

/// The (sine, cosine) of each wall's turn angle, for [`Wall::proximity_turned`].
pub fn turns(wall_angle_rad: &[f64]) -> Vec<(f64, f64)> {
    wall_angle_rad.iter().map(|a| a.sin_cos()).collect()
}

/// The angle between neighbouring beads around a drum of `count_around`, rad.
#[inline]
fn bead_step_rad(count_around: u32) -> f64 {
    2.0 * std::f64::consts::PI / f64::from(count_around)
}

/// The integer nearest to `t` whose parity is `parity` (0 even, 1 odd), as a float.
#[inline]
fn nearest_with_parity(t: f64, parity: u8) -> f64 {
    let p = f64::from(parity);
    2.0 * ((t - p) * 0.5).round() + p
}

#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    pub name: String,
    pub species: SpeciesId,
    /// Private: `bead_direction` and `baffle_axis_distances_m` are derived from it when the wall is built.
    shape: WallShape,
    /// The name of the wall whose glued beads this wall is (`None` for a wall of its own): a name given for a
    /// drum or plane in the scenario stands for its beads too (heat, cohesion switches, the heated drum's arc).
    pub glued_to: Option<String>,
    /// Glued beads around a drum: the (sine, cosine) of each bead's body angle kΔθ, at index k + `BEAD_INDEX_OFFSET`
    /// (k from −count/2 − 1 to count/2 + 1), computed once as [`Wall::proximity_turned`] would compute them per call
    /// (the same bits); empty for other shapes.
    bead_direction: Vec<(f64, f64)>,
    /// A baffle's mid-section's nearest and farthest distances from the axis (`segment_axis_distances_m`), m,
    /// computed once for [`Wall::gap_lower_bound_m`]; (0, 0) for other shapes.
    baffle_axis_distances_m: (f64, f64),
}

/// The offset of k = 0 in [`Wall`]'s bead direction table, beyond the count/2 that k can reach.
const BEAD_INDEX_OFFSET: i64 = 2;

/// A particle touching (or near) a wall.
#[derive(Debug, Clone, Copy)]
pub struct WallProximity {
    /// Distance from the particle centre to the wall surface (negative if the centre is behind it).
    pub gap_m: f64,
    /// Unit normal from the wall to the particle centre.
    pub normal: Vec3,
    /// The wall's velocity at the contact point.
    pub wall_velocity: Vec3,
    /// The wall's angular velocity vector (zero for static walls).
    pub wall_angular_velocity: Vec3,
}

impl Wall {
    /// A wall of `shape` called `name`, made of `species`.
    pub fn new(name: String, species: SpeciesId, shape: WallShape) -> Self {
        let bead_direction = match shape {
            WallShape::GluedBeads { count_around, .. } => {
                let step_rad = bead_step_rad(count_around);
                let half = i64::from(count_around / 2) + BEAD_INDEX_OFFSET;
                (-half..=half).map(|k| (k as f64 * step_rad).sin_cos()).collect()
            }
            _ => Vec::new(),
        };
        let baffle_axis_distances_m = match &shape {
            WallShape::Baffle { start_m, end_m, .. } => segment_axis_distances_m(start_m, end_m),
            _ => (0.0, 0.0),
        };
        Wall {
            name,
            species,
            shape,
            glued_to: None,
            bead_direction,
            baffle_axis_distances_m,
        }
    }

    /// The wall's geometry and motion, as built.
    pub fn shape(&self) -> &WallShape {
        &self.shape
    }

    /// This wall as glued beads of the wall called `parent`.
    pub fn glued_to(self, parent: &str) -> Self {
        Wall {
            glued_to: Some(parent.to_string()),
            ..self
        }
    }

    /// A static plane whose normal is along z: in pseudo-2-D runs (no motion along z) a particle's gap to it never
    /// changes.
    pub fn is_plane_normal_to_z(&self) -> bool {
        matches!(self.shape, WallShape::Plane { normal, .. } if normal.x == 0.0 && normal.y == 0.0)
    }

    /// A static plane (not a drum or a baffle).
    pub fn is_plane(&self) -> bool {
        matches!(self.shape, WallShape::Plane { .. })
    }

    /// The contact law's effective radius R* for a particle of radius `particle_radius_m` touching this wall: the
    /// particle's own against a smooth surface (a partner of infinite radius), R_i R_b / (R_i + R_b) against a glued
    /// bead of radius R_b, as against a particle of that size (seed 000 §3.4 builds the wall from particles). The
    /// partner's mass stays infinite either way: the bead is glued.
    #[inline]
    pub fn contact_radius_m(&self, particle_radius_m: f64) -> f64 {
        match self.bead_radius_m() {
            Some(bead_radius_m) => particle_radius_m * bead_radius_m / (particle_radius_m + bead_radius_m),
            None => particle_radius_m,
        }
    }

    /// The radius of the wall's glued beads, or `None` for a smooth wall.
    #[inline]
    pub fn bead_radius_m(&self) -> Option<f64> {
        match self.shape {
            WallShape::GluedBeads { bead_radius_m, .. } | WallShape::PlaneBeads { bead_radius_m, .. } => {
                Some(bead_radius_m)
            }
            WallShape::Plane { .. } | WallShape::RotatingCylinder { .. } | WallShape::Baffle { .. } => None,
        }
    }

    /// Angular velocity of the wall's rotation (0 for static walls).
    pub fn angular_velocity_rad_per_s(&self) -> f64 {
        match &self.shape {
            WallShape::Plane { .. } | WallShape::PlaneBeads { .. } => 0.0,
            WallShape::RotatingCylinder { frame, .. }
            | WallShape::Baffle { frame, .. }
            | WallShape::GluedBeads { frame, .. } => frame.angular_velocity_rad_per_s,
        }
    }

    /// Largest distance any surface point can move per radian of rotation (for the neighbour-list skin check).
    pub fn max_lever_m(&self) -> f64 {
        match &self.shape {
            // A cylinder's surface moves only tangentially to itself: its gap to any point never changes.
            WallShape::Plane { .. } | WallShape::RotatingCylinder { .. } | WallShape::PlaneBeads { .. } => 0.0,
            // The farthest point of the mid-section (an end) plus half the plate's thickness.
            WallShape::Baffle { half_thickness_m, .. } => self.baffle_axis_distances_m.1 + half_thickness_m,
            WallShape::GluedBeads {
                radius_m,
                bead_radius_m,
                ..
            } => radius_m + bead_radius_m,
        }
    }

    /// A lower bound of [`Wall::proximity`]'s gap at `x` whatever the wall's turn, from the distance to the axis
    /// alone: a glued bead's centre lies on the cylinder of radius `radius_m`, and every point of a baffle's
    /// mid-section between its nearest and farthest distances from the axis, so a particle at distance ρ from the
    /// axis is at least |ρ − radius| (beads) or max(0, nearest − ρ, ρ − farthest) (baffles) from them. Less a
    /// rounding allowance of 1e-9 of the lengths involved, so that it never exceeds the gap `proximity` computes.
    /// The neighbour build uses it to skip the exact gap (an `atan2` per bead wall) for the bed's interior, which
    /// changes no decision. Shapes whose exact gap is as cheap give −∞.
    #[inline]
    pub fn gap_lower_bound_m(&self, x: &Vec3) -> f64 {
        let axis_distance_m = |frame: &RotatingFrame| {
            let r = x - frame.axis_point_m;
            (r - frame.axis * r.dot(&frame.axis)).norm()
        };
        match &self.shape {
            WallShape::Plane { .. } | WallShape::RotatingCylinder { .. } | WallShape::PlaneBeads { .. } => {
                f64::NEG_INFINITY
            }
            WallShape::GluedBeads {
                frame,
                radius_m,
                bead_radius_m,
                ..
            } => {
                let rho = axis_distance_m(frame);
                (rho - radius_m).abs() - bead_radius_m - 1e-9 * (rho + radius_m)
            }
            WallShape::Baffle {
                frame,
                half_thickness_m,
                ..
            } => {
                let rho = axis_distance_m(frame);
                let (nearest_m, farthest_m) = self.baffle_axis_distances_m;
                (nearest_m - rho).max(rho - farthest_m).max(0.0) - half_thickness_m - 1e-9 * (rho + farthest_m)
            }
        }
    }

    /// Gap, normal and wall velocity for a particle centre at `x` when the wall has turned by `angle_rad`.
    #[inline]
    pub fn proximity(&self, x: &Vec3, angle_rad: f64) -> WallProximity {
        self.proximity_turned(x, angle_rad.sin_cos())
    }

    /// [`Wall::proximity`] with the turn angle's (sine, cosine) `turn` given: the passes over all particles take it
    /// once per wall and step (`angle_rad.sin_cos()`, the same bits) instead of once per particle.
    #[inline]
    pub fn proximity_turned(&self, x: &Vec3, turn: (f64, f64)) -> WallProximity {
        match &self.shape {
            WallShape::Plane { point_m, normal } => WallProximity {
                gap_m: (x - point_m).dot(normal),
                normal: *normal,
                wall_velocity: Vec3::zeros(),
                wall_angular_velocity: Vec3::zeros(),
            },
            WallShape::RotatingCylinder { frame, radius_m } => {
                let r = x - frame.axis_point_m;
                let radial = r - frame.axis * r.dot(&frame.axis);
                let rho = radial.norm();
                let outward = if rho > 0.0 { radial / rho } else { frame.e1 };
                let contact_point = frame.axis_point_m + frame.axis * r.dot(&frame.axis) + outward * *radius_m;
                WallProximity {
                    gap_m: radius_m - rho,
                    normal: -outward,
                    wall_velocity: frame.velocity_at(&contact_point),
                    wall_angular_velocity: frame.axis * frame.angular_velocity_rad_per_s,
                }
            }
            WallShape::Baffle {
                frame,
                start_m,
                end_m,
                half_thickness_m,
            } => {
                let (u, v) = frame.body_coordinates(x, turn);
                let (su, sv) = (end_m[0] - start_m[0], end_m[1] - start_m[1]);
                let len2 = su * su + sv * sv;
                let t = if len2 > 0.0 {
                    (((u - start_m[0]) * su + (v - start_m[1]) * sv) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (du, dv) = (u - start_m[0] - t * su, v - start_m[1] - t * sv);
                let dist = (du * du + dv * dv).sqrt();
                let normal = if dist > 0.0 {
                    frame.world_vector(du / dist, dv / dist, turn)
                } else {
                    frame.world_vector(-sv, su, turn).normalize()
                };
                let contact_point = x - normal * (dist - half_thickness_m);
                WallProximity {
                    gap_m: dist - half_thickness_m,
                    normal,
                    wall_velocity: frame.velocity_at(&contact_point),
                    wall_angular_velocity: frame.axis * frame.angular_velocity_rad_per_s,
                }
            }
            WallShape::PlaneBeads {
                point_m,
                normal,
                e1,
                e2,
                bead_radius_m,
                spacing_m,
                parity,
            } => {
                let r = x - point_m;
                let i = nearest_with_parity(r.dot(e1) / spacing_m[0], parity[0]);
                let j = nearest_with_parity(r.dot(e2) / spacing_m[1], parity[1]);
                let centre = point_m + e1 * (i * spacing_m[0]) + e2 * (j * spacing_m[1]);
                let d = x - centre;
                let dist = d.norm();
                WallProximity {
                    gap_m: dist - bead_radius_m,
                    normal: if dist > 0.0 { d / dist } else { *normal },
                    wall_velocity: Vec3::zeros(),
                    wall_angular_velocity: Vec3::zeros(),
                }
            }
            WallShape::GluedBeads {
                frame,
                radius_m,
                bead_radius_m,
                count_around,
                axial_spacing_m,
                parity,
            } => {
                let (u, v) = frame.body_coordinates(x, turn);
                let step_rad = bead_step_rad(*count_around);
                let k = nearest_with_parity(v.atan2(u) / step_rad, parity[0]);
                let axial_m = (x - frame.axis_point_m).dot(&frame.axis);
                let ring_m = nearest_with_parity(axial_m / axial_spacing_m, parity[1]) * axial_spacing_m;
                // (sin, cos) of kΔθ: |k| ≤ count/2 + 1 since atan2 is within ±π.
                let (s, co) =
                    self.bead_direction[(k as i64 + i64::from(*count_around / 2) + BEAD_INDEX_OFFSET) as usize];
                let centre =
                    frame.axis_point_m + frame.axis * ring_m + frame.world_vector(radius_m * co, radius_m * s, turn);
                let d = x - centre;
                let dist = d.norm();
                // A centre on the bead's own centre: push it inwards, towards the axis.
                let normal = if dist > 0.0 {
                    d / dist
                } else {
                    -frame.world_vector(co, s, turn)
                };
                let contact_point = centre + normal * *bead_radius_m;
                WallProximity {
                    gap_m: dist - bead_radius_m,
                    normal,
                    wall_velocity: frame.velocity_at(&contact_point),
                    wall_angular_velocity: frame.axis * frame.angular_velocity_rad_per_s,
                }
            }
        }
    }
}

/// The nearest and farthest distances from the origin of the segment `start`–`end` (in-plane coordinates, m).
fn segment_axis_distances_m(start_m: &[f64; 2], end_m: &[f64; 2]) -> (f64, f64) {
    let (su, sv) = (end_m[0] - start_m[0], end_m[1] - start_m[1]);
    let len2 = su * su + sv * sv;
    let t = if len2 > 0.0 {
        (-(start_m[0] * su + start_m[1] * sv) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let nearest = (start_m[0] + t * su).hypot(start_m[1] + t * sv);
    let farthest = start_m[0].hypot(start_m[1]).max(end_m[0].hypot(end_m[1]));
    (nearest, farthest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_gap_normal_and_surface_velocity() {
        let frame = RotatingFrame::new(Vec3::zeros(), Vec3::z(), 2.0);
        let wall = Wall::new(
            "drum".into(),
            SpeciesId(0),
            WallShape::RotatingCylinder { frame, radius_m: 1.0 },
        );
        let p = wall.proximity(&Vec3::new(0.0, -0.9, 0.3), 0.0);
        assert!((p.gap_m - 0.1).abs() < 1e-12);
        assert!((p.normal - Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
        // Ω ẑ × (0, −1, 0.3) = (2, 0, 0): the bottom moves towards +x for counter-clockwise rotation.
        assert!((p.wall_velocity - Vec3::new(2.0, 0.0, 0.0)).norm() < 1e-12);
    }

    /// A glued bead is a particle for the contact law's R* (R_i R_b / (R_i + R_b)); a smooth wall an infinite one.
    #[test]
    fn a_glued_bead_contact_takes_the_pair_radius() {
        let plane = |bead_radius_m: Option<f64>| {
            Wall::new(
                "floor".into(),
                SpeciesId(0),
                match bead_radius_m {
                    Some(bead_radius_m) => WallShape::PlaneBeads {
                        point_m: Vec3::zeros(),
                        normal: Vec3::z(),
                        e1: Vec3::x(),
                        e2: Vec3::y(),
                        bead_radius_m,
                        spacing_m: [0.1, 0.1],
                        parity: [0, 0],
                    },
                    None => WallShape::Plane {
                        point_m: Vec3::zeros(),
                        normal: Vec3::z(),
                    },
                },
            )
        };
        assert_eq!(plane(None).contact_radius_m(0.002), 0.002);
        assert!((plane(Some(0.002)).contact_radius_m(0.002) - 0.001).abs() < 1e-15);
        assert!((plane(Some(0.001)).contact_radius_m(0.002) - 0.002 / 3.0).abs() < 1e-15);
    }

    /// Every direction around the drum, ±π included, at any turn: each sub-lattice's gap is the distance to its
    /// nearest bead found by trying them all (the bead direction table covers every index the lookup can reach).
    #[test]
    fn glued_bead_gaps_all_the_way_round_match_a_search_of_every_bead() {
        for count_around in [8u32, 36, 90] {
            let frame = RotatingFrame::new(Vec3::zeros(), Vec3::z(), 1.0);
            let step = 2.0 * std::f64::consts::PI / f64::from(count_around);
            for parity in 0..2u8 {
                let wall = Wall::new(
                    "beads".into(),
                    SpeciesId(0),
                    WallShape::GluedBeads {
                        frame,
                        radius_m: 1.0,
                        bead_radius_m: 0.01,
                        count_around,
                        axial_spacing_m: 0.5,
                        parity: [parity, 0],
                    },
                );
                for angle_rad in [0.0, 0.3, -2.0, std::f64::consts::PI] {
                    let mut directions: Vec<f64> =
                        (0..720).map(|n| f64::from(n) * std::f64::consts::PI / 360.0).collect();
                    directions.extend([std::f64::consts::PI - angle_rad, -std::f64::consts::PI - angle_rad]);
                    for phi in directions {
                        let x = Vec3::new(0.9 * phi.cos(), 0.9 * phi.sin(), 0.0);
                        let nearest = (0..count_around)
                            .filter(|k| k % 2 == u32::from(parity))
                            .map(|k| {
                                let theta = f64::from(k) * step + angle_rad;
                                (x - Vec3::new(theta.cos(), theta.sin(), 0.0)).norm()
                            })
                            .fold(f64::INFINITY, f64::min);
                        let gap = wall.proximity_turned(&x, angle_rad.sin_cos()).gap_m;
                        assert!(
                            (gap - (nearest - 0.01)).abs() < 1e-12,
                            "{count_around} {parity} {angle_rad} {phi}"
                        );
                    }
                }
            }
        }
    }

    /// The neighbour build's bound never exceeds the exact gap, at any turn, for glued beads and for baffles along
    /// a radius, leaning, and through the axis; and it is the gap itself (within its allowance) straight in front
    /// of a bead, on the baffle's own radius beyond its tip, and far inside a drum's beads.
    #[test]
    fn the_gap_bound_is_below_every_gap_and_tight_where_it_should_be() {
        let frame = RotatingFrame::new(Vec3::new(0.01, -0.02, 0.0), Vec3::z(), 0.7);
        let beads = Wall::new(
            "beads".into(),
            SpeciesId(0),
            WallShape::GluedBeads {
                frame,
                radius_m: 0.1,
                bead_radius_m: 0.0015,
                count_around: 210,
                axial_spacing_m: 0.00315,
                parity: [1, 0],
            },
        );
        let baffle = |start_m: [f64; 2], end_m: [f64; 2]| {
            Wall::new(
                "baffle".into(),
                SpeciesId(0),
                WallShape::Baffle {
                    frame,
                    start_m,
                    end_m,
                    half_thickness_m: 0.0015,
                },
            )
        };
        let walls = [
            beads.clone(),
            baffle([0.1, 0.0], [0.08, 0.0]),
            baffle([0.0, 0.1], [0.014, 0.086]),
            baffle([-0.05, 0.0], [0.05, 0.0]),
            baffle([0.0, 0.0], [0.0, 0.05]),
        ];
        for wall in &walls {
            for angle_rad in [0.0, 0.4, -2.5, std::f64::consts::PI] {
                for i in 0..60 {
                    for j in 0..60 {
                        let x = frame.axis_point_m
                            + Vec3::new(
                                -0.11 + 0.22 * f64::from(i) / 59.0,
                                -0.11 + 0.22 * f64::from(j) / 59.0,
                                0.002,
                            );
                        let gap = wall.proximity(&x, angle_rad).gap_m;
                        let bound = wall.gap_lower_bound_m(&x);
                        assert!(
                            bound <= gap,
                            "{} at {x:?}, turn {angle_rad}: bound {bound} > gap {gap}",
                            wall.name
                        );
                    }
                }
            }
        }
        let along = |angle_rad: f64, rho: f64| {
            frame.axis_point_m + Vec3::new(rho * angle_rad.cos(), rho * angle_rad.sin(), 0.0)
        };
        // Bead k = 1 at turn 0 (parity 1), axial ring 0: straight in front of it, 2 mm inside.
        let x = along(2.0 * std::f64::consts::PI / 210.0, 0.098);
        let (gap, bound) = (beads.proximity(&x, 0.0).gap_m, beads.gap_lower_bound_m(&x));
        assert!(
            gap - bound < 1e-9 && (gap - 0.0005).abs() < 1e-12,
            "gap {gap} bound {bound}"
        );
        assert!((beads.gap_lower_bound_m(&along(1.0, 0.05)) - 0.0485).abs() < 1e-9);
        // The plate from 0.1 to 0.08 along e1, and a point 1 cm further in on its radius: 1 cm − half thickness.
        let x = along(0.0, 0.07);
        let (gap, bound) = (walls[1].proximity(&x, 0.0).gap_m, walls[1].gap_lower_bound_m(&x));
        assert!(
            (gap - 0.0085).abs() < 1e-12 && gap - bound < 1e-9,
            "gap {gap} bound {bound}"
        );
        // Through the axis: no bound inside its reach; beyond it, the distance past its tip.
        assert!(walls[3].gap_lower_bound_m(&along(1.0, 0.03)) < 0.0);
        assert!((walls[3].gap_lower_bound_m(&along(1.0, 0.07)) - 0.0185).abs() < 1e-9);
    }

    /// The four sub-lattices together are the whole bead lattice: the nearest of their beads is the nearest bead,
    /// which turns with the drum and moves at Ω × the contact point.
    #[test]
    fn glued_beads_are_the_nearest_bead_of_each_sub_lattice() {
        let frame = RotatingFrame::new(Vec3::zeros(), Vec3::z(), 2.0);
        let lattice: Vec<Wall> = (0..4u8)
            .map(|p| {
                Wall::new(
                    format!("beads_{p}"),
                    SpeciesId(0),
                    WallShape::GluedBeads {
                        frame,
                        radius_m: 1.0,
                        bead_radius_m: 0.05,
                        count_around: 36,
                        axial_spacing_m: 0.2,
                        parity: [p / 2, p % 2],
                    },
                )
            })
            .collect();
        let step = 2.0 * std::f64::consts::PI / 36.0;
        // Beside bead k = 3 (odd), ring j = 2 (even), at angle 0: 0.1 m inwards and 0.04 m along the axis from its
        // centre.
        let at =
            |k: f64, radial: f64, axial: f64| Vec3::new(radial * (k * step).cos(), radial * (k * step).sin(), axial);
        let x = at(3.0, 0.9, 0.44);
        let gaps: Vec<f64> = lattice.iter().map(|w| w.proximity(&x, 0.0).gap_m).collect();
        let expected = 0.1f64.hypot(0.04) - 0.05;
        assert!((gaps[2] - expected).abs() < 1e-12, "{gaps:?}");
        assert!(gaps.iter().enumerate().all(|(p, &g)| p == 2 || g > gaps[2]));
        let p = lattice[2].proximity(&x, 0.0);
        let contact = x - p.normal * p.gap_m;
        assert!((contact - at(3.0, 1.0, 0.4)).norm() - 0.05 < 1e-12);
        assert!((p.wall_velocity - Vec3::new(-2.0 * contact.y, 2.0 * contact.x, 0.0)).norm() < 1e-12);
        // Turned by one step, bead k = 3 sits where k = 4 sat: a point there sees it again.
        assert!((lattice[2].proximity(&at(4.0, 0.9, 0.44), step).gap_m - expected).abs() < 1e-12);
        // Across the angle ±π and along the axis the lattice continues: bead k = 18 ≡ −18 at angle π.
        let far = Vec3::new(-0.9, 1e-9, -0.4 + 0.04);
        let g = lattice[0].proximity(&far, 0.0).gap_m;
        assert!((g - (0.1f64.hypot(0.04) - 0.05)).abs() < 1e-9, "{g}");
    }

    /// A floor's four sub-lattices: the nearest of their beads is the nearest bead, straight above it the gap is
    /// the height less the bead's radius, and the beads do not move.
    #[test]
    fn plane_beads_are_the_nearest_bead_of_each_sub_lattice() {
        let lattice: Vec<Wall> = (0..4u8)
            .map(|p| {
                Wall::new(
                    format!("floor_beads_{p}"),
                    SpeciesId(0),
                    WallShape::PlaneBeads {
                        point_m: Vec3::new(0.0, 0.1, 0.0),
                        normal: Vec3::y(),
                        e1: Vec3::x(),
                        e2: -Vec3::z(),
                        bead_radius_m: 0.5,
                        spacing_m: [1.0, 2.0],
                        parity: [p / 2, p % 2],
                    },
                )
            })
            .collect();
        // Above bead i = 3 (odd), j = -2 (even: z = +4), 0.3 m off along x, 1.6 m above the plane.
        let x = Vec3::new(3.3, 1.7, 4.0);
        let gaps: Vec<f64> = lattice.iter().map(|w| w.proximity(&x, 0.0).gap_m).collect();
        let expected = 0.3f64.hypot(1.6) - 0.5;
        assert!((gaps[2] - expected).abs() < 1e-12, "{gaps:?}");
        assert!(gaps.iter().enumerate().all(|(p, &g)| p == 2 || g > gaps[2]), "{gaps:?}");
        let p = lattice[2].proximity(&x, 0.0);
        assert!((p.normal - Vec3::new(0.3, 1.6, 0.0).normalize()).norm() < 1e-12);
        assert_eq!(p.wall_velocity, Vec3::zeros());
        assert_eq!(lattice[2].max_lever_m(), 0.0);
    }

    #[test]
    fn baffle_turns_with_its_frame() {
        let frame = RotatingFrame::new(Vec3::zeros(), Vec3::z(), 1.0);
        let wall = Wall::new(
            "b".into(),
            SpeciesId(0),
            WallShape::Baffle {
                frame,
                start_m: [0.5, 0.0],
                end_m: [1.0, 0.0],
                half_thickness_m: 0.01,
            },
        );
        // At angle 0 the plate lies on +x; a point above it at (0.75, 0.1).
        let p0 = wall.proximity(&Vec3::new(0.75, 0.1, 0.0), 0.0);
        assert!((p0.gap_m - 0.09).abs() < 1e-12);
        // After a quarter turn the plate lies on +y; the same distance is now along −x.
        let p1 = wall.proximity(&Vec3::new(-0.1, 0.75, 0.0), std::f64::consts::FRAC_PI_2);
        assert!((p1.gap_m - 0.09).abs() < 1e-12);
        assert!((p1.normal - Vec3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
        // Contact point (−0.01, 0.75): Ω ẑ × r = (−0.75, −0.01).
        assert!((p1.wall_velocity - Vec3::new(-0.75, -0.01, 0.0)).norm() < 1e-9);
    }
}
