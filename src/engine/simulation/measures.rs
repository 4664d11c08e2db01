//! What a run's present state measures, read-only: the elastic energy in its contacts, the bed's height, the
//! liquid it holds (each particle's coating gain, the total). Part of [`Simulation`]'s impl, kept apart from the
//! stepping.

use super::Simulation;
use crate::engine::Vec3;
use crate::engine::liquid::total_liquid_m3;

impl Simulation {
    /// The coating mass gain of each particle, m³ of liquid (seed 000 eq. 6.45's distribution): the liquid it holds
    /// now (its film, half of each bridge to another particle, all of each bridge to a wall) less the film its
    /// species started with. Liquid the spray put on a surface particle counts wherever bridges have carried it
    /// since: seed 000 §6.3.2 explains CV_m's fall by the transfer from the sprayed layer to the particles inside.
    pub fn coating_gain_m3(&self) -> Vec<f64> {
        let p = &self.particles;
        let mut held = crate::engine::liquid::held_liquid_m3(&p.liquid_m3, &self.history, &self.work.list);
        for (i, h) in held.iter_mut().enumerate() {
            *h -= self.config.species.get(p.species[i]).liquid_content * p.radius_m[i].powi(3);
        }
        held
    }

    /// Liquid on the particles plus liquid in bridges, m³.
    pub fn total_liquid_m3(&self) -> f64 {
        total_liquid_m3(&self.particles.liquid_m3, &self.history)
    }

    /// Elastic energy stored in the active contacts, J: (8/15) E* √R* δ^{5/2} for Hertzian contacts that have not
    /// yielded, ½ K δ² for the linear spring. Tangential springs are not counted (zero for frictionless runs).
    pub fn elastic_energy_j(&self) -> f64 {
        let c = &self.config;
        let p = &self.particles;
        let potential = |mat: &crate::engine::models::PairMaterial, r_star: f64, overlap: f64| {
            c.contact_law.normal.elastic_energy_j(mat, r_star, overlap)
        };
        let mut e = 0.0;
        for i in 0..p.len() {
            for k in self.work.list.pairs_of(i) {
                let j = self.work.list.partner[k] as usize;
                let d = c.domain.separation(&p.position_m[i], &p.position_m[j]).norm();
                let overlap = p.radius_m[i] + p.radius_m[j] - d;
                if overlap > 0.0 {
                    let r_star = p.radius_m[i] * p.radius_m[j] / (p.radius_m[i] + p.radius_m[j]);
                    e += potential(c.pair_table.get(p.species[i], p.species[j]), r_star, overlap);
                }
            }
            for k in self.work.list.walls_of(i) {
                let w = self.work.list.wall_partner[k] as usize;
                let wall = &c.walls[w];
                let overlap = p.radius_m[i] - wall.proximity(&p.position_m[i], self.wall_angle_rad[w]).gap_m;
                if overlap > 0.0 {
                    e += potential(
                        c.pair_table.get(p.species[i], wall.species),
                        wall.contact_radius_m(p.radius_m[i]),
                        overlap,
                    );
                }
            }
        }
        e
    }

    /// Height of the bed along −g: the highest particle top, and the mean centre height, in m.
    pub fn bed_height_m(&self) -> (f64, f64) {
        let g = self.config.gravity.at(self.time_s);
        let up = if g.norm() > 0.0 { -g.normalize() } else { Vec3::z() };
        let p = &self.particles;
        let mut top = f64::NEG_INFINITY;
        let mut sum = 0.0;
        for i in 0..p.len() {
            let h = p.position_m[i].dot(&up);
            top = top.max(h + p.radius_m[i]);
            sum += h;
        }
        (top, sum / p.len().max(1) as f64)
    }
}
