//! Error against time: the curves render-bench draws, their log–log fit, and the
//! equal-error speed-up of one method over another.

/// A least-squares line `log e = a + b log t` through `(t, e)` points (positive only);
/// `None` with fewer than two distinct times.
pub fn fit_loglog(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && t.is_finite() && e.is_finite())
        .map(|(t, e)| (t.ln(), e.ln()))
        .collect();
    let n = p.len() as f64;
    if p.len() < 2 {
        return None;
    }
    let (mx, my) = (
        p.iter().map(|v| v.0).sum::<f64>() / n,
        p.iter().map(|v| v.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|v| (v.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = p.iter().map(|v| (v.0 - mx) * (v.1 - my)).sum();
    let b = sxy / sxx;
    Some((my - b * mx, b))
}

/// The time a curve of `(seconds, error)` points needs to reach error `e`, interpolated
/// linearly in log–log between the two points around it (the curve ordered by time), and
/// whether it was interpolated: a curve whose first point is already below `e` gives that
/// point's time and `false` (an upper bound). `None` when the curve never reaches `e`.
pub fn time_to_reach(curve: &[(f64, f64)], e: f64) -> Option<(f64, bool)> {
    let mut p: Vec<(f64, f64)> = curve
        .iter()
        .copied()
        .filter(|(t, v)| *t > 0.0 && *v > 0.0 && t.is_finite() && v.is_finite())
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    if e.is_nan() || e <= 0.0 {
        return None;
    }
    if let Some(first) = p.first()
        && first.1 <= e
    {
        return Some((first.0, false));
    }
    p.windows(2).find_map(|w| {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e0 > e && e1 <= e {
            let f = (e.ln() - e0.ln()) / (e1.ln() - e0.ln());
            Some(((t0.ln() + f * (t1.ln() - t0.ln())).exp(), true))
        } else {
            None
        }
    })
}

/// The equal-error speed-up of a run `(t, e)` over a baseline curve: the time the
/// baseline's log–log fit needs to reach error `e`, divided by `t`. `None` when the
/// baseline's error does not fall with time.
pub fn speedup(baseline: &[(f64, f64)], t: f64, e: f64) -> Option<f64> {
    let (a, b) = fit_loglog(baseline)?;
    if b >= 0.0 || t <= 0.0 || e <= 0.0 {
        return None;
    }
    let t_base = ((e.ln() - a) / b).exp();
    let s = t_base / t;
    s.is_finite().then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_to_reach_interpolates_in_log_log() {
        let c = [(1.0, 1.0), (4.0, 0.25), (16.0, 0.0625)];
        let (t, exact) = time_to_reach(&c, 0.5).unwrap();
        assert!((t - 2.0).abs() < 1e-12 && exact);
        assert_eq!(time_to_reach(&c, 2.0), Some((1.0, false)));
        assert_eq!(time_to_reach(&c, 0.01), None);
        assert_eq!(time_to_reach(&c, f64::NAN), None);
    }

    #[test]
    fn speedup_reads_the_baseline_fit() {
        // Error ∝ 1/t: the baseline reaches e = 0.01 at t = 100.
        let base: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0].iter().map(|&t| (t, 1.0 / t)).collect();
        let (a, b) = fit_loglog(&base).unwrap();
        assert!(a.abs() < 1e-12 && (b + 1.0).abs() < 1e-12);
        let s = speedup(&base, 10.0, 0.01).unwrap();
        assert!((s - 10.0).abs() < 1e-9, "{s}");
        assert_eq!(speedup(&[(1.0, 1.0), (2.0, 2.0)], 1.0, 0.5), None);
    }
}
