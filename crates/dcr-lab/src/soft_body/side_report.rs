//! The comparison of one or more scenes as a markdown section (docs/benchmarks.md).

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::side_by_side::{SideMethod, SideRow, SweepEnd};
use super::soft_scene::SoftSceneParams;

/// One scene's rows: the rapier-FEM sweep, the dcr rows and the no-response row.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneComparison {
    /// Scene name.
    pub scene: String,
    /// rapier's default substep count (marked in the table).
    pub default_substeps: usize,
    /// The sweep's rows in order, then the other rows.
    pub rows: Vec<SideRow>,
    /// How the sweep ended.
    pub sweep: SweepEnd,
}

fn fmt_sig(x: f64) -> String {
    if !x.is_finite() {
        return "–".into();
    }
    let a = x.abs();
    if a == 0.0 {
        "0".into()
    } else if a >= 100.0 {
        format!("{x:.0}")
    } else if a >= 10.0 {
        format!("{x:.1}")
    } else if a >= 1.0 {
        format!("{x:.2}")
    } else if a >= 0.01 {
        format!("{x:.3}")
    } else {
        format!("{x:.1e}")
    }
}

impl SceneComparison {
    fn row(&self, m: &SideMethod) -> Option<&SideRow> {
        self.rows.iter().find(|r| &r.method == m)
    }

    /// The last row of the sweep (the converged one when the sweep converged).
    pub fn last_soft(&self) -> Option<&SideRow> {
        self.rows.iter().rev().find(|r| {
            matches!(r.method, SideMethod::RapierFem { substeps, .. } if substeps == self.sweep.last_substeps)
        })
    }
}

/// The markdown table of each scene's rows (outcomes as mean ± sample standard deviation for
/// ensembles), with a line per scene on where the sweep ended and how the converged soft
/// object compares with dcr (cost per step, outcomes).
pub fn render_markdown(scenes: &[SceneComparison]) -> String {
    let mut s = String::new();
    for sc in scenes {
        let names: Vec<(String, String)> = sc
            .rows
            .first()
            .map(|r| {
                r.outcomes
                    .iter()
                    .map(|(n, (_, u))| (n.clone(), u.clone()))
                    .collect()
            })
            .unwrap_or_default();
        let _ = writeln!(s, "#### {}\n", sc.scene);
        if let Some(r) = sc.rows.iter().find(|r| r.members > 1) {
            let _ = writeln!(
                s,
                "Every row is an ensemble of {} runs: the scene as written and {} with the \
                 projectile started {} mm away across gravity, each in its own direction. \
                 Outcomes are the members' mean ± sample standard deviation; step times are over \
                 all members' steps; run s is the whole ensemble.\n",
                r.members,
                r.members - 1,
                fmt_sig(r.perturbation * 1e3)
            );
        }
        let _ = write!(
            s,
            "| method | step median ms | step p99 ms | × ★ table step | response median / p99 ms | peak RSS MiB |"
        );
        for (n, u) in &names {
            let _ = write!(s, " {n} ({u}) |");
        }
        let _ = writeln!(s, " soft surface under a prop, peak mm | run s |");
        let _ = write!(s, "|---|---|---|---|---|---|");
        for _ in &names {
            let _ = write!(s, "---|");
        }
        let _ = writeln!(s, "---|---|");
        let table_step = sc.row(&SideMethod::Transfer).map(|r| r.step_ms_median);
        for r in &sc.rows {
            let mut label = r.method.label();
            if let SideMethod::RapierFem { substeps, .. } = r.method {
                // rapier's default: its substeps and every solver setting at rapier's own value.
                let d = SoftSceneParams::new(std::path::PathBuf::new());
                let default = SideMethod::RapierFem {
                    substeps: sc.default_substeps,
                    cg_iterations: d.cg_iterations,
                    max_dense_dofs: d.max_dense_dofs,
                    cg_tolerance: d.cg_tolerance,
                };
                if r.method == default {
                    label.push_str(" (rapier's default)");
                }
                if sc.sweep.converged && substeps == sc.sweep.last_substeps {
                    label.push_str(if sc.sweep.within_noise {
                        " (converged within noise)"
                    } else {
                        " (converged)"
                    });
                }
            }
            let ratio =
                table_step.map_or("–".into(), |t| format!("{:.0}×", r.step_ms_median / t));
            let response = r.response_ms.map_or("–".into(), |[a, b]| {
                format!("{} / {}", fmt_sig(a), fmt_sig(b))
            });
            let _ = write!(
                s,
                "| {label} | {} | {} | {ratio} | {response} | {} |",
                fmt_sig(r.step_ms_median),
                fmt_sig(r.step_ms_p99),
                r.peak_rss_mib.map_or("–".into(), |m| format!("{m:.0}")),
            );
            for (n, _) in &names {
                let v = r.outcomes.get(n).map_or(f64::NAN, |v| v.0);
                if r.members > 1 {
                    let sd = r.spread.get(n).copied().unwrap_or(f64::NAN);
                    let _ = write!(s, " {} ± {} |", fmt_sig(v), fmt_sig(sd));
                } else {
                    let _ = write!(s, " {} |", fmt_sig(v));
                }
            }
            let _ = writeln!(
                s,
                " {} | {:.0} |",
                r.surface_peak_mm.map_or("–".into(), fmt_sig),
                r.wall_s
            );
        }
        let _ = writeln!(s);
        let end = &sc.sweep;
        let _ = writeln!(
            s,
            "Sweep: stopped at {} substeps ({}; last doubling changed the outcomes by at most {}{}).",
            end.last_substeps,
            end.reason,
            if end.last_change.is_finite() {
                format!("{:.1} %", 100.0 * end.last_change)
            } else {
                "–".into()
            },
            if end.within_noise {
                ", every mean within max(the tolerance, two standard errors of the difference)"
            } else {
                ""
            }
        );
        if let (Some(soft), Some(t), Some(m)) = (
            sc.last_soft(),
            sc.row(&SideMethod::Transfer),
            sc.row(&SideMethod::Modal),
        ) {
            let _ = writeln!(
                s,
                "Last soft row against dcr: {:.0}× the ★ table's whole step and {:.0}× the 20-mode \
                 one (medians); {:.0}× the ★ table's response alone.",
                soft.step_ms_median / t.step_ms_median,
                soft.step_ms_median / m.step_ms_median,
                soft.step_ms_median / t.response_ms.map_or(f64::NAN, |r| r[0]),
            );
        }
        let _ = writeln!(s);
    }
    s
}
