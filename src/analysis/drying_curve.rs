//! The drying curve of a wet bed (seed 000 §7.3, Figs. 90–91, 93–94): the moisture content X(t) (liquid over dry
//! solid, kg/kg) and the drying rate −dX/dt, with what a drying engineer reads off them: the times by which half
//! and nine tenths of the liquid have gone, and the constant-rate period (the stretch where the surface is still
//! wet and the rate is set by heat and vapour transport, McCabe, Smith & Harriott ch. 24).
//!
//! CHOICE (the seed reads its constant-rate period off a plot): the constant-rate period is the longest stretch of
//! consecutive series rows over which the drying rate, taken between neighbouring rows, stays positive and within
//! [`RATE_BAND`] of itself (largest over smallest), lasting at least [`MIN_PERIOD_FRACTION`] of the drying time
//! (the start to the time 90 % has gone, or the run's end) and [`MIN_PERIOD_ROWS`] rows; its rate is the fall of X
//! over it divided by its length.

/// Largest over smallest drying rate within a constant-rate period (±13 % about its middle).
pub const RATE_BAND: f64 = 1.3;

/// A constant-rate period spans at least this fraction of the drying time.
pub const MIN_PERIOD_FRACTION: f64 = 0.2;

/// A constant-rate period spans at least this many rows (rates between neighbouring rows: one fewer).
pub const MIN_PERIOD_ROWS: usize = 5;

/// A constant-rate period found in a drying curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantRatePeriod {
    pub from_s: f64,
    pub to_s: f64,
    /// −ΔX/Δt over it, 1/s (kg of liquid per kg of dry solid per second).
    pub rate_per_s: f64,
}

/// The time by which X(t) has fallen to (1 − `fraction`) of its first value, interpolated linearly between rows;
/// `None` if it never does (or the series is empty).
pub fn time_to_fraction_removed(t_s: &[f64], moisture: &[f64], fraction: f64) -> Option<f64> {
    let (&x0, &t0) = (moisture.first()?, t_s.first()?);
    let level = (1.0 - fraction) * x0;
    let mut previous = (t0, x0);
    for (&t, &x) in t_s.iter().zip(moisture) {
        if x <= level {
            let (tp, xp) = previous;
            return Some(if xp > x {
                tp + (xp - level) / (xp - x) * (t - tp)
            } else {
                t
            });
        }
        previous = (t, x);
    }
    None
}

/// The drying curve's constant-rate period (see the module documentation), or `None` when it has none.
pub fn constant_rate_period(t_s: &[f64], moisture: &[f64]) -> Option<ConstantRatePeriod> {
    assert_eq!(t_s.len(), moisture.len(), "constant_rate_period: one moisture per time");
    let n = t_s.len();
    if n < MIN_PERIOD_ROWS {
        return None;
    }
    // Rate between rows k and k + 1.
    let rate: Vec<f64> = (0..n - 1)
        .map(|k| -(moisture[k + 1] - moisture[k]) / (t_s[k + 1] - t_s[k]))
        .collect();
    let end_s = time_to_fraction_removed(t_s, moisture, 0.9).unwrap_or(t_s[n - 1]);
    let drying_time_s = end_s - t_s[0];
    let mut best: Option<(usize, usize)> = None;
    for start in 0..rate.len() {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        let mut end = start;
        while end < rate.len() {
            let r = rate[end];
            if !(r.is_finite() && r > 0.0) || hi.max(r) > RATE_BAND * lo.min(r) {
                break;
            }
            lo = lo.min(r);
            hi = hi.max(r);
            end += 1;
        }
        // Rates start..end cover rows start..=end.
        if end > start {
            let span = t_s[end] - t_s[start];
            if best.is_none_or(|(s, e)| span > t_s[e] - t_s[s]) {
                best = Some((start, end));
            }
        }
    }
    let (start, end) = best?;
    let span = t_s[end] - t_s[start];
    (end - start + 1 >= MIN_PERIOD_ROWS && drying_time_s > 0.0 && span >= MIN_PERIOD_FRACTION * drying_time_s).then(
        || ConstantRatePeriod {
            from_s: t_s[start],
            to_s: t_s[end],
            rate_per_s: (moisture[start] - moisture[end]) / span,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_falling_rate_curve_after_a_constant_rate_is_split_where_the_rate_falls() {
        // X = 1 − 0.1 t for t ≤ 5, then falling exponentially at the same initial rate: 0.5 e^{−0.2 (t − 5)}.
        let t: Vec<f64> = (0..=200).map(|k| 0.1 * k as f64).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&t| {
                if t <= 5.0 {
                    1.0 - 0.1 * t
                } else {
                    0.5 * (-0.2 * (t - 5.0)).exp()
                }
            })
            .collect();
        let period = constant_rate_period(&t, &x).expect("a constant-rate period");
        assert_eq!(period.from_s, 0.0);
        // The exponential's rate 0.1 e^{−0.2 s} stays within 1.3× of 0.1 until s = 5 ln 1.3 = 1.31 s.
        assert!((period.to_s - 6.3).abs() < 0.11, "{period:?}");
        assert!((period.rate_per_s - 0.1).abs() < 0.01, "{period:?}");
        let half = time_to_fraction_removed(&t, &x, 0.5).unwrap();
        assert!((half - 5.0).abs() < 1e-9, "{half}");
        let ninety = time_to_fraction_removed(&t, &x, 0.9).unwrap();
        // 0.5 e^{−0.2 s} = 0.1 at s = 5 ln 5 = 8.047 s; linear between rows 0.1 s apart.
        assert!((ninety - (5.0 + 5.0 * 5f64.ln())).abs() < 1e-3, "{ninety}");
    }

    #[test]
    fn a_purely_exponential_curve_has_no_constant_rate_period() {
        let t: Vec<f64> = (0..=100).map(|k| 0.1 * k as f64).collect();
        let x: Vec<f64> = t.iter().map(|&t| (-0.5 * t).exp()).collect();
        // The rate halves every 1.39 s: any stretch within 1.3× lasts 0.52 s, under a fifth of the 4.6 s to 90 %.
        assert_eq!(constant_rate_period(&t, &x), None);
        assert_eq!(time_to_fraction_removed(&t, &x, 0.999), None);
    }
}
