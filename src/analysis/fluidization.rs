//! Minimum fluidization velocity from a sweep of gas velocities, two ways:
//!
//! - **pressure fluctuations** (seed 000 §4.1.2, Figs. 44–45): below u_mf the bed pressure drop is steady; at u_mf
//!   its standard deviation jumps. u_mf is the first velocity above the largest jump of log σ(ΔP) between
//!   neighbouring velocities of the sweep (so its resolution is the sweep's spacing; the velocity below the jump is
//!   reported too);
//! - **sustained fluctuations** (the same signal read as a state): the lowest velocity of the sweep from which σ(ΔP)
//!   stays above [`MOVING_BED_STD_OVER_WEIGHT`] of W/A at every higher velocity. Near the onset a cohesive bed can
//!   be bistable (moving at one velocity, packed again at the next); this reading takes the velocity above the last
//!   return to the packed state, where the largest-jump reading may take an earlier, isolated burst;
//! - **Ergun line** (seed 001 §7, "theoretical" u_mf): a straight line fitted to the mean ΔP of the packed-bed
//!   points (those below the jump) meets the bed-weight line W/A.

/// One job of the sweep: superficial gas velocity, mean and standard deviation of the bed pressure drop, and W/A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPoint {
    pub velocity_m_per_s: f64,
    pub pressure_drop_mean_pa: f64,
    pub pressure_drop_std_pa: f64,
    pub bed_weight_per_area_pa: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinimumFluidization {
    /// First velocity above the jump of σ(ΔP).
    pub from_fluctuations_m_per_s: f64,
    /// The velocity just below the jump.
    pub below_jump_m_per_s: f64,
    /// σ(ΔP) above over σ(ΔP) below the jump.
    pub jump_ratio: f64,
    /// Where the line through the packed-bed points meets W/A (NaN with fewer than two packed points).
    pub from_ergun_line_m_per_s: f64,
    /// The lowest velocity from which the bed keeps moving (σ(ΔP) ≥ 1 % of W/A) at every higher velocity; NaN when
    /// the sweep does not bracket the onset (its slowest point already moving, or its fastest still packed).
    pub from_sustained_fluctuations_m_per_s: f64,
}

/// σ(ΔP) over W/A that tells a moving bed from a packed one. CHOICE: in seed 000's bed (D2, D3) packed beds show
/// σ ≤ 0.1 % of W/A (the gas solver's noise) and moving beds ≥ 1.5 %; 1 % lies in that gap.
pub const MOVING_BED_STD_OVER_WEIGHT: f64 = 0.01;

/// u_mf from the sweep points (any order, at least three finite points; `None` otherwise).
pub fn minimum_fluidization(points: &[SweepPoint]) -> Option<MinimumFluidization> {
    let mut p: Vec<SweepPoint> = points
        .iter()
        .copied()
        .filter(|q| {
            q.velocity_m_per_s.is_finite() && q.pressure_drop_std_pa.is_finite() && q.pressure_drop_mean_pa.is_finite()
        })
        .collect();
    if p.len() < 3 {
        return None;
    }
    p.sort_by(|a, b| a.velocity_m_per_s.total_cmp(&b.velocity_m_per_s));
    let floor = 1e-9
        * p.iter()
            .map(|q| q.pressure_drop_std_pa)
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
    let log_std = |q: &SweepPoint| (q.pressure_drop_std_pa.max(0.0) + floor).ln();
    let (k, jump) = (0..p.len() - 1)
        .map(|k| (k, log_std(&p[k + 1]) - log_std(&p[k])))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let packed = &p[..=k];
    let weight = p.iter().map(|q| q.bed_weight_per_area_pa).sum::<f64>() / p.len() as f64;
    let from_ergun_line_m_per_s = if packed.len() >= 2 {
        let (a, b) = fit_line(
            &packed.iter().map(|q| q.velocity_m_per_s).collect::<Vec<_>>(),
            &packed.iter().map(|q| q.pressure_drop_mean_pa).collect::<Vec<_>>(),
        );
        if a > 0.0 { (weight - b) / a } else { f64::NAN }
    } else {
        f64::NAN
    };
    let moving = |q: &SweepPoint| q.pressure_drop_std_pa >= MOVING_BED_STD_OVER_WEIGHT * q.bed_weight_per_area_pa;
    let still_moving = p.iter().rev().take_while(|q| moving(q)).count();
    let from_sustained_fluctuations_m_per_s = if still_moving == 0 || still_moving == p.len() {
        f64::NAN
    } else {
        p[p.len() - still_moving].velocity_m_per_s
    };
    Some(MinimumFluidization {
        from_sustained_fluctuations_m_per_s,
        from_fluctuations_m_per_s: p[k + 1].velocity_m_per_s,
        below_jump_m_per_s: p[k].velocity_m_per_s,
        jump_ratio: jump.exp(),
        from_ergun_line_m_per_s,
    })
}

/// One level of a defluidization/fluidization cycle: its superficial velocity and time-averaged pressure drop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleLevel {
    pub velocity_m_per_s: f64,
    pub pressure_drop_mean_pa: f64,
}

/// Seed 001's three velocities of one cycle (§6.4.2.1, Fig. 6.9; notes §4): seed 001's cycle first lowers the gas
/// (defluidization branch, down to its slowest level) and then raises it again (fluidization branch); a cycle
/// that rises first and then falls is read on the same two branches ([`cycle_branches`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleVelocities {
    /// U_mf,df: the line through the falling branch's packed-bed points meets W/A.
    pub defluidization_m_per_s: f64,
    /// U_mf,th: the same on the rising branch.
    pub fluidization_theoretical_m_per_s: f64,
    /// U_mf,in: the velocity of the overshoot peak (the largest pressure drop of the rising branch before the bed
    /// gives way), if it exceeds W/A; NaN without an overshoot.
    pub incipient_m_per_s: f64,
    /// The overshoot peak's pressure drop over W/A (above 1: an overshoot).
    pub overshoot_ratio: f64,
    /// Index (into the levels given) of the top of the rising branch's climb, the overshoot peak when above W/A.
    pub peak_level: Option<usize>,
}

/// The packed-bed points of a branch (CHOICE: seed 001 fits "all packed-bed points" without a rule; here the run of
/// levels next to the cycle's slowest level whose ΔP stays below 0.8 W/A, clear of the transition, those with a
/// positive velocity) need at least two for a line. Only the run next to the slowest level counts: a bubbling level
/// whose mean ΔP happens to dip below 0.8 W/A at the top of the cycle is not a packed bed.
const PACKED_FRACTION_OF_WEIGHT: f64 = 0.8;

/// The two branches of a cycle of levels in time order, as index ranges. Seed 001's order, down then up: the
/// falling branch is the run of non-increasing velocities that ends just before the first slowest level, the
/// rising branch the run of non-decreasing velocities from the slowest level on. A cycle that rises first and then
/// falls (a fresh bed fluidized, then defluidized): when it ends at its slowest level, the rising branch is the
/// climb that led into the fall; when it starts at its slowest level, the falling branch is the fall after the
/// climb's top. A branch with fewer than two levels is empty.
pub fn cycle_branches(levels: &[CycleLevel]) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
    let v = |k: usize| levels[k].velocity_m_per_s;
    let slowest = levels
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.velocity_m_per_s.total_cmp(&b.1.velocity_m_per_s))
        .map_or(0, |(k, _)| k);
    if levels.is_empty() {
        return (0..0, 0..0);
    }
    let mut fall_start = slowest;
    while fall_start > 0 && v(fall_start - 1) >= v(fall_start) {
        fall_start -= 1;
    }
    let mut rise_end = slowest + 1;
    while rise_end < levels.len() && v(rise_end) >= v(rise_end - 1) {
        rise_end += 1;
    }
    let rising = if rise_end - slowest >= 2 {
        slowest..rise_end
    } else {
        let mut rise_start = fall_start;
        while rise_start > 0 && v(rise_start - 1) <= v(rise_start) {
            rise_start -= 1;
        }
        rise_start..fall_start + 1
    };
    let falling = if fall_start < slowest {
        fall_start..slowest
    } else {
        // No fall into the slowest level (it is the first): the fall after the rise's top, if any.
        let top = rising.end - 1;
        let mut fall_end = top + 1;
        while fall_end < levels.len() && v(fall_end) <= v(fall_end - 1) {
            fall_end += 1;
        }
        if fall_end - top >= 2 { top..fall_end } else { 0..0 }
    };
    (falling, rising)
}

/// U_mf,df, U_mf,th, U_mf,in and the overshoot from the levels of one cycle in time order, on the branches of
/// [`cycle_branches`].
pub fn cycle_velocities(levels: &[CycleLevel], bed_weight_per_area_pa: f64) -> CycleVelocities {
    let (falling, rising) = cycle_branches(levels);
    let rising_start = rising.start;
    let (falling, rising) = (&levels[falling], &levels[rising]);
    // `towards_top`: the branch's levels from the slowest one outwards.
    let crossing = |towards_top: &mut dyn Iterator<Item = &CycleLevel>| {
        let packed: Vec<&CycleLevel> = towards_top
            .take_while(|l| {
                l.pressure_drop_mean_pa.is_finite()
                    && l.pressure_drop_mean_pa < PACKED_FRACTION_OF_WEIGHT * bed_weight_per_area_pa
            })
            .filter(|l| l.velocity_m_per_s > 0.0)
            .collect();
        if packed.len() < 2 {
            return f64::NAN;
        }
        let (a, b) = fit_line(
            &packed.iter().map(|l| l.velocity_m_per_s).collect::<Vec<_>>(),
            &packed.iter().map(|l| l.pressure_drop_mean_pa).collect::<Vec<_>>(),
        );
        if a > 0.0 {
            (bed_weight_per_area_pa - b) / a
        } else {
            f64::NAN
        }
    };
    let fluidization_theoretical_m_per_s = crossing(&mut rising.iter());
    // Seed 001's overshoot region: the points above W'/A "left of the bubbling region" (notes §4.1). CHOICE: the
    // bubbling region starts at the first level whose mean pressure drop falls below the previous level's, where
    // the bed has given way; the peak is the last level of the climb before it. Level means of a bubbling bed
    // swing by up to 10 % from one level to the next (D8's 0.1 s levels, averaged over 0.05 s), so a window reaching into it
    // would count bubbles as an overshoot.
    let mut climb = rising
        .iter()
        .enumerate()
        .take_while(|(_, l)| l.pressure_drop_mean_pa.is_finite());
    let mut top = climb.next();
    for (k, l) in climb {
        match top {
            Some((_, p)) if l.pressure_drop_mean_pa < p.pressure_drop_mean_pa => break,
            _ => top = Some((k, l)),
        }
    }
    let peak = top.map(|(_, l)| l);
    let overshoot_ratio = peak.map_or(f64::NAN, |l| l.pressure_drop_mean_pa / bed_weight_per_area_pa);
    CycleVelocities {
        defluidization_m_per_s: crossing(&mut falling.iter().rev()),
        fluidization_theoretical_m_per_s,
        incipient_m_per_s: match peak {
            Some(l) if overshoot_ratio > 1.0 => l.velocity_m_per_s,
            _ => f64::NAN,
        },
        overshoot_ratio,
        peak_level: top.map(|(k, _)| rising_start + k),
    }
}

/// Least-squares line y = a x + b (NaN without a spread in x).
fn fit_line(x: &[f64], y: &[f64]) -> (f64, f64) {
    super::fit::fit_line(x, y).map_or((f64::NAN, f64::NAN), |f| (f.slope, f.intercept))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(u: f64, mean: f64, std: f64) -> SweepPoint {
        SweepPoint {
            velocity_m_per_s: u,
            pressure_drop_mean_pa: mean,
            pressure_drop_std_pa: std,
            bed_weight_per_area_pa: 1000.0,
        }
    }

    #[test]
    fn the_jump_and_the_ergun_line_are_found() {
        // Packed: ΔP = 500 u (+ noise-free), σ tiny; fluidized from 2.0 on: ΔP = W/A, σ large.
        let pts = [
            point(2.4, 1000.0, 60.0),
            point(1.0, 500.0, 0.4),
            point(1.5, 750.0, 0.6),
            point(0.5, 250.0, 0.3),
            point(2.0, 1000.0, 50.0),
        ];
        let m = minimum_fluidization(&pts).unwrap();
        assert_eq!(m.from_fluctuations_m_per_s, 2.0);
        assert_eq!(m.below_jump_m_per_s, 1.5);
        assert!((m.jump_ratio / (50.0 / 0.6) - 1.0).abs() < 1e-6, "{}", m.jump_ratio);
        assert!(
            (m.from_ergun_line_m_per_s - 2.0).abs() < 1e-12,
            "{}",
            m.from_ergun_line_m_per_s
        );
    }

    /// A cycle 2 → 0 → 2 m/s with W/A = 1000 Pa: falling packed branch ΔP = 500 u (crossing W/A at 2.0), rising
    /// packed branch ΔP = 600 u (crossing at 1.667) and an overshoot to 1150 Pa at 1.8 m/s.
    fn levels(velocities: &[f64]) -> Vec<CycleLevel> {
        velocities
            .iter()
            .map(|&u| CycleLevel {
                velocity_m_per_s: u,
                pressure_drop_mean_pa: u,
            })
            .collect()
    }

    #[test]
    fn a_cycle_splits_into_its_falling_and_rising_branches_in_either_order() {
        // Seed 001's order: down, then up (the slowest level starts the rising branch).
        assert_eq!(cycle_branches(&levels(&[1.0, 0.5, 0.0, 0.5, 1.0, 1.0])), (0..2, 2..6));
        // Only up (D3's steps): no falling branch.
        assert_eq!(cycle_branches(&levels(&[0.8, 1.0, 1.2])), (0..0, 0..3));
        // Up, then down to below the start: the climb, then the fall from the top.
        assert_eq!(cycle_branches(&levels(&[0.8, 1.0, 1.2, 1.0, 0.6, 0.4])), (2..5, 0..3));
        // Up, then down to above the start.
        assert_eq!(cycle_branches(&levels(&[0.4, 1.0, 1.2, 1.0, 0.6])), (2..5, 0..3));
    }

    #[test]
    fn a_cycle_that_rises_first_reads_the_same_velocities_as_one_that_falls_first() {
        // ΔP = 2u Pa on the packed levels (u < 0.5 m/s), W/A = 1 Pa beyond: both lines meet W/A at 0.5 m/s.
        let cycle = |velocities: &[f64]| -> Vec<CycleLevel> {
            velocities
                .iter()
                .map(|&u| CycleLevel {
                    velocity_m_per_s: u,
                    pressure_drop_mean_pa: (2.0 * u).min(1.0),
                })
                .collect()
        };
        let down_up = cycle_velocities(&cycle(&[1.0, 0.8, 0.3, 0.2, 0.1, 0.0, 0.1, 0.2, 0.3, 0.8, 1.0]), 1.0);
        let up_down = cycle_velocities(&cycle(&[0.1, 0.2, 0.3, 0.8, 1.0, 0.8, 0.3, 0.2, 0.1, 0.0]), 1.0);
        for v in [down_up, up_down] {
            assert!((v.defluidization_m_per_s - 0.5).abs() < 1e-12, "{v:?}");
            assert!((v.fluidization_theoretical_m_per_s - 0.5).abs() < 1e-12, "{v:?}");
        }
        assert_eq!(up_down.peak_level, Some(4), "the climb tops out at 1.0 m/s");
    }

    #[test]
    fn a_cycle_gives_seed_001s_three_velocities() {
        let level = |u: f64, dp: f64| CycleLevel {
            velocity_m_per_s: u,
            pressure_drop_mean_pa: dp,
        };
        // The top level's bubbling bed dips below 0.8 W/A: not a packed-bed point (it is not next to the packed run).
        let mut levels = vec![level(2.4, 700.0), level(2.2, 1000.0), level(2.0, 990.0)];
        for u in [1.4, 1.0, 0.6, 0.2, 0.0] {
            levels.push(level(u, 500.0 * u));
        }
        for u in [0.2, 0.6, 1.0, 1.2] {
            levels.push(level(u, 600.0 * u));
        }
        // The climb peaks at 1.8 m/s and the bed gives way; the bubbling swing at 2.2 m/s after it is not an
        // overshoot.
        levels.extend([level(1.8, 1150.0), level(2.0, 1005.0), level(2.2, 1200.0)]);
        let c = cycle_velocities(&levels, 1000.0);
        assert!((c.defluidization_m_per_s - 2.0).abs() < 1e-12, "{c:?}");
        assert!(
            (c.fluidization_theoretical_m_per_s - 1000.0 / 600.0).abs() < 1e-12,
            "{c:?}"
        );
        assert_eq!(c.incipient_m_per_s, 1.8);
        assert!((c.overshoot_ratio - 1.15).abs() < 1e-12);
        assert_eq!(c.peak_level, Some(12), "the 1.8 m/s level, the 13th");
        // Without an overshoot there is no incipient velocity.
        let flat: Vec<CycleLevel> = levels
            .iter()
            .map(|l| level(l.velocity_m_per_s, l.pressure_drop_mean_pa.min(1000.0)))
            .collect();
        assert!(cycle_velocities(&flat, 1000.0).incipient_m_per_s.is_nan());
        // A dry bed's climb levels off below W/A and the bed gives way; bubbles then swing the level means above
        // W/A: no overshoot, the peak is the climb's top.
        let mut dry = levels[..levels.len() - 3].to_vec();
        dry.extend([
            level(1.6, 985.0),
            level(1.8, 980.0),
            level(2.0, 1050.0),
            level(2.2, 940.0),
        ]);
        let c = cycle_velocities(&dry, 1000.0);
        assert!((c.overshoot_ratio - 0.985).abs() < 1e-12, "{c:?}");
        assert!(c.incipient_m_per_s.is_nan());
        assert_eq!(c.peak_level, Some(12), "the climb's top, 1.6 m/s");
    }

    #[test]
    fn a_bistable_onset_is_read_above_the_last_return_to_the_packed_state() {
        // Seed 000's wet bed at Ca_g = 2 (D3's first run, W/A ≈ 1000 Pa): a burst at 1.45 m/s, packed again at 1.50.
        let pts = [
            point(1.40, 1011.0, 0.465),
            point(1.425, 1009.0, 0.092),
            point(1.45, 977.0, 15.6),
            point(1.475, 999.0, 20.7),
            point(1.50, 959.0, 0.455),
            point(1.525, 976.0, 34.8),
            point(1.55, 1001.0, 21.7),
            point(1.60, 994.0, 83.3),
        ];
        let m = minimum_fluidization(&pts).unwrap();
        assert_eq!(m.from_fluctuations_m_per_s, 1.45, "the largest jump is the first burst");
        assert_eq!(m.from_sustained_fluctuations_m_per_s, 1.525);
        // A sweep that never leaves the packed state, or starts already moving, does not bracket the onset.
        let packed: Vec<SweepPoint> = pts.iter().map(|q| point(q.velocity_m_per_s, 900.0, 0.5)).collect();
        assert!(
            minimum_fluidization(&packed)
                .unwrap()
                .from_sustained_fluctuations_m_per_s
                .is_nan()
        );
        let moving: Vec<SweepPoint> = pts.iter().map(|q| point(q.velocity_m_per_s, 1000.0, 50.0)).collect();
        assert!(
            minimum_fluidization(&moving)
                .unwrap()
                .from_sustained_fluctuations_m_per_s
                .is_nan()
        );
    }

    #[test]
    fn too_few_points_give_none() {
        assert!(minimum_fluidization(&[point(1.0, 1.0, 1.0), point(2.0, 1.0, 2.0)]).is_none());
        let with_nan = [point(1.0, 1.0, 1.0), point(2.0, 1.0, 2.0), point(3.0, f64::NAN, 5.0)];
        assert!(minimum_fluidization(&with_nan).is_none());
    }
}
