//! The pair pass's read access to positions, velocities, spins and temperatures: plain slices while nothing writes
//! them ([`Plain`]), cells while the serial loop kicks and drifts particles in place ([`Cells`]). The kernels read
//! through [`Motion`] and compile once per view.

use std::cell::Cell;

use super::super::Vec3;

/// Read access to positions and velocities: plain slices while nothing writes them, cells while a serial loop
/// kicks (and drifts) particles in place.
pub(super) trait Motion {
    fn x(&self, i: usize) -> Vec3;
    fn v(&self, i: usize) -> Vec3;
    fn w(&self, i: usize) -> Vec3;
    /// Temperature, K (a run with heat transfer only).
    fn t(&self, i: usize) -> f64;
}

pub(super) struct Plain<'a> {
    pub(super) x: &'a [Vec3],
    pub(super) v: &'a [Vec3],
    pub(super) w: &'a [Vec3],
    pub(super) t: &'a [f64],
}

impl Motion for Plain<'_> {
    #[inline(always)]
    fn x(&self, i: usize) -> Vec3 {
        self.x[i]
    }
    #[inline(always)]
    fn v(&self, i: usize) -> Vec3 {
        self.v[i]
    }
    #[inline(always)]
    fn w(&self, i: usize) -> Vec3 {
        self.w[i]
    }
    #[inline(always)]
    fn t(&self, i: usize) -> f64 {
        self.t[i]
    }
}

/// Cells over a range of particles starting at `base` (0 for all particles), indexed by global particle index.
pub(super) struct Cells<'a> {
    x: &'a [Cell<Vec3>],
    v: &'a [Cell<Vec3>],
    w: &'a [Cell<Vec3>],
    t: &'a [Cell<f64>],
    base: usize,
}

impl<'a> Cells<'a> {
    pub(super) fn new(x: &'a mut [Vec3], v: &'a mut [Vec3], w: &'a mut [Vec3], t: &'a mut [f64], base: usize) -> Self {
        Cells {
            x: Cell::from_mut(x).as_slice_of_cells(),
            v: Cell::from_mut(v).as_slice_of_cells(),
            w: Cell::from_mut(w).as_slice_of_cells(),
            t: Cell::from_mut(t).as_slice_of_cells(),
            base,
        }
    }

    #[inline(always)]
    pub(super) fn set_t(&self, i: usize, t: f64) {
        self.t[i - self.base].set(t);
    }

    #[inline(always)]
    pub(super) fn set(&self, i: usize, x: Vec3, v: Vec3, w: Vec3) {
        self.x[i - self.base].set(x);
        self.v[i - self.base].set(v);
        self.w[i - self.base].set(w);
    }
}

impl Motion for Cells<'_> {
    #[inline(always)]
    fn x(&self, i: usize) -> Vec3 {
        self.x[i - self.base].get()
    }
    #[inline(always)]
    fn v(&self, i: usize) -> Vec3 {
        self.v[i - self.base].get()
    }
    #[inline(always)]
    fn w(&self, i: usize) -> Vec3 {
        self.w[i - self.base].get()
    }
    #[inline(always)]
    fn t(&self, i: usize) -> f64 {
        self.t[i - self.base].get()
    }
}
