//! Least-squares fits of the attenuation laws to measured (r, s) samples: Eq. 14 (α, β, r0) and
//! the §4.5 law s = C r^−β, in log space (see the parent module's docs).

use super::FitError;

/// Fewest usable pairs accepted by the fits.
pub const MIN_FIT_SAMPLES: usize = 4;

/// Eq. 14 parameters fitted to samples (r in m).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct AttenuationFit {
    /// Material absorption α (1/m), ≥ 0.
    pub alpha: f64,
    /// Geometric spreading exponent β, ≥ 0.
    pub beta: f64,
    /// Minimum distance r0 (m), > 0.
    pub r0: f64,
    /// R² of ln s (1: perfect).
    pub r2_log: f64,
    /// RMS error of ln s (a factor e^rms on s).
    pub rms_log: f64,
    /// Samples used.
    pub n: usize,
    /// Which constraint face the optimum lies on: `free`, `alpha=0`, `beta=0`, `alpha=beta=0`.
    pub active: &'static str,
}

impl AttenuationFit {
    /// s(r) of the fitted law (not clamped at r0).
    pub fn factor(&self, r: f64) -> f64 {
        (-self.alpha * (r - self.r0)).exp() * (r / self.r0).powf(-self.beta)
    }
}

/// §4.5 simplified law s = C r^−β (r in m) fitted to samples.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SimplifiedFit {
    /// C.
    pub c: f64,
    /// β, ≥ 0.
    pub beta: f64,
    /// R² of ln s.
    pub r2_log: f64,
    /// RMS error of ln s.
    pub rms_log: f64,
    /// Samples used.
    pub n: usize,
}

/// Least squares of y on the columns of `a` (n × k, k ≤ 3) by modified Gram–Schmidt QR.
/// Returns (coefficients, residual sum of squares) or `None` if the columns are dependent.
fn least_squares(cols: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, f64)> {
    let k = cols.len();
    let mut q: Vec<Vec<f64>> = cols.to_vec();
    let mut rmat = vec![vec![0.0; k]; k];
    for j in 0..k {
        let norm0 = q[j].iter().map(|x| x * x).sum::<f64>().sqrt();
        for i in 0..j {
            let d: f64 = q[i].iter().zip(&q[j]).map(|(a, b)| a * b).sum();
            rmat[i][j] = d;
            let qi = q[i].clone();
            q[j].iter_mut().zip(&qi).for_each(|(x, a)| *x -= d * a);
        }
        let nrm = q[j].iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(nrm > 1e-10 * norm0.max(f64::MIN_POSITIVE)) {
            return None;
        }
        rmat[j][j] = nrm;
        q[j].iter_mut().for_each(|x| *x /= nrm);
    }
    let qty: Vec<f64> = q
        .iter()
        .map(|qj| qj.iter().zip(y).map(|(a, b)| a * b).sum())
        .collect();
    let mut x = vec![0.0; k];
    for j in (0..k).rev() {
        let s: f64 = (j + 1..k).map(|i| rmat[j][i] * x[i]).sum();
        x[j] = (qty[j] - s) / rmat[j][j];
    }
    let rss = y
        .iter()
        .enumerate()
        .map(|(i, yi)| {
            let p: f64 = (0..k).map(|j| cols[j][i] * x[j]).sum();
            (yi - p).powi(2)
        })
        .sum();
    Some((x, rss))
}

/// The usable (r, ln s) pairs.
fn usable(r: &[f64], s: &[f64]) -> Result<(Vec<f64>, Vec<f64>), FitError> {
    let (rr, ls): (Vec<f64>, Vec<f64>) = r
        .iter()
        .zip(s)
        .filter(|(r, s)| r.is_finite() && **r > 0.0 && s.is_finite() && **s > 0.0)
        .map(|(r, s)| (*r, s.ln()))
        .unzip();
    if rr.len() < MIN_FIT_SAMPLES {
        return Err(FitError::TooFewSamples {
            have: rr.len(),
            need: MIN_FIT_SAMPLES,
        });
    }
    Ok((rr, ls))
}

fn quality(ls: &[f64], rss: f64) -> (f64, f64) {
    let n = ls.len() as f64;
    let mean = ls.iter().sum::<f64>() / n;
    let tot: f64 = ls.iter().map(|y| (y - mean).powi(2)).sum();
    let r2 = if tot > 0.0 { 1.0 - rss / tot } else { 1.0 };
    (r2, (rss / n).sqrt())
}

/// r0 > 0 with α r0 + β ln r0 = c (α, β ≥ 0), or `None`.
fn solve_r0(alpha: f64, beta: f64, c: f64) -> Option<f64> {
    if beta > 0.0 {
        // g(x) = α e^x + β x − c, increasing in x = ln r0.
        let g = |x: f64| alpha * x.min(700.0).exp() + beta * x - c;
        let (mut lo, mut hi) = (-1.0f64, 1.0f64);
        while g(lo) > 0.0 {
            lo *= 2.0;
            if lo < -1e6 {
                return None;
            }
        }
        while g(hi) < 0.0 {
            hi *= 2.0;
            if hi > 1e6 {
                return None;
            }
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r0 = (0.5 * (lo + hi)).exp();
        (r0.is_finite() && r0 > 0.0).then_some(r0)
    } else if alpha > 0.0 && c > 0.0 {
        Some(c / alpha)
    } else {
        None
    }
}

/// Least-squares fit of Eq. 14, s = exp(−α(r − r0)) (r/r0)^−β, to samples (r in m, s > 0);
/// r0 is fitted too (see the module docs). Samples with r ≤ 0, s ≤ 0 or non-finite values are
/// ignored.
///
/// # Errors
/// [`FitError::TooFewSamples`] below [`MIN_FIT_SAMPLES`] usable samples;
/// [`FitError::Degenerate`] if no α ≥ 0, β ≥ 0, r0 > 0 fits (e.g. a single distance).
///
/// ```
/// use dcr_lab::attenuation_fit::fit_eq14;
/// let r: Vec<f64> = (1..40).map(|i| 0.05 * i as f64).collect();
/// let s: Vec<f64> = r.iter().map(|r| (-0.5 * (r - 0.03)).exp() * (r / 0.03).powf(-0.8)).collect();
/// let f = fit_eq14(&r, &s).unwrap();
/// assert!((f.alpha - 0.5).abs() < 1e-8 && (f.beta - 0.8).abs() < 1e-8);
/// assert!((f.r0 - 0.03).abs() < 1e-9);
/// ```
pub fn fit_eq14(r: &[f64], s: &[f64]) -> Result<AttenuationFit, FitError> {
    let (rr, ls) = usable(r, s)?;
    let one = vec![1.0; rr.len()];
    let mr: Vec<f64> = rr.iter().map(|r| -r).collect();
    let ml: Vec<f64> = rr.iter().map(|r| -r.ln()).collect();
    let mut best: Option<(f64, AttenuationFit)> = None;
    let faces: [(&'static str, bool, bool); 3] = [
        ("free", true, true),
        ("alpha=0", false, true),
        ("beta=0", true, false),
    ];
    for (name, use_a, use_b) in faces {
        let mut cols = vec![one.clone()];
        if use_a {
            cols.push(mr.clone());
        }
        if use_b {
            cols.push(ml.clone());
        }
        let Some((x, rss)) = least_squares(&cols, &ls) else {
            continue;
        };
        let c = x[0];
        let alpha = if use_a { x[1] } else { 0.0 };
        let beta = if use_b { x[cols.len() - 1] } else { 0.0 };
        if alpha < 0.0 || beta < 0.0 {
            continue;
        }
        let Some(r0) = solve_r0(alpha, beta, c) else {
            continue;
        };
        if best.as_ref().is_none_or(|(b, _)| rss < *b) {
            let (r2_log, rms_log) = quality(&ls, rss);
            best = Some((
                rss,
                AttenuationFit {
                    alpha,
                    beta,
                    r0,
                    r2_log,
                    rms_log,
                    n: rr.len(),
                    active: name,
                },
            ));
        }
    }
    best.map(|(_, f)| f)
        .ok_or_else(|| FitError::Degenerate("no α ≥ 0, β ≥ 0, r0 > 0 fits the samples".into()))
}

/// As [`fit_eq14`] with r0 (m) given: ln s = −α(r − r0) − β ln(r/r0), linear in (α, β).
///
/// # Errors
/// As [`fit_eq14`]; [`FitError::Params`] if r0 is not finite and > 0.
pub fn fit_eq14_fixed_r0(r: &[f64], s: &[f64], r0: f64) -> Result<AttenuationFit, FitError> {
    if !(r0.is_finite() && r0 > 0.0) {
        return Err(FitError::Params(format!(
            "r0 must be finite and > 0 m, got {r0}"
        )));
    }
    let (rr, ls) = usable(r, s)?;
    let ma: Vec<f64> = rr.iter().map(|r| -(r - r0)).collect();
    let mb: Vec<f64> = rr.iter().map(|r| -(r / r0).ln()).collect();
    let mut best: Option<(f64, AttenuationFit)> = None;
    let faces: [(&'static str, bool, bool); 4] = [
        ("free", true, true),
        ("alpha=0", false, true),
        ("beta=0", true, false),
        ("alpha=beta=0", false, false),
    ];
    for (name, use_a, use_b) in faces {
        let mut cols = Vec::new();
        if use_a {
            cols.push(ma.clone());
        }
        if use_b {
            cols.push(mb.clone());
        }
        let (x, rss) = if cols.is_empty() {
            (vec![], ls.iter().map(|y| y * y).sum())
        } else {
            match least_squares(&cols, &ls) {
                Some(v) => v,
                None => continue,
            }
        };
        let alpha = if use_a { x[0] } else { 0.0 };
        let beta = if use_b { x[x.len() - 1] } else { 0.0 };
        if alpha < 0.0 || beta < 0.0 {
            continue;
        }
        if best.as_ref().is_none_or(|(b, _)| rss < *b) {
            let (r2_log, rms_log) = quality(&ls, rss);
            best = Some((
                rss,
                AttenuationFit {
                    alpha,
                    beta,
                    r0,
                    r2_log,
                    rms_log,
                    n: rr.len(),
                    active: name,
                },
            ));
        }
    }
    best.map(|(_, f)| f)
        .ok_or_else(|| FitError::Degenerate("no α ≥ 0, β ≥ 0 fits the samples".into()))
}

/// Least-squares fit of the §4.5 law s = C r^−β (r in m): ln s = ln C − β ln r, β ≥ 0.
///
/// # Errors
/// [`FitError::TooFewSamples`]; [`FitError::Degenerate`] if every r is the same.
pub fn fit_simplified(r: &[f64], s: &[f64]) -> Result<SimplifiedFit, FitError> {
    let (rr, ls) = usable(r, s)?;
    let one = vec![1.0; rr.len()];
    let ml: Vec<f64> = rr.iter().map(|r| -r.ln()).collect();
    let (c, beta, rss) = match least_squares(&[one.clone(), ml], &ls) {
        Some((x, rss)) if x[1] >= 0.0 => (x[0], x[1], rss),
        Some(_) => {
            let (x, rss) = least_squares(&[one], &ls).expect("a column of ones");
            (x[0], 0.0, rss)
        }
        None => return Err(FitError::Degenerate("every distance is the same".into())),
    };
    let (r2_log, rms_log) = quality(&ls, rss);
    Ok(SimplifiedFit {
        c: c.exp(),
        beta,
        r2_log,
        rms_log,
        n: rr.len(),
    })
}
