//! Conduction through the gas between two nearly touching surfaces: the particle–fluid–particle path of Rong &
//! Horio (1999), as MFIX-DEM computes it (its `DES_COND_EQ_PFP`, Zhou, Yu & Zulli 2009), for particle pairs and for
//! a particle beside a wall (a sphere of infinite radius). Not in seed 000's model (which has the gas exchange heat
//! with particles by convection only, eqs. 5.5–5.8); a run switches it on with `heat.gas.lens_conduction`.
//!
//! Heat crosses the gas gap along lines parallel to the line of centres: an annulus of radius r and width dr
//! conducts k_g 2πr dr / g(r), g(r) the gap between the two surfaces there, so
//!
//!   H = k_g ∫_{r_in}^{r_out} 2πr dr / max(g(r), s)                                          (Rong & Horio 1999)
//!
//! - **The region.** A lens of gas of radius (1 + f) R_b round the larger particle (f the lens fraction, MFIX's
//!   `FLPC`, default 0.2): r_out is where the lens meets the smaller particle's surface (law of cosines; capped at
//!   the smaller radius), or where the lens meets the wall; no path where the lens does not reach the partner. r_in
//!   is where the surfaces meet (0 while apart): inside it the solids touch and conduct by [`super::conduction`].
//! - **The smallest gap** s (MFIX's `DES_MIN_COND_DIST`, default 4e-10 m): the surfaces never conduct through less
//!   gas than this (the integral diverges logarithmically at touching surfaces).
//! - **The gap.** g(r) = g₀ + r²/(2R*), the parabola of the two surfaces near the axis (g₀ the surface gap, negative
//!   in overlap; R* = R_i R_j/(R_i + R_j), R_i for a wall): the integral is then closed,
//!   H = 2π R* k_g [(min(u_s, u_out) − u_in)/s + ln((g₀ + u_out)/(g₀ + max(u_in, u_s)))] with u = r²/(2R*),
//!   u_in = max(0, −g₀), u_s = s − g₀ (each term only where its interval is not empty). CHOICE: MFIX integrates the
//!   exact spheres' gap numerically (adaptive Simpson) at every contact and step; the parabola is within 3 % of
//!   that integral for touching and separated pairs of equal and 2:1 radii and for walls (tests below), at one
//!   logarithm a pair.
//! - **Wet pairs.** A liquid bridge's own conduction (`bridge_conduction`) is added beside the lens; the lens does not
//!   give up the part of the gap the liquid fills (CHOICE: the bridge's share of the lens is small for the bridges of
//!   seed 000, V/R³ ≤ 0.05, but the two overlap where the gap is narrowest).

/// The lens's parameters and the gas's conductivity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GasLens {
    /// k_g, W/(m K).
    pub gas_conductivity_w_per_m_k: f64,
    /// f: the lens round the larger particle has radius (1 + f) R_b.
    pub lens_radius_fraction: f64,
    /// s, m: the smallest gap the gas conducts across.
    pub min_gap_m: f64,
}

impl GasLens {
    /// The largest surface gap at which the lens of a particle of radius `largest_radius_m` reaches a partner, m:
    /// f R_b (for pairs and walls alike).
    pub fn reach_m(&self, largest_radius_m: f64) -> f64 {
        self.lens_radius_fraction * largest_radius_m
    }

    /// H of particles of radii `ri`, `rj` whose centres are `centre_distance_m` apart, W/K (0 where the lens of the
    /// larger does not reach the smaller).
    #[inline(always)]
    pub fn pair_conductance_w_per_k(&self, ri: f64, rj: f64, centre_distance_m: f64) -> f64 {
        let (big, small) = if ri >= rj { (ri, rj) } else { (rj, ri) };
        let lens = (1.0 + self.lens_radius_fraction) * big;
        let d = centre_distance_m;
        if d >= lens + small {
            return 0.0;
        }
        // The lens sphere (about the larger centre) and the smaller sphere meet on a circle of radius r_out:
        // its foot on the line of centres is x = (L² − R_s² + d²)/(2d) from the larger centre, r_out² = L² − x².
        let x = (lens * lens - small * small + d * d) / (2.0 * d);
        let r_out2 = (lens * lens - x * x).min(small * small);
        self.conductance(ri * rj / (ri + rj), d - ri - rj, r_out2)
    }

    /// H of a particle of radius `ri` whose surface is `gap_m` from a wall (negative in overlap), W/K.
    #[inline(always)]
    pub fn wall_conductance_w_per_k(&self, ri: f64, gap_m: f64) -> f64 {
        let lens = (1.0 + self.lens_radius_fraction) * ri;
        let h = ri + gap_m;
        if h >= lens {
            return 0.0;
        }
        self.conductance(ri, gap_m, (lens * lens - h * h).min(ri * ri))
    }

    /// The closed integral for effective radius `r_star`, surface gap `g0` and r_out² `r_out2`.
    #[inline(always)]
    fn conductance(&self, r_star: f64, g0: f64, r_out2: f64) -> f64 {
        let s = self.min_gap_m;
        let u_out = r_out2 / (2.0 * r_star);
        let u_in = (-g0).max(0.0);
        if u_out <= u_in {
            return 0.0;
        }
        let u_s = s - g0;
        // Where the gap is below s it counts as s; beyond, the logarithm of the parabola.
        let floored = if u_s > u_in { (u_s.min(u_out) - u_in) / s } else { 0.0 };
        let from = u_in.max(u_s);
        let open = if u_out > from {
            ((g0 + u_out) / (g0 + from)).ln()
        } else {
            0.0
        };
        2.0 * std::f64::consts::PI * r_star * self.gas_conductivity_w_per_m_k * (floored + open)
    }

    /// An upper bound of H for any pair or wall with radii up to `largest_radius_m`, W/K (for the explicit step's
    /// stability): R* ≤ R_b, u_out ≤ R_b, the floored part ≤ 1, g₀ + u_out ≤ R_b.
    pub fn largest_conductance_w_per_k(&self, largest_radius_m: f64) -> f64 {
        2.0 * std::f64::consts::PI
            * largest_radius_m
            * self.gas_conductivity_w_per_m_k
            * (1.0 + (largest_radius_m / self.min_gap_m).ln().max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const AIR: GasLens = GasLens {
        gas_conductivity_w_per_m_k: 0.0261,
        lens_radius_fraction: 0.2,
        min_gap_m: 4e-10,
    };

    /// The integral Rong & Horio and MFIX evaluate, over the exact spheres' gap d − √(R_b² − r²) − √(R_s² − r²)
    /// (or R + g₀ − √(R² − r²) to a wall), by the midpoint rule on r = r_in + (r_out − r_in) t² (dense where the
    /// integrand is steep).
    fn exact_spheres(lens: &GasLens, ri: f64, rj: f64, d: f64, wall: bool) -> f64 {
        let (big, small) = if ri >= rj && !wall { (ri, rj) } else { (rj, ri) };
        let l = (1.0 + lens.lens_radius_fraction) * if wall { ri } else { big };
        let (r_in, r_out) = if wall {
            let h = ri + d;
            let r_in = if d < 0.0 { (ri * ri - h * h).sqrt() } else { 0.0 };
            (r_in, (l * l - h * h).sqrt().min(ri))
        } else {
            let x = (l * l - small * small + d * d) / (2.0 * d);
            let r_in = if d < ri + rj {
                let xb = (big * big - small * small + d * d) / (2.0 * d);
                (big * big - xb * xb).sqrt()
            } else {
                0.0
            };
            (r_in, (l * l - x * x).sqrt().min(small))
        };
        let n = 400_000;
        let mut sum = 0.0;
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            let r = r_in + (r_out - r_in) * t * t;
            let dr = (r_out - r_in) * 2.0 * t / n as f64;
            let gap = if wall {
                ri + d - (ri * ri - r * r).sqrt()
            } else {
                d - (big * big - r * r).sqrt() - (small * small - r * r).sqrt()
            };
            sum += 2.0 * std::f64::consts::PI * r / gap.max(lens.min_gap_m) * dr;
        }
        lens.gas_conductivity_w_per_m_k * sum
    }

    #[test]
    fn the_closed_parabola_is_within_three_per_cent_of_the_exact_spheres_integral() {
        let r = 1.5e-3;
        for lens in [AIR, GasLens { min_gap_m: 1e-7, ..AIR }] {
            for (ri, rj, gap) in [
                (r, r, 0.0),
                (r, r, -1e-6),
                (r, r, 1e-6),
                (r, r, 1e-5),
                (r, r, 1e-4),
                (r, r, 2.5e-4),
                (r, 0.5 * r, 0.0),
                (r, 0.5 * r, 5e-5),
                (r, 2.0 * r, 1e-5),
            ] {
                let d = ri + rj + gap;
                let closed = lens.pair_conductance_w_per_k(ri, rj, d);
                let exact = exact_spheres(&lens, ri, rj, d, false);
                assert!(
                    (closed / exact - 1.0).abs() < 0.03,
                    "R {ri} {rj} gap {gap} s {}: {closed} vs {exact}",
                    lens.min_gap_m
                );
                assert_eq!(closed, lens.pair_conductance_w_per_k(rj, ri, d), "symmetric");
            }
            for gap in [-1e-6, 0.0, 1e-6, 1e-5, 1e-4, 2.5e-4] {
                let closed = lens.wall_conductance_w_per_k(r, gap);
                let exact = exact_spheres(&lens, r, f64::INFINITY, gap, true);
                assert!(
                    (closed / exact - 1.0).abs() < 0.03,
                    "wall gap {gap}: {closed} vs {exact}"
                );
            }
        }
    }

    /// Touching 3 mm beads in air: k_g 2π R* (1 + ln(u_out/s)), u_out = r_out²/(2R*) with r_out² = L² − x²,
    /// x = (L² − R² + 4R²)/(4R) (a hand evaluation: 1.792e-3 W/K); beyond the lens's reach nothing.
    #[test]
    fn touching_beads_conduct_by_the_hand_formula_and_nothing_beyond_the_lens() {
        let r: f64 = 1.5e-3;
        let l = 1.2 * r;
        let x = (l * l + 3.0 * r * r) / (4.0 * r);
        let u_out = (l * l - x * x) / r;
        let hand = 0.0261 * 2.0 * std::f64::consts::PI * 0.5 * r * (1.0 + (u_out / 4e-10).ln());
        let h = AIR.pair_conductance_w_per_k(r, r, 2.0 * r);
        assert!((h / hand - 1.0).abs() < 1e-12, "{h} vs {hand}");
        assert!((h - 1.792e-3).abs() < 1e-6);
        assert_eq!(AIR.pair_conductance_w_per_k(r, r, 2.0 * r + AIR.reach_m(r)), 0.0);
        assert!(AIR.pair_conductance_w_per_k(r, r, 2.0 * r + 0.99 * AIR.reach_m(r)) > 0.0);
        assert_eq!(AIR.wall_conductance_w_per_k(r, AIR.reach_m(r)), 0.0);
        assert!(AIR.wall_conductance_w_per_k(r, 0.99 * AIR.reach_m(r)) > 0.0);
    }

    /// H falls as the gap opens from touching, is continuous through touching (the floored part takes over from the logarithm),
    /// and stays under the stability bound.
    #[test]
    fn conductance_falls_with_the_gap_continuously_and_under_the_bound() {
        let r = 1.5e-3;
        let bound = AIR.largest_conductance_w_per_k(r);
        let mut last = f64::INFINITY;
        for k in 0..=2000 {
            let gap = k as f64 * AIR.reach_m(r) / 2000.0;
            let h = AIR.pair_conductance_w_per_k(r, r, 2.0 * r + gap);
            let hw = AIR.wall_conductance_w_per_k(r, gap);
            assert!(h <= last * (1.0 + 1e-12), "gap {gap}: {h} after {last}");
            assert!(h < bound && hw < bound, "gap {gap}: {h} {hw} vs {bound}");
            last = h;
        }
        let below = AIR.pair_conductance_w_per_k(r, r, 2.0 * r - 1e-15);
        let above = AIR.pair_conductance_w_per_k(r, r, 2.0 * r + 1e-15);
        assert!((below / above - 1.0).abs() < 1e-4, "{below} vs {above}");
    }
}
