//! Reductions of a metric's time series: the exponential mixing-rate fit, the time to a fraction of the maximum, and
//! a least-squares line with its intercept's standard error (seed 000 §6.3.2's CV_m against 1/√t).
//!
//! Seed 000 §4.1.3 extracts "a mixing rate constant" by "fitting [the IS(t)] data to an exponential function"
//! (Fig. 50), and §2.5.2 / Table 1 report the time at which the Lacey index first reaches 90 % of its maximum. Both
//! are here, as plain functions of sampled (t, y) with no knowledge of what y is.
//!
//! Not here: computing IS or Lacey at one instant (`super::mixing`), and any smoothing of noisy series.

/// y(t) = offset + amplitude · exp(−rate_constant · (t − reference_time)), fitted by least squares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialFit {
    /// k, 1/s: the mixing rate constant of seed 000 §4.1.3 when y is IS(t).
    pub rate_constant_per_s: f64,
    /// y(reference time) − y(∞); negative for a rising approach (a Lacey index climbing to its plateau).
    pub amplitude: f64,
    /// y(∞), the asymptote (for IS: the level of the mixed state, not 0 with finite samples).
    pub offset: f64,
    /// 1 − SSE/SST of the fit.
    pub r_squared: f64,
    /// The earliest sample time, at which `amplitude` is measured; 0 for a series that starts at t = 0, where
    /// amplitude = y_0 − y_∞.
    pub reference_time_s: f64,
}

impl ExponentialFit {
    /// The fitted curve at `t_s`.
    pub fn value_at(&self, t_s: f64) -> f64 {
        self.offset + self.amplitude * (-self.rate_constant_per_s * (t_s - self.reference_time_s)).exp()
    }

    /// 1/k, s.
    pub fn time_constant_s(&self) -> f64 {
        1.0 / self.rate_constant_per_s
    }
}

/// Grid points in ln k before the Brent refinement.
const RATE_GRID_POINTS: usize = 241;
/// Smallest rate searched, times the span of the series: a decay by less than 0.1 % over the record is a line.
const RATE_MIN_TIMES_SPAN: f64 = 1e-3;
/// Largest rate searched, times the smallest sample spacing: by exp(−30) the decay is over before the second sample.
const RATE_MAX_TIMES_SPACING: f64 = 30.0;

/// Least-squares fit of y = y_∞ + (y_0 − y_∞)·exp(−k (t − t_0)) to samples (t_s, y), t_0 the earliest time.
///
/// CHOICE: seed 000 §4.1.3 names no form beyond "an exponential function". IS decays from 0.5 towards the level of
/// the mixed state (about √(P(1−P)/(k+1)) with samples of k+1 particles, not 0), so the form has a free offset; a
/// pure exp(−kt) would bend k to reach zero. The same form fits a rising approach (amplitude < 0).
///
/// Method: variable projection. For each trial k the model is linear in (offset, amplitude), which are solved in
/// closed form; the remaining one-dimensional residual SSE(k) is scanned on a logarithmic grid from 10⁻³/span to
/// 30/(smallest spacing), then refined by Brent's method in ln k around the best grid point. The grid makes the
/// search robust to a poor start; the closed-form inner solve makes it exact in the linear parameters.
///
/// Returns `None` if fewer than 4 finite samples or fewer than 3 distinct times remain (three parameters and a
/// check), if the series is constant, or if there is no decay to measure: the best k lies at either end of the
/// search (a straight line or exponential growth, k → 0; a step completed before the second sample, k → ∞).
/// Samples with a non-finite t or y are ignored; times need not be sorted. A noisy series with no trend may still
/// give a fit; judge it by `r_squared`.
///
/// # Panics
/// If the slices differ in length.
pub fn fit_exponential_decay(t_s: &[f64], y: &[f64]) -> Option<ExponentialFit> {
    fit(t_s, y, None)
}

/// [`fit_exponential_decay`] with the asymptote fixed at `offset`: y = offset + amplitude·exp(−k (t − t_0)). For
/// IS(t) with the offset at the random mixture's level √(P(1−P)/n) (n particles per local sample), k measures
/// the approach to a random mixture, and a bed that stalls above it (cohesive agglomerates) gets a small k where
/// the free-offset fit would report how fast it reached its own plateau.
pub fn fit_exponential_decay_to(t_s: &[f64], y: &[f64], offset: f64) -> Option<ExponentialFit> {
    fit(t_s, y, Some(offset))
}

fn fit(t_s: &[f64], y: &[f64], fixed_offset: Option<f64>) -> Option<ExponentialFit> {
    assert_eq!(t_s.len(), y.len(), "fit_exponential_decay: one y per time");
    let (t, y): (Vec<f64>, Vec<f64>) = t_s
        .iter()
        .zip(y)
        .filter(|(t, y)| t.is_finite() && y.is_finite())
        .map(|(&t, &y)| (t, y))
        .unzip();
    if t.len() < 4 {
        return None;
    }
    let mut sorted = t.clone();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    if sorted.len() < 3 {
        return None;
    }
    let t0_s = sorted[0];
    let span_s = sorted[sorted.len() - 1] - t0_s;
    let spacing_s = sorted.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
    let tau_s: Vec<f64> = t.iter().map(|&t| t - t0_s).collect();

    let mean_y = y.iter().sum::<f64>() / y.len() as f64;
    let sst = y.iter().map(|v| (v - mean_y) * (v - mean_y)).sum::<f64>();
    if sst.is_nan() || sst <= 0.0 {
        return None;
    }

    let ln_k_lo = (RATE_MIN_TIMES_SPAN / span_s).ln();
    let ln_k_hi = (RATE_MAX_TIMES_SPACING / spacing_s).ln();
    if !(ln_k_lo.is_finite() && ln_k_hi.is_finite() && ln_k_hi > ln_k_lo) {
        return None;
    }
    let linear = |k_per_s: f64| match fixed_offset {
        None => linear_part(&tau_s, &y, k_per_s),
        Some(offset) => amplitude_part(&tau_s, &y, k_per_s, offset),
    };
    let sse = |ln_k: f64| linear(ln_k.exp()).2;
    let step = (ln_k_hi - ln_k_lo) / (RATE_GRID_POINTS - 1) as f64;
    let grid: Vec<f64> = (0..RATE_GRID_POINTS).map(|i| sse(ln_k_lo + step * i as f64)).collect();
    let best = (0..RATE_GRID_POINTS)
        .min_by(|&a, &b| grid[a].total_cmp(&grid[b]))
        .expect("the grid is not empty");
    if best == 0 || best == RATE_GRID_POINTS - 1 {
        return None;
    }
    let ln_k = brent_minimum(
        sse,
        ln_k_lo + step * (best - 1) as f64,
        ln_k_lo + step * (best + 1) as f64,
        1e-12,
    );
    let k_per_s = ln_k.exp();
    let (offset, amplitude, sse_min) = linear(k_per_s);
    if !(amplitude != 0.0 && offset.is_finite() && amplitude.is_finite()) {
        return None;
    }
    Some(ExponentialFit {
        rate_constant_per_s: k_per_s,
        amplitude,
        offset,
        r_squared: 1.0 - sse_min / sst,
        reference_time_s: t0_s,
    })
}

/// For a fixed rate, the least-squares (offset, amplitude) of y ≈ offset + amplitude·exp(−k τ) and its SSE.
///
/// Centred normal equations: amplitude = Σ(e − ē)(y − ȳ)/Σ(e − ē)², offset = ȳ − amplitude·ē. When the basis
/// function is numerically constant over the samples (k far too small or too large) the fit is the mean alone.
fn linear_part(tau_s: &[f64], y: &[f64], k_per_s: f64) -> (f64, f64, f64) {
    let n = y.len() as f64;
    let e: Vec<f64> = tau_s.iter().map(|&tau| (-k_per_s * tau).exp()).collect();
    let mean_e = e.iter().sum::<f64>() / n;
    let mean_y = y.iter().sum::<f64>() / n;
    let (mut see, mut sey) = (0.0, 0.0);
    for (ei, yi) in e.iter().zip(y) {
        see += (ei - mean_e) * (ei - mean_e);
        sey += (ei - mean_e) * (yi - mean_y);
    }
    let amplitude = if see > 1e-300 { sey / see } else { 0.0 };
    let offset = mean_y - amplitude * mean_e;
    (offset, amplitude, residual_sum_of_squares(&e, y, offset, amplitude))
}

/// Σ (y − offset − amplitude·e)².
fn residual_sum_of_squares(e: &[f64], y: &[f64], offset: f64, amplitude: f64) -> f64 {
    e.iter()
        .zip(y)
        .map(|(ei, yi)| (yi - offset - amplitude * ei).powi(2))
        .sum()
}

/// For a fixed rate and offset, the least-squares amplitude of y ≈ offset + amplitude·exp(−k τ) and the SSE.
fn amplitude_part(tau_s: &[f64], y: &[f64], k_per_s: f64, offset: f64) -> (f64, f64, f64) {
    let e: Vec<f64> = tau_s.iter().map(|&tau| (-k_per_s * tau).exp()).collect();
    let see: f64 = e.iter().map(|e| e * e).sum();
    let sey: f64 = e.iter().zip(y).map(|(e, y)| e * (y - offset)).sum();
    let amplitude = if see > 1e-300 { sey / see } else { 0.0 };
    (offset, amplitude, residual_sum_of_squares(&e, y, offset, amplitude))
}

/// Brent's method (golden section with parabolic steps) for a minimum of `f` inside [a, b], to relative tolerance
/// `tol` in x.
fn brent_minimum(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    const GOLDEN: f64 = 0.381_966_011_250_105_1; // (3 − √5)/2
    let mut x = a + GOLDEN * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..200 {
        let xm = 0.5 * (a + b);
        let tol1 = tol * x.abs() + 1e-15;
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // Parabola through (v, fv), (w, fw), (x, fx).
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let e_prev = e;
            if p.abs() < (0.5 * q * e_prev).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(xm - x);
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol1 { x + d } else { x + tol1.copysign(d) };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv) = (w, fw);
            (w, fw) = (x, fx);
            (x, fx) = (u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv) = (w, fw);
                (w, fw) = (u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    x
}

/// The first time y reaches `fraction` × (largest y), linearly interpolated between the samples that bracket the
/// crossing: seed 000 Table 1's "time used to achieve 90 % Max(M)" with fraction = 0.9 and y the Lacey index.
///
/// Samples must be in time order; the answer is on the series' own clock (the seed measures from the start of the
/// simulation). If the first sample already reaches the level, its time is returned. Samples with a non-finite t or
/// y are skipped. Returns `None` for an empty series, a non-finite fraction, or a level no sample reaches (possible
/// when max y < 0 and fraction < 1).
///
/// Note: seed 000 §2.5.2 defines the level as 90 % of the maximum and this follows the text. Its Table 1 "90 %
/// Max(M)" column is 0.2 to 1.0 points above 0.9 × Max(M) in every row, more than rounding explains; it would fit
/// M_0 + 0.9 (Max − M_0) with initial values M_0 of 2–10 %, but the seed does not say so.
///
/// # Panics
/// If the slices differ in length.
pub fn time_to_fraction_of_max(t_s: &[f64], y: &[f64], fraction: f64) -> Option<f64> {
    assert_eq!(t_s.len(), y.len(), "time_to_fraction_of_max: one y per time");
    if !fraction.is_finite() {
        return None;
    }
    let finite = || {
        t_s.iter()
            .zip(y)
            .filter(|(t, y)| t.is_finite() && y.is_finite())
            .map(|(&t, &y)| (t, y))
    };
    let max = finite().map(|(_, y)| y).max_by(f64::total_cmp)?;
    let level = fraction * max;
    let mut previous: Option<(f64, f64)> = None;
    for (t, v) in finite() {
        if v >= level {
            return Some(match previous {
                // previous y < level ≤ v, so the division is by a positive number.
                Some((t_prev, v_prev)) => t_prev + (level - v_prev) / (v - v_prev) * (t - t_prev),
                None => t,
            });
        }
        previous = Some((t, v));
    }
    None
}

/// A least-squares line y = slope · x + intercept, with what tells a line through the origin from one that is not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    /// The intercept's standard error, s·√(1/n + x̄²/S_xx) with s² the residuals' sum of squares over n − 2 (NaN
    /// with two points).
    pub intercept_std_error: f64,
    /// R² = S_xy²/(S_xx S_yy); 1 when y does not vary.
    pub r_squared: f64,
}

/// Fits y = slope · x + intercept by ordinary least squares. `None` with fewer than two points or no spread in x.
/// Points with a non-finite x or y are skipped.
///
/// # Panics
/// If the slices differ in length.
pub fn fit_line(x: &[f64], y: &[f64]) -> Option<LineFit> {
    assert_eq!(x.len(), y.len(), "fit_line: one y per x");
    let (x, y): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(&x, &y)| (x, y))
        .unzip();
    if x.len() < 2 {
        return None;
    }
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|x| (x - mx) * (x - mx)).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum();
    let syy: f64 = y.iter().map(|y| (y - my) * (y - my)).sum();
    // (Also no line when sxx is NaN.)
    if sxx.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let residual_ss: f64 = x.iter().zip(&y).map(|(x, y)| (y - intercept - slope * x).powi(2)).sum();
    let intercept_std_error = if x.len() > 2 {
        (residual_ss / (n - 2.0) * (1.0 / n + mx * mx / sxx)).sqrt()
    } else {
        f64::NAN
    };
    Some(LineFit {
        slope,
        intercept,
        intercept_std_error,
        r_squared: if syy > 0.0 { sxy * sxy / (sxx * syy) } else { 1.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::RngExt;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;

    /// Standard normal deviate by Box–Muller.
    fn normal(rng: &mut ChaCha8Rng) -> f64 {
        let u1: f64 = 1.0 - rng.random::<f64>();
        let u2: f64 = rng.random::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    fn series(t_end_s: f64, points: usize, f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..points).map(|i| t_end_s * i as f64 / (points - 1) as f64).collect();
        let y = t.iter().map(|&t| f(t)).collect();
        (t, y)
    }

    #[test]
    fn recovers_an_is_decay_from_noisy_samples() {
        // IS from 0.5 (segregated) towards 0.15 (the mixed level for samples of 11), k = 0.4 1/s, noise σ = 0.01.
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let (t, mut y) = series(20.0, 201, |t| 0.15 + 0.35 * (-0.4 * t).exp());
        for v in &mut y {
            *v += 0.01 * normal(&mut rng);
        }
        let fit = fit_exponential_decay(&t, &y).expect("a clear decay");
        assert!((fit.rate_constant_per_s / 0.4 - 1.0).abs() < 0.05, "{fit:?}");
        assert!((fit.amplitude / 0.35 - 1.0).abs() < 0.03, "{fit:?}");
        assert!((fit.offset - 0.15).abs() < 0.005, "{fit:?}");
        assert!(fit.r_squared > 0.97 && fit.r_squared < 1.0, "{fit:?}");
        assert_eq!(fit.reference_time_s, 0.0);
    }

    #[test]
    fn recovers_exact_data_to_high_precision_with_a_late_clock_and_shuffled_samples() {
        // The series starts at t = 100 s and arrives out of order; amplitude is measured at the first time.
        let (mut t, mut y) = series(10.0, 50, |t| 2.0 - 1.5 * (-1.3 * t).exp());
        for v in &mut t {
            *v += 100.0;
        }
        t.reverse();
        y.reverse();
        let fit = fit_exponential_decay(&t, &y).expect("exact data");
        assert!((fit.rate_constant_per_s - 1.3).abs() < 1e-7, "{fit:?}");
        assert!((fit.amplitude + 1.5).abs() < 1e-7, "{fit:?}");
        assert!((fit.offset - 2.0).abs() < 1e-7, "{fit:?}");
        assert!(fit.r_squared > 1.0 - 1e-12);
        assert_eq!(fit.reference_time_s, 100.0);
        assert!((fit.value_at(101.0) - (2.0 - 1.5 * (-1.3f64).exp())).abs() < 1e-7);
        assert!((fit.time_constant_s() - 1.0 / 1.3).abs() < 1e-7);
    }

    #[test]
    fn no_decay_gives_none() {
        let (t, _) = series(10.0, 30, |t| t);
        // Too few points.
        assert_eq!(fit_exponential_decay(&t[..3], &[0.5, 0.3, 0.2]), None);
        // Only two distinct times.
        assert_eq!(
            fit_exponential_decay(&[0.0, 0.0, 1.0, 1.0], &[0.5, 0.5, 0.3, 0.3]),
            None
        );
        // Constant.
        assert_eq!(fit_exponential_decay(&t, &vec![0.3; 30]), None);
        // A straight line: k → 0.
        let line: Vec<f64> = t.iter().map(|t| 0.5 - 0.01 * t).collect();
        assert_eq!(fit_exponential_decay(&t, &line), None);
        // Growth: no positive rate fits.
        let growth: Vec<f64> = t.iter().map(|t| 0.1 * (0.3 * t).exp()).collect();
        assert_eq!(fit_exponential_decay(&t, &growth), None);
        // A step over between the first two samples: k → ∞.
        let step: Vec<f64> = t.iter().map(|&t| if t == 0.0 { 0.5 } else { 0.15 }).collect();
        assert_eq!(fit_exponential_decay(&t, &step), None);
        // Non-finite samples are skipped, not propagated.
        let mut y: Vec<f64> = t.iter().map(|t| 0.1 + 0.4 * (-0.5 * t).exp()).collect();
        y[3] = f64::NAN;
        let fit = fit_exponential_decay(&t, &y).expect("27 good samples");
        assert!((fit.rate_constant_per_s - 0.5).abs() < 1e-7);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Any decay whose time constant lies inside the record, sampled at ≥ 20 points, is recovered.
        #[test]
        fn recovers_exact_decays(
            k_per_s in 0.05f64..5.0,
            amplitude in prop_oneof![-2.0f64..-0.01, 0.01f64..2.0],
            offset in -1.0f64..1.0,
            points in 20usize..200,
        ) {
            let t_end_s = 8.0 / k_per_s;
            let (t, y) = series(t_end_s, points, |t| offset + amplitude * (-k_per_s * t).exp());
            let fit = fit_exponential_decay(&t, &y).expect("exact decay");
            prop_assert!((fit.rate_constant_per_s / k_per_s - 1.0).abs() < 1e-6, "{:?}", fit);
            prop_assert!((fit.amplitude / amplitude - 1.0).abs() < 1e-6, "{:?}", fit);
            prop_assert!((fit.offset - offset).abs() < 1e-6 * amplitude.abs().max(1.0), "{:?}", fit);
        }
    }

    #[test]
    fn time_to_fraction_of_max_on_known_curves() {
        // A ramp to a plateau of 1 at t = 10 s: 90 % of the maximum is reached at exactly 9 s, between samples.
        let t: Vec<f64> = (0..=30).map(|i| i as f64 * 0.7).collect();
        let ramp: Vec<f64> = t.iter().map(|&t| (t / 10.0).min(1.0)).collect();
        let t90 = time_to_fraction_of_max(&t, &ramp, 0.9).expect("reached");
        assert!((t90 - 9.0).abs() < 1e-12, "{t90}");

        // 1 − exp(−t) sampled finely: t* = −ln(1 − 0.9 max) up to interpolation error.
        let t: Vec<f64> = (0..=10_000).map(|i| i as f64 * 1e-3).collect();
        let y: Vec<f64> = t.iter().map(|&t| 1.0 - (-t).exp()).collect();
        let max = 1.0 - (-10.0f64).exp();
        let exact = -(1.0 - 0.9 * max).ln();
        let t90 = time_to_fraction_of_max(&t, &y, 0.9).expect("reached");
        assert!((t90 - exact).abs() < 1e-6, "{t90} vs {exact}");

        // The first crossing counts, not a later one after a dip; the max may come after the crossing.
        let t = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [0.0, 0.5, 0.95, 0.6, 0.8, 1.0];
        let expected = 1.0 + (0.9 - 0.5) / (0.95 - 0.5);
        assert!((time_to_fraction_of_max(&t, &y, 0.9).expect("reached") - expected).abs() < 1e-12);
        // Already there at the first sample.
        assert_eq!(
            time_to_fraction_of_max(&t, &[1.0, 0.2, 0.3, 0.4, 0.5, 0.6], 0.9),
            Some(0.0)
        );
    }

    #[test]
    fn time_to_fraction_of_max_edge_cases() {
        assert_eq!(time_to_fraction_of_max(&[], &[], 0.9), None);
        assert_eq!(time_to_fraction_of_max(&[0.0, 1.0], &[f64::NAN, f64::NAN], 0.9), None);
        assert_eq!(time_to_fraction_of_max(&[0.0, 1.0], &[0.1, 0.2], f64::NAN), None);
        // All negative: 0.9 × max is above max.
        assert_eq!(time_to_fraction_of_max(&[0.0, 1.0], &[-2.0, -1.0], 0.9), None);
        // A NaN sample is skipped: interpolation runs between its neighbours.
        let t = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(time_to_fraction_of_max(&t, &[0.0, f64::NAN, 1.0, 1.0], 0.5), Some(1.0));
    }

    /// With the asymptote fixed at its true value the rate is recovered; a series that stalls above that asymptote
    /// gets a smaller rate than the free fit gives it.
    #[test]
    fn a_fixed_asymptote_recovers_the_rate_and_penalises_a_stall() {
        let t: Vec<f64> = (0..80).map(|i| 0.05 * i as f64).collect();
        let y: Vec<f64> = t.iter().map(|t| 0.15 + 0.35 * (-1.3 * t).exp()).collect();
        let f = fit_exponential_decay_to(&t, &y, 0.15).unwrap();
        assert!((f.rate_constant_per_s - 1.3).abs() < 1e-6, "{f:?}");
        // Fast drop to a plateau at 0.25: the free fit sees a fast decay, the fixed one a slow approach to 0.15.
        let stall: Vec<f64> = t.iter().map(|t| 0.25 + 0.25 * (-3.0 * t).exp()).collect();
        let free = fit_exponential_decay(&t, &stall).unwrap();
        let fixed = fit_exponential_decay_to(&t, &stall, 0.15).unwrap();
        assert!((free.rate_constant_per_s - 3.0).abs() < 1e-6);
        assert!(fixed.rate_constant_per_s < 0.5 * free.rate_constant_per_s, "{fixed:?}");
    }

    #[test]
    fn a_line_fit_recovers_an_exact_line_and_the_textbook_intercept_error() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let exact: Vec<f64> = x.iter().map(|x| 2.5 * x - 1.0).collect();
        let f = fit_line(&x, &exact).unwrap();
        assert!(
            (f.slope - 2.5).abs() < 1e-12 && (f.intercept + 1.0).abs() < 1e-12,
            "{f:?}"
        );
        assert!(
            f.intercept_std_error.abs() < 1e-12 && (f.r_squared - 1.0).abs() < 1e-12,
            "{f:?}"
        );
        // y = 0, 1, 1, 2 on x = 0..3: slope 0.6, intercept 0.1, residuals -0.1, 0.3, -0.3, 0.1 (SS 0.2),
        // s² = 0.1, SE(b) = sqrt(0.1 (1/4 + 2.25/5)) = sqrt(0.07).
        let f = fit_line(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 1.0, 2.0]).unwrap();
        assert!(
            (f.slope - 0.6).abs() < 1e-12 && (f.intercept - 0.1).abs() < 1e-12,
            "{f:?}"
        );
        assert!((f.intercept_std_error - 0.07f64.sqrt()).abs() < 1e-12, "{f:?}");
        assert!((f.r_squared - 0.9).abs() < 1e-12, "{f:?}");
        assert!(fit_line(&[1.0, 1.0], &[0.0, 1.0]).is_none());
        assert!(fit_line(&[1.0, f64::NAN], &[0.0, 1.0]).is_none());
        assert!(fit_line(&[0.0, 1.0], &[0.0, 1.0]).unwrap().intercept_std_error.is_nan());
    }
}
