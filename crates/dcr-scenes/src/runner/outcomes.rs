//! Outcome figures measured on a trajectory (plates' lift, wrench slide, post tilt, ...).

use crate::runner::Trajectory;
use crate::scene::{name_matches, OutcomeDesc};

fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

fn qconj(a: [f64; 4]) -> [f64; 4] {
    [-a[0], -a[1], -a[2], a[3]]
}

/// Rotation angle (deg) of a unit quaternion.
fn qangle_deg(q: [f64; 4]) -> f64 {
    2.0 * q[3].abs().min(1.0).acos().to_degrees()
}

/// The unit of an outcome kind.
pub fn unit_of(kind: &str) -> &'static str {
    match kind {
        "max_lift" | "max_slide" => "mm",
        "max_tilt" | "max_sway" | "sway_range" => "deg",
        "count_fallen" | "count_moved" => "bodies",
        _ => "",
    }
}

/// Measures `o` on `traj`. `None` if no body matches or the kind is unknown.
pub fn measure_outcome(o: &OutcomeDesc, traj: &Trajectory) -> Option<f64> {
    let bodies: Vec<usize> = (0..traj.names.len())
        .filter(|&b| name_matches(&o.bodies, &traj.names[b]))
        .collect();
    if bodies.is_empty() || traj.rows() == 0 {
        return None;
    }
    let rows: Vec<usize> = (0..traj.rows())
        .filter(|&k| traj.time[k] >= o.after)
        .collect();
    let last = traj.rows() - 1;
    let mut best: f64 = 0.0;
    match o.kind.as_str() {
        "max_lift" => {
            for &b in &bodies {
                let y0 = traj.pos(0, b)[1];
                for &k in &rows {
                    best = best.max((traj.pos(k, b)[1] - y0) * 1e3);
                }
            }
        }
        "max_slide" => {
            for &b in &bodies {
                let p0 = traj.pos(0, b);
                let p = traj.pos(last, b);
                best = best.max(((p[0] - p0[0]).powi(2) + (p[2] - p0[2]).powi(2)).sqrt() * 1e3);
            }
        }
        "max_tilt" => {
            for &b in &bodies {
                let q0 = traj.rot(0, b);
                for &k in &rows {
                    best = best.max(qangle_deg(qmul(qconj(q0), traj.rot(k, b))));
                }
            }
        }
        "max_sway" => {
            let rel = o
                .relative_to
                .as_ref()
                .and_then(|r| traj.names.iter().position(|n| n == r));
            for &b in &bodies {
                let q0 = match rel {
                    Some(r) => qmul(qconj(traj.rot(0, r)), traj.rot(0, b)),
                    None => traj.rot(0, b),
                };
                for &k in &rows {
                    let q = match rel {
                        Some(r) => qmul(qconj(traj.rot(k, r)), traj.rot(k, b)),
                        None => traj.rot(k, b),
                    };
                    best = best.max(qangle_deg(qmul(qconj(q0), q)));
                }
            }
        }
        "sway_range" => {
            // Range (max − min) over time of the signed hinge-free rotation angle of each body
            // relative to `relative_to`, measured from its start; constant sag drops out.
            let rel = o
                .relative_to
                .as_ref()
                .and_then(|r| traj.names.iter().position(|n| n == r));
            for &b in &bodies {
                let relq = |k: usize| match rel {
                    Some(r) => qmul(qconj(traj.rot(k, r)), traj.rot(k, b)),
                    None => traj.rot(k, b),
                };
                let q0 = relq(0);
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for &k in &rows {
                    let d = qmul(qconj(q0), relq(k));
                    // Signed angle about the rotation's own dominant axis sign convention.
                    let s = if d[0] + d[1] + d[2] >= 0.0 { 1.0 } else { -1.0 };
                    let a = s * qangle_deg(d);
                    lo = lo.min(a);
                    hi = hi.max(a);
                }
                if hi >= lo {
                    best = best.max(hi - lo);
                }
            }
        }
        "count_fallen" => {
            let n = bodies
                .iter()
                .filter(|&&b| traj.pos(0, b)[1] - traj.pos(last, b)[1] > o.threshold)
                .count();
            best = n as f64;
        }
        "count_moved" => {
            let n = bodies
                .iter()
                .filter(|&&b| {
                    let (p0, p) = (traj.pos(0, b), traj.pos(last, b));
                    ((p[0] - p0[0]).powi(2) + (p[1] - p0[1]).powi(2) + (p[2] - p0[2]).powi(2))
                        .sqrt()
                        > o.threshold
                })
                .count();
            best = n as f64;
        }
        _ => return None,
    }
    Some(best)
}
