//! The mixing oscillation of a drum run: the bed is carried up the rising wall and slides
//! back, so the zone counts swing with a period of their own (in the reduced drum, about half
//! a turn). Its period and amplitude, from the steady frames' four zone-count series.
//!
//! The rule: for trial periods from two frame intervals (the shortest a frame series can
//! show) up to the length of the steady window, 0.5% apart, each series is fitted by least
//! squares with a constant and a sinusoid of that period (its own phase and amplitude); the
//! period is the one that leaves the least of the four series' variance unexplained, each
//! series counted by the fraction of its own variance (so the small counts of the large grains
//! weigh as much as the large counts of the small ones). A best period at the window's length
//! means the window holds less than one swing: no period is given.

/// The fitted swing of the four zone counts (zone 1 M1, zone 1 M2, zone 2 M1, zone 2 M2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oscillation {
    pub period_s: f64,
    /// Each series' amplitude (half its swing from crest to trough), grains.
    pub amplitudes: [f64; 4],
    /// The share of the series' variance the sinusoids explain (mean over the series that
    /// vary), 0 .. 1.
    pub explained: f64,
}

/// Trial periods this far apart (a ratio).
const PERIOD_STEP: f64 = 1.005;
/// Fewer steady frames than this give no period.
pub const MIN_FRAMES: usize = 6;

/// The oscillation of the series `counts` sampled at `times` (s, increasing, evenly or not);
/// None with fewer than [`MIN_FRAMES`] frames, series that do not vary, or a window shorter
/// than one swing.
pub fn oscillation(times: &[f64], counts: &[[f64; 4]]) -> Option<Oscillation> {
    if times.len() < MIN_FRAMES || times.len() != counts.len() {
        return None;
    }
    let window = times[times.len() - 1] - times[0];
    let interval = window / (times.len() - 1) as f64;
    let variances: [f64; 4] = std::array::from_fn(|k| variance(counts.iter().map(|c| c[k])));
    let varying: Vec<usize> = (0..4).filter(|&k| variances[k] > 0.0).collect();
    if varying.is_empty() || interval.is_nan() || interval <= 0.0 {
        return None;
    }
    // (unexplained share, period, amplitudes) of the best trial period so far.
    let mut best: Option<(f64, f64, [f64; 4])> = None;
    let mut period = 2.0 * interval;
    while period <= window * (1.0 + 1e-9) {
        if let Some((unexplained, amplitudes)) =
            fit_all(times, counts, &variances, &varying, period)
        {
            if best.is_none_or(|b| unexplained < b.0) {
                best = Some((unexplained, period, amplitudes));
            }
        }
        period *= PERIOD_STEP;
    }
    let (unexplained, period_s, amplitudes) = best?;
    // At the top of the range, the fit would take a longer period still: not resolved.
    (period_s * PERIOD_STEP <= window).then_some(Oscillation {
        period_s,
        amplitudes,
        explained: 1.0 - unexplained,
    })
}

/// The mean unexplained share of the `varying` series' variance with sinusoids of `period`,
/// and their amplitudes; None where the period aliases to a constant at these times.
fn fit_all(
    times: &[f64],
    counts: &[[f64; 4]],
    variances: &[f64; 4],
    varying: &[usize],
    period: f64,
) -> Option<(f64, [f64; 4])> {
    let mut unexplained = 0.0;
    let mut amplitudes = [0.0; 4];
    for &k in varying {
        let series: Vec<f64> = counts.iter().map(|c| c[k]).collect();
        let (residual, amplitude) = sinusoid_fit(times, &series, period)?;
        unexplained += residual / (variances[k] * times.len() as f64);
        amplitudes[k] = amplitude;
    }
    Some((unexplained / varying.len() as f64, amplitudes))
}

/// The population variance of `values`.
fn variance(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let n = values.clone().count() as f64;
    let mean = values.clone().sum::<f64>() / n;
    values.map(|v| (v - mean).powi(2)).sum::<f64>() / n
}

/// Least squares of `y = a + b sin(w t) + c cos(w t)`, w = 2 pi / period: the residual sum
/// of squares and the amplitude sqrt(b^2 + c^2); None when the three columns are dependent
/// (the period aliases to a constant at these times).
fn sinusoid_fit(times: &[f64], y: &[f64], period: f64) -> Option<(f64, f64)> {
    let w = std::f64::consts::TAU / period;
    let rows: Vec<[f64; 3]> = times
        .iter()
        .map(|&t| [1.0, (w * t).sin(), (w * t).cos()])
        .collect();
    let mut normal = [[0.0; 3]; 3];
    let mut rhs = [0.0; 3];
    for (row, &v) in rows.iter().zip(y) {
        for i in 0..3 {
            rhs[i] += row[i] * v;
            for j in 0..3 {
                normal[i][j] += row[i] * row[j];
            }
        }
    }
    let [a, b, c] = solve3(normal, rhs)?;
    let residual = rows
        .iter()
        .zip(y)
        .map(|(r, &v)| (v - a - b * r[1] - c * r[2]).powi(2))
        .sum();
    Some((residual, b.hypot(c)))
}

/// The solution of the 3 x 3 normal equations by Cramer's rule; None when they are (nearly)
/// singular.
fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    // The entries of the sine and cosine columns are at most 1: det <= n^3 (n = m[0][0]).
    if d.is_nan() || d.abs() <= 1e-9 * m[0][0].powi(3) {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for i in 0..3 {
            mk[i][k] = r[i];
        }
        *o = det(&mk) / d;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames every 0.1 s over `window` s of counts swinging with `period` about their means.
    fn swinging(window: f64, period: f64, amplitudes: [f64; 4]) -> (Vec<f64>, Vec<[f64; 4]>) {
        let n = (window / 0.1).round() as usize + 1;
        let times: Vec<f64> = (0..n).map(|k| 1.0 + 0.1 * k as f64).collect();
        let counts = times
            .iter()
            .map(|&t| {
                std::array::from_fn(|k| {
                    let phase = 0.7 * k as f64;
                    1000.0 + amplitudes[k] * (std::f64::consts::TAU * t / period + phase).sin()
                })
            })
            .collect();
        (times, counts)
    }

    #[test]
    fn a_swing_of_one_and_a_half_seconds_over_two_seconds_is_found_with_its_amplitudes() {
        let (times, counts) = swinging(2.0, 1.5, [1500.0, 150.0, 1800.0, 300.0]);
        let o = oscillation(&times, &counts).unwrap();
        assert!((o.period_s / 1.5 - 1.0).abs() < 0.006, "{o:?}");
        for (a, want) in o.amplitudes.iter().zip([1500.0, 150.0, 1800.0, 300.0]) {
            assert!((a / want - 1.0).abs() < 0.02, "{o:?}");
        }
        assert!(o.explained > 0.99, "{o:?}");
    }

    #[test]
    fn a_window_shorter_than_one_swing_gives_no_period() {
        let (times, counts) = swinging(1.0, 3.0, [1500.0, 150.0, 1800.0, 300.0]);
        assert_eq!(oscillation(&times, &counts), None);
    }

    #[test]
    fn counts_that_do_not_vary_or_too_few_frames_give_no_period() {
        let (times, counts) = swinging(2.0, 1.5, [0.0; 4]);
        assert_eq!(oscillation(&times, &counts), None);
        let (times, counts) = swinging(0.4, 0.3, [100.0; 4]);
        assert_eq!(times.len(), 5);
        assert_eq!(oscillation(&times, &counts), None);
    }

    /// The series each follow their own sinusoid plus a slower drift and noise-like wiggles;
    /// the joint period is the one the large swings share.
    #[test]
    fn the_period_shared_by_the_series_wins_over_a_wiggle_in_one() {
        let (times, mut counts) = swinging(2.5, 1.2, [800.0, 80.0, 900.0, 120.0]);
        for (t, c) in times.iter().zip(counts.iter_mut()) {
            c[1] += 30.0 * (std::f64::consts::TAU * t / 0.3).sin();
        }
        let o = oscillation(&times, &counts).unwrap();
        assert!((o.period_s / 1.2 - 1.0).abs() < 0.01, "{o:?}");
    }
}
