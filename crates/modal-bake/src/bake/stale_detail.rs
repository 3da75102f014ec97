//! Why a base is stale, in the words of the options that would change it: the texts of
//! [`BaseStatus`](super::BaseStatus)'s details (what `check` prints and `batch` reports).
//!
//! Each function compares what the base records (its `meta`, fixed nodes, surface and
//! `meta.bake_params`) with what a bake of this mesh with these options would write, and names
//! every difference it can see; none reads anything the staleness check did not already hold.

use super::params::ModeRequest;
use super::prepare::Prepared;
use super::{BakeParams, OUTPUT_VERSION, TOOL_VERSION};
use dcr_runtime::format::ModesFile;

/// Why the tool that wrote `base` differs from this one: its output version, or the
/// heat-geodesic surface order this tool stores and the base lacks.
pub(super) fn tool_difference(base: &ModesFile, version_matches: bool) -> String {
    if !version_matches {
        let recorded = base.meta.bake_params.get("output_version").map_or_else(
            || "no output version".to_string(),
            |v| format!("output version {v}"),
        );
        return format!(
            "written by {} ({recorded}); this {TOOL_VERSION} writes output version {OUTPUT_VERSION}",
            base.meta.tool_version
        );
    }
    format!(
        "written by {} without the heat-geodesic surface order this {TOOL_VERSION} stores",
        base.meta.tool_version
    )
}

/// What differs between the mesh `base` was baked from and `prepared` (nodes, tetrahedra,
/// fixed nodes, surface positions and size); always one line.
pub(super) fn geometry_difference(base: &ModesFile, prepared: &Prepared) -> String {
    let mesh = &prepared.mesh;
    let mut parts = Vec::new();
    let same_counts =
        base.meta.volume_nodes == mesh.nodes.len() && base.meta.volume_tets == mesh.tets.len();
    if !same_counts {
        parts.push(format!(
            "the base's mesh has {} nodes and {} tetrahedra, this one {} and {}",
            base.meta.volume_nodes,
            base.meta.volume_tets,
            mesh.nodes.len(),
            mesh.tets.len()
        ));
    }
    let fixed_now = prepared.fixed.len();
    let fixed_base = base.fixed_nodes.len();
    if fixed_base != fixed_now {
        parts.push(format!(
            "the base fixes {fixed_base} nodes, these options fix {fixed_now} (--fixed, --fixed-below, --fixed-box, --fixed-near)"
        ));
    } else if same_counts
        && !base
            .fixed_nodes
            .iter()
            .zip(&prepared.fixed)
            .all(|(&a, &b)| a as usize == b)
    {
        parts.push(format!(
            "the base and these options fix {fixed_now} nodes each, but other ones"
        ));
    }
    // The size of each: the surface's bounding-box diagonal (m).
    let now_surface: Vec<[f64; 3]> = base
        .surface_to_volume
        .iter()
        .filter_map(|&v| mesh.nodes.get(v as usize).copied())
        .collect();
    let (d_base, d_now) = (
        diagonal(&base.surface_vertices),
        diagonal(if same_counts {
            &now_surface
        } else {
            &mesh.nodes
        }),
    );
    let ratio = d_now / d_base;
    let resized = d_base > 0.0 && ratio.is_finite() && !(0.99..=1.01).contains(&ratio);
    // A factor between two of the units --units reads (m, cm, mm, in), within 1 %.
    let unit_like = resized
        && [10.0, 100.0, 1000.0, 2.54, 25.4, 1.0 / 0.0254]
            .iter()
            .any(|&f: &f64| (ratio.max(1.0 / ratio) / f - 1.0).abs() < 0.01);
    // Another mesh of the same object (a remeshed asset) differs in size a little: say so
    // when the counts match (a moved or scaled mesh), the factor is a unit's or large.
    if resized && (same_counts || unit_like || !(0.8..=1.25).contains(&ratio)) {
        parts.push(format!(
            "this mesh is {} the base's size ({d_now:.4e} m across, the base {d_base:.4e} m{})",
            times(ratio),
            if unit_like {
                "; read with another --units?"
            } else {
                ""
            }
        ));
    } else if same_counts && now_surface.len() == base.surface_vertices.len() {
        let (moved, at) = base
            .surface_vertices
            .iter()
            .zip(&now_surface)
            .enumerate()
            .map(|(i, (a, b))| (distance(*a, *b), i))
            .fold((0.0_f64, 0), |m, x| if x.0 > m.0 { x } else { m });
        if moved > 0.0 {
            parts.push(format!(
                "the same {} nodes and {} tetrahedra; surface nodes moved by up to {moved:.3e} m ({:.3} % of its size, volume node {})",
                mesh.nodes.len(),
                mesh.tets.len(),
                100.0 * moved / d_base.max(f64::MIN_POSITIVE),
                base.surface_to_volume[at]
            ));
        }
    }
    if parts.is_empty() {
        parts.push(format!(
            "the same {} nodes, {} tetrahedra, fixed nodes and surface positions: interior nodes, the tetrahedra's connectivity or the mid-edge nodes differ",
            mesh.nodes.len(),
            mesh.tets.len()
        ));
    }
    parts.join("; ")
}

/// `detail` with, for a base `bake --target-error` chose, the options that check it.
pub(super) fn with_target_choice(base: &ModesFile, detail: String) -> String {
    match crate::target_error::check_options(base) {
        Some(options) => format!(
            "{detail} (the base is a `bake --target-error` choice: check it with the bake's options, {options})"
        ),
        None => detail,
    }
}

/// The parameters recorded in `base` that differ from `params`, each named by its option:
/// `--density: 700 kg/m³ in the base, 750 kg/m³ asked; --modes/--max-freq: 10 modes in the
/// base, 12 modes asked`.
pub(super) fn parameter_difference(base: &ModesFile, params: &BakeParams) -> String {
    let recorded: BakeParams = match serde_json::from_value(base.meta.bake_params.clone()) {
        Ok(p) => p,
        Err(e) => {
            return format!(
            "its recorded parameters (meta.bake_params) do not read as this {TOOL_VERSION}'s: {e}"
        )
        }
    };
    let mut parts = Vec::new();
    let mut differ = |option: &str, was: String, now: String| {
        if was != now {
            parts.push(format!("{option}: {was} in the base, {now} asked"));
        }
    };
    let (m0, m1) = (&recorded.material, &params.material);
    differ(
        "--youngs",
        format!("{} Pa", option_number(m0.youngs)),
        format!("{} Pa", option_number(m1.youngs)),
    );
    differ(
        "--poisson",
        option_number(m0.poisson),
        option_number(m1.poisson),
    );
    differ(
        "--density",
        format!("{} kg/m³", option_number(m0.density)),
        format!("{} kg/m³", option_number(m1.density)),
    );
    differ(
        "--modes/--max-freq",
        modes(recorded.modes),
        modes(params.modes),
    );
    differ("--fixed", list(&recorded.fixed), list(&params.fixed));
    let below =
        |b: &[super::FixedBelow]| list(&b.iter().map(ToString::to_string).collect::<Vec<_>>());
    differ(
        "--fixed-below",
        below(&recorded.fixed_below),
        below(&params.fixed_below),
    );
    let boxes = |b: &[[f64; 6]]| {
        list(
            &b.iter()
                .map(|b| {
                    b.iter()
                        .map(|&x| option_number(x))
                        .collect::<Vec<_>>()
                        .join(",")
                })
                .collect::<Vec<_>>(),
        )
    };
    differ(
        "--fixed-box",
        boxes(&recorded.fixed_boxes),
        boxes(&params.fixed_boxes),
    );
    let near = |n: &[super::FixedNear]| {
        list(
            &n.iter()
                .map(|s| {
                    format!(
                        "{} points, {} faces, {}",
                        s.points.len(),
                        s.triangles.len(),
                        s.distance.map_or_else(
                            || "default distance".to_string(),
                            |d| format!("{} m", option_number(d))
                        )
                    )
                })
                .collect::<Vec<_>>(),
        )
    };
    let (near_was, near_now) = (near(&recorded.fixed_near), near(&params.fixed_near));
    let near_moved = recorded.fixed_near != params.fixed_near && near_was == near_now;
    differ("--fixed-near/--fixed-near-distance", near_was, near_now);
    differ(
        "--rayleigh",
        format!(
            "{},{}",
            option_number(recorded.rayleigh[0]),
            option_number(recorded.rayleigh[1])
        ),
        format!(
            "{},{}",
            option_number(params.rayleigh[0]),
            option_number(params.rayleigh[1])
        ),
    );
    differ("--lumped", on_off(recorded.lumped), on_off(params.lumped));
    let f32 = |p: &BakeParams| on_off(p.precision == dcr_runtime::format::ModesPrecision::F32);
    differ("--f32", f32(&recorded), f32(params));
    if near_moved {
        parts.push("--fixed-near: the same counts and distance, other points or faces".into());
    }
    if parts.is_empty() {
        return "every recorded parameter equals these options, but the base's parameter hash does not (its record was edited or written by another tool)".into();
    }
    parts.join("; ")
}

/// How the transfer table `base` holds (or lacks) differs from the one `expected` records
/// (`None`: no table asked for), each difference named by its option.
pub(super) fn transfer_difference(
    base: &ModesFile,
    expected: Option<&serde_json::Value>,
) -> String {
    let recorded = base.meta.bake_params.get("transfer");
    match (&base.transfer, expected) {
        (Some(t), None) => format!(
            "the base holds a transfer table (--transfer-h {} s); no --transfer-h was given",
            option_number(t.h)
        ),
        (None, Some(e)) => format!(
            "the base has no transfer table; --transfer-h {} asks for one",
            e.get("h").map_or_else(|| "?".into(), ToString::to_string)
        ),
        (None, None) => "the base's table record disagrees with its content".into(),
        (Some(_), Some(e)) => {
            let Some(recorded) = recorded else {
                return "the base's table has no recorded parameters (meta.bake_params.transfer)"
                    .into();
            };
            if recorded.get("regions").is_none() {
                return "the base records only its table's h, modes and order (chosen by the `bake --target-error` of an earlier modal-bake): bake it again".into();
            }
            let mut parts = Vec::new();
            for (key, option) in [
                ("h", "--transfer-h"),
                ("modes", "--transfer-modes"),
                ("regions", "--transfer-region"),
                ("up", "--transfer-up"),
                ("up_min_cos", "the region's normal cone"),
                ("oversample", "--transfer-oversample"),
                ("order", "--transfer-order"),
            ] {
                let (was, now) = (recorded.get(key), e.get(key));
                if was != now {
                    let show = |v: Option<&serde_json::Value>| {
                        v.map_or_else(|| "none".to_string(), ToString::to_string)
                    };
                    parts.push(format!(
                        "{option}: {} in the base, {} asked",
                        show(was),
                        show(now)
                    ));
                }
            }
            if recorded.get("modes_fixed_by") != e.get("modes_fixed_by") {
                parts.push("the table's extra modes were solved with the physical groups alone fixed, these options fix every selector".into());
            }
            if parts.is_empty() {
                parts.push("the table's recorded parameters differ".into());
            }
            parts.join("; ")
        }
    }
}

/// `x` in the shortest form that parses back to the same `f64`, as an option's value is
/// typed: `1.1e9`, `0.3`, `770`, `1e-7` (exponent form outside 1e-3 … 1e5).
pub fn option_number(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e5 || x.abs() < 1e-3) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// A mode request as its option's value.
fn modes(m: ModeRequest) -> String {
    match m {
        ModeRequest::Count(n) => format!("{n} modes"),
        ModeRequest::MaxFreqHz(f) => format!("below {} Hz", option_number(f)),
    }
}

fn list(items: &[String]) -> String {
    if items.is_empty() {
        "none".into()
    } else {
        items.join(" ")
    }
}

fn on_off(b: bool) -> String {
    if b { "on" } else { "off" }.into()
}

/// `ratio` as a factor to four significant digits: `1000×`, `0.0254×`.
fn times(ratio: f64) -> String {
    let rounded: f64 = format!("{ratio:.3e}").parse().unwrap_or(ratio);
    format!("{}×", option_number(rounded))
}

/// The diagonal (m) of the bounding box of `points`; 0 for none.
fn diagonal(points: &[[f64; 3]]) -> f64 {
    let Some(first) = points.first() else {
        return 0.0;
    };
    let (mut lo, mut hi) = (*first, *first);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    distance(lo, hi)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_typed() {
        assert_eq!(option_number(1.1e9), "1.1e9");
        assert_eq!(option_number(0.3), "0.3");
        assert_eq!(option_number(770.0), "770");
        assert_eq!(option_number(1e-7), "1e-7");
        assert_eq!(times(1_000.000_000_1), "1000×");
        assert_eq!(times(1e6), "1e6×");
        assert_eq!(times(0.0254), "0.0254×");
    }
}
