//! [`solve_penalty_block`]: the normal forces of one prop's contact points over a coupling step,
//! implicit in the forces (see the module doc of [`super`]).
//!
//! The end-of-step gaps are affine in the held forces, g = g_free + A f (A symmetric positive
//! semi-definite: the elastic step compliance plus Δt² times the bodies' inverse effective
//! masses), and each point's force is the clamped spring–dashpot of its end-of-step gap,
//! f_a = max(0, b_a − κ_a (A f)_a). This is the linear complementarity problem
//! 0 ≤ f ⊥ (D + A) f − D b ≥ 0 with D = diag(1/κ) positive, so D + A is symmetric positive
//! definite and the solution is unique. It is found by active-set iterations (a Cholesky
//! solve of the active rows, drop the negative forces, add the violated inactive rows), with
//! projected Gauss–Seidel (which converges for any symmetric positive definite matrix) as the
//! fallback should the active set cycle. Blocks are a prop's few contact points: the dense
//! solve is faer's Cholesky.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// What [`solve_penalty_block`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockSolveInfo {
    /// Active-set iterations.
    pub iterations: usize,
    /// Whether the projected Gauss–Seidel fallback ran.
    pub fallback: bool,
    /// Largest complementarity residual left, in force units (N): max over points of
    /// |f_a − max(0, b_a − κ_a (A f)_a)|.
    pub residual: f64,
}

/// Solves f_a = max(0, b_a − κ_a Σ_b A_ab f_b) for the n forces `f` (N).
///
/// `a` is the n × n matrix A (row-major, m/N, symmetric positive semi-definite), `kappa` the
/// per-point κ_a > 0 (N/m), `b` the per-point free force b_a (N). `f` holds the result.
pub fn solve_penalty_block(a: &[f64], kappa: &[f64], b: &[f64], f: &mut [f64]) -> BlockSolveInfo {
    let n = b.len();
    debug_assert!(a.len() == n * n && kappa.len() == n && f.len() == n);
    f.fill(0.0);
    let mut active: Vec<bool> = b.iter().map(|&x| x > 0.0).collect();
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    let tol = 1e-12 * scale;
    let mut iterations = 0;
    let mut ok = false;
    for _ in 0..4 * n + 8 {
        iterations += 1;
        let idx: Vec<usize> = (0..n).filter(|&i| active[i]).collect();
        f.fill(0.0);
        if !idx.is_empty() {
            let k = idx.len();
            let m = Mat::<f64>::from_fn(k, k, |r, c| {
                let (i, j) = (idx[r], idx[c]);
                a[i * n + j] + if i == j { 1.0 / kappa[i] } else { 0.0 }
            });
            let rhs = Mat::<f64>::from_fn(k, 1, |r, _| b[idx[r]] / kappa[idx[r]]);
            let Ok(llt) = m.as_ref().llt(Side::Lower) else {
                break;
            };
            let x = llt.solve(rhs.as_ref());
            for (r, &i) in idx.iter().enumerate() {
                f[i] = x[(r, 0)];
            }
        }
        let mut changed = false;
        for i in 0..n {
            if active[i] && f[i] < 0.0 {
                active[i] = false;
                changed = true;
            }
        }
        if changed {
            continue;
        }
        for i in 0..n {
            if !active[i] && b[i] - kappa[i] * row_dot(a, n, i, f) > tol {
                active[i] = true;
                changed = true;
            }
        }
        if !changed {
            ok = true;
            break;
        }
    }
    for x in f.iter_mut() {
        *x = x.max(0.0);
    }
    let mut fallback = false;
    if !ok || residual(a, kappa, b, f) > 1e-9 * scale {
        fallback = true;
        // Projected Gauss–Seidel on (D + A) f = D b, f ≥ 0.
        for _ in 0..10_000 {
            let mut delta = 0.0f64;
            for i in 0..n {
                let off = row_dot(a, n, i, f) - a[i * n + i] * f[i];
                let fi = ((b[i] - kappa[i] * off) / (1.0 + kappa[i] * a[i * n + i])).max(0.0);
                delta = delta.max((fi - f[i]).abs());
                f[i] = fi;
            }
            if delta <= 1e-13 * scale {
                break;
            }
        }
    }
    BlockSolveInfo {
        iterations,
        fallback,
        residual: residual(a, kappa, b, f),
    }
}

fn row_dot(a: &[f64], n: usize, i: usize, f: &[f64]) -> f64 {
    a[i * n..(i + 1) * n]
        .iter()
        .zip(f)
        .map(|(x, y)| x * y)
        .sum()
}

fn residual(a: &[f64], kappa: &[f64], b: &[f64], f: &[f64]) -> f64 {
    let n = b.len();
    (0..n)
        .map(|i| (f[i] - (b[i] - kappa[i] * row_dot(a, n, i, f)).max(0.0)).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift), seeded.
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// Over random positive semi-definite blocks (rank-deficient ones included, κ from soft to
    /// near-rigid), the solution satisfies the complementarity conditions: f ≥ 0, the
    /// end-of-step force law holds at every point, and it equals the solution found by trying
    /// every active set.
    #[test]
    fn block_solution_is_the_complementarity_solution() {
        let mut r = rng(0x5eed);
        for case in 0..200 {
            let n = 1 + case % 6;
            let rank = 1 + case % n.max(1);
            let mut a = vec![0.0; n * n];
            for _ in 0..rank {
                let v: Vec<f64> = (0..n).map(|_| r()).collect();
                for i in 0..n {
                    for j in 0..n {
                        a[i * n + j] += 1e-6 * v[i] * v[j];
                    }
                }
            }
            let kappa: Vec<f64> = (0..n).map(|_| 10f64.powf(5.0 + 4.0 * r().abs())).collect();
            let b: Vec<f64> = (0..n).map(|_| 10.0 * r()).collect();
            let mut f = vec![0.0; n];
            let info = solve_penalty_block(&a, &kappa, &b, &mut f);
            assert!(info.residual < 1e-8, "case {case}: {info:?}");
            assert!(f.iter().all(|x| *x >= 0.0));
            // Brute force: the active set whose solution is feasible and complementary.
            let mut found = false;
            for mask in 0..(1u32 << n) {
                let idx: Vec<usize> = (0..n).filter(|i| mask >> i & 1 == 1).collect();
                let mut g = vec![0.0; n];
                if !idx.is_empty() {
                    let k = idx.len();
                    let m = Mat::<f64>::from_fn(k, k, |p, q| {
                        let (i, j) = (idx[p], idx[q]);
                        a[i * n + j] + if i == j { 1.0 / kappa[i] } else { 0.0 }
                    });
                    let rhs = Mat::<f64>::from_fn(k, 1, |p, _| b[idx[p]] / kappa[idx[p]]);
                    let x = m.as_ref().llt(Side::Lower).unwrap().solve(rhs.as_ref());
                    for (p, &i) in idx.iter().enumerate() {
                        g[i] = x[(p, 0)];
                    }
                }
                if residual(&a, &kappa, &b, &g) < 1e-9 && g.iter().all(|x| *x >= -1e-12) {
                    for i in 0..n {
                        assert!(
                            (g[i] - f[i]).abs() < 1e-7 * (1.0 + g[i].abs()),
                            "case {case}"
                        );
                    }
                    found = true;
                    break;
                }
            }
            assert!(found, "case {case}: no active set solves it");
        }
    }
}
