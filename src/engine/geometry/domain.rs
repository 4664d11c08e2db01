//! The simulation box, its periodic axes and the minimum-image convention; and gravity, which may vary in time.
//!
//! Non-periodic axes are bounded by walls the scenario declares (a particle leaving the box on such an axis is
//! "lost", a numerical failure); periodic axes wrap positions into [lo, hi).

use serde::{Deserialize, Serialize};

use crate::engine::Vec3;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    pub lo_m: Vec3,
    pub hi_m: Vec3,
    pub periodic: [bool; 3],
    /// Any axis periodic: when false, the separation is a plain difference (the hot loop's fast path).
    any_periodic: bool,
}

impl Domain {
    pub fn new(lo_m: Vec3, hi_m: Vec3, periodic: [bool; 3]) -> Self {
        Domain {
            lo_m,
            hi_m,
            periodic,
            any_periodic: periodic.iter().any(|&p| p),
        }
    }

    pub fn length_m(&self) -> Vec3 {
        self.hi_m - self.lo_m
    }

    /// The separation vector a − b under the minimum-image convention on periodic axes.
    #[inline]
    pub fn separation(&self, a: &Vec3, b: &Vec3) -> Vec3 {
        let mut d = a - b;
        if !self.any_periodic {
            return d;
        }
        for axis in 0..3 {
            if self.periodic[axis] {
                let l = self.hi_m[axis] - self.lo_m[axis];
                if d[axis] > 0.5 * l {
                    d[axis] -= l;
                } else if d[axis] < -0.5 * l {
                    d[axis] += l;
                }
            }
        }
        d
    }

    /// Wraps a position into the box on periodic axes.
    #[inline]
    pub fn wrap(&self, x: &mut Vec3) {
        if !self.any_periodic {
            return;
        }
        for axis in 0..3 {
            if self.periodic[axis] {
                let l = self.hi_m[axis] - self.lo_m[axis];
                if x[axis] >= self.hi_m[axis] {
                    x[axis] -= l;
                } else if x[axis] < self.lo_m[axis] {
                    x[axis] += l;
                }
            }
        }
    }

    /// True when a particle centre lies outside the box on a non-periodic axis by more than `tolerance_m`.
    #[inline]
    pub fn is_lost(&self, x: &Vec3, tolerance_m: f64) -> bool {
        (0..3).any(|axis| {
            !self.periodic[axis] && (x[axis] < self.lo_m[axis] - tolerance_m || x[axis] > self.hi_m[axis] + tolerance_m)
        })
    }
}

/// Axis names for configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// Gravity, optionally with one component flipping sign as a square wave (seed 000 §3.2, the zig-zag chute).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gravity {
    pub vector_m_per_s2: [f64; 3],
    pub flip: Option<GravityFlip>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GravityFlip {
    /// The component that flips sign.
    pub axis: Axis,
    /// Flip frequency f: the component keeps its sign for 1/(2f), then reverses.
    pub frequency_hz: f64,
}

impl Gravity {
    /// Gravity at time `time_s`.
    pub fn at(&self, time_s: f64) -> Vec3 {
        let mut g = Vec3::from(self.vector_m_per_s2);
        if let Some(flip) = self.flip {
            let half_periods = (2.0 * flip.frequency_hz * time_s).floor() as i64;
            if half_periods.rem_euclid(2) == 1 {
                g[flip.axis.index()] = -g[flip.axis.index()];
            }
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_image_on_periodic_axis_only() {
        let d = Domain::new(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [true, false, false]);
        let s = d.separation(&Vec3::new(0.95, 0.9, 0.0), &Vec3::new(0.05, 0.1, 0.0));
        assert!((s.x + 0.1).abs() < 1e-12 && (s.y - 0.8).abs() < 1e-12);
    }

    #[test]
    fn gravity_flips_every_half_period() {
        let g = Gravity {
            vector_m_per_s2: [1.0, -2.0, 0.0],
            flip: Some(GravityFlip {
                axis: Axis::Y,
                frequency_hz: 2.0,
            }),
        };
        assert_eq!(g.at(0.1).y, -2.0);
        assert_eq!(g.at(0.3).y, 2.0);
        assert_eq!(g.at(0.6).y, -2.0);
        assert_eq!(g.at(0.3).x, 1.0);
    }
}
