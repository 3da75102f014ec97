//! The scene's outcomes under the coupled reference beside the distant response's methods at
//! gain 1 (`docs/outcomes.md` and its lift-over-time plot).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use dcr_files::write_atomic;
use dcr_scenes::runner::{run_scene, MethodChoice, RunParams, Trajectory};
use dcr_scenes::scene::{name_matches, SceneDesc};
use plotters::prelude::*;

use super::SceneTruth;

/// One method's outcomes on a scene.
#[derive(Clone, Debug)]
pub struct MethodOutcome {
    /// What it is (`modal, 20 modes`, `★ table`, …).
    pub label: String,
    /// Outcomes: name → (value, unit).
    pub outcomes: BTreeMap<String, (f64, String)>,
    /// Kinetic energy the responses gave the props (J, the world's account; the reference: the
    /// work of the elastic surface's motion on the props).
    pub delivered_j: f64,
    /// Largest Δv (m/s, along the normal) given to each body: the response events' for the
    /// methods, the elastic surface's upward speed under the body's contacts for the reference.
    pub delta_v: BTreeMap<String, f64>,
    /// Trajectory at the scene's h.
    pub trajectory: Trajectory,
}

/// A scene's reference and methods.
pub struct SceneComparison {
    /// The reference.
    pub truth: SceneTruth,
    /// The methods (the rigid scene with the response off first).
    pub methods: Vec<MethodOutcome>,
    /// The scene.
    pub desc: SceneDesc,
}

/// Runs the scene's methods at gain 1 over the reference's length: the response off (rigid),
/// modal 20 modes, the transfer table (★, when the object has transfer settings) and spatial
/// attenuation (the object's settings, else C = 1, β = 1).
///
/// # Errors
/// A failed run or bake.
pub fn compare_scene(
    desc: &SceneDesc,
    root: &Path,
    truth: SceneTruth,
    progress: bool,
) -> Result<SceneComparison> {
    let mut methods = vec![MethodOutcome {
        label: "coupled reference".into(),
        outcomes: truth.run.outcomes.clone(),
        delivered_j: truth.run.delivered.values().sum(),
        delta_v: truth.run.surface_speed.clone(),
        trajectory: truth.run.trajectory.clone(),
    }];
    // The ★ table over the object's upward faces (as docs/accuracy.md builds it) where the
    // scene names no transfer settings.
    let mut desc = desc.clone();
    for e in &mut desc.elastic {
        if e.transfer.is_none() {
            e.transfer = Some(serde_json::from_value(
                serde_json::json!({"up": [0.0, 1.0, 0.0]}),
            )?);
        }
    }
    let desc = &desc;
    let mut runs: Vec<(&str, bool, MethodChoice)> = vec![
        ("rigid (response off)", false, MethodChoice::Modal),
        ("modal, 20 modes (Eq. 9–13)", true, MethodChoice::Modal),
    ];
    runs.push(("★ transfer table", true, MethodChoice::Transfer));
    runs.push(("attenuation (Eq. 14–16)", true, MethodChoice::Attenuation));
    for (label, on, method) in runs {
        if progress {
            eprintln!("[scene-truth] {}: {label}", desc.name);
        }
        let mut p = RunParams::new(root.to_path_buf(), on);
        p.seconds = Some(truth.seconds);
        p.gain = Some(1.0);
        p.method = method;
        let r = run_scene(desc, &p).with_context(|| format!("{}: {label}", desc.name))?;
        methods.push(MethodOutcome {
            label: label.to_string(),
            outcomes: r.outcomes,
            delivered_j: r.injected_ke,
            delta_v: if on {
                r.received
                    .iter()
                    .map(|(k, v)| (k.clone(), v.max_delta_v))
                    .collect()
            } else {
                BTreeMap::new()
            },
            trajectory: r.trajectory,
        });
    }
    Ok(SceneComparison {
        truth,
        methods,
        desc: desc.clone(),
    })
}

/// Largest instantaneous lift (mm) over the bodies matching `pattern` at each row.
fn lift_series(traj: &Trajectory, pattern: &str) -> Vec<(f64, f64)> {
    let bodies: Vec<usize> = (0..traj.names.len())
        .filter(|&b| name_matches(pattern, &traj.names[b]))
        .collect();
    (0..traj.rows())
        .map(|k| {
            let l = bodies
                .iter()
                .map(|&b| (traj.pos(k, b)[1] - traj.pos(0, b)[1]) * 1e3)
                .fold(f64::NEG_INFINITY, f64::max);
            (traj.time[k], l)
        })
        .collect()
}

/// The lift over time of the first `max_lift` outcome's bodies, one line per method (SVG).
fn lift_svg(c: &SceneComparison) -> Result<Option<String>> {
    let Some(o) = c.desc.outcomes.iter().find(|o| o.kind == "max_lift") else {
        return Ok(None);
    };
    let series: Vec<(String, Vec<(f64, f64)>)> = c
        .methods
        .iter()
        .map(|m| (m.label.clone(), lift_series(&m.trajectory, &o.bodies)))
        .collect();
    let tmax = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p.0))
        .fold(0.0, f64::max);
    let ymax = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p.1))
        .fold(0.1, f64::max)
        * 1.1;
    let ymin = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p.1))
        .fold(0.0, f64::min)
        .max(-ymax);
    let mut svg = String::new();
    {
        let draw = |svg: &mut String| -> Result<(), Box<dyn std::error::Error>> {
            let root = SVGBackend::with_string(svg, (760, 420)).into_drawing_area();
            root.fill(&WHITE)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(
                    format!(
                        "{}: largest {} lift over time (gain 1)",
                        c.desc.name, o.bodies
                    ),
                    ("sans-serif", 18),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..tmax.max(1e-3), ymin..ymax)?;
            chart
                .configure_mesh()
                .x_desc("t (s)")
                .y_desc("lift (mm)")
                .draw()?;
            let colors = [BLACK, RGBColor(150, 150, 150), RED, BLUE, GREEN, MAGENTA];
            for (i, (label, pts)) in series.iter().enumerate() {
                let col = colors[i % colors.len()];
                let w = if i == 0 { 3 } else { 1 };
                chart
                    .draw_series(LineSeries::new(pts.clone(), col.stroke_width(w)))?
                    .label(label.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(w))
                    });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()?;
            root.present()?;
            Ok(())
        };
        draw(&mut svg).map_err(|e| anyhow::anyhow!("drawing the lift plot: {e}"))?;
    }
    Ok(Some(svg))
}

fn fmt(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// The error of `v` against the reference `r` (%), or the absolute difference when the
/// reference is near zero.
fn err(v: f64, r: f64, unit: &str) -> String {
    if r.abs() < 0.01 {
        format!("{:+} {unit}", fmt(v - r))
    } else {
        format!("{:+.0} %", 100.0 * (v - r) / r)
    }
}

/// Writes `OUT/outcomes.md` and `OUT/outcomes/SCENE_lift.svg` for `scenes`. `header` goes
/// under the title (the command, date and load).
///
/// # Errors
/// A file cannot be written.
pub fn write_outcomes_page(out: &Path, scenes: &[SceneComparison], header: &str) -> Result<()> {
    let dir = out.join("outcomes");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut md = String::new();
    writeln!(
        md,
        "# Outcomes: the distant response vs a coupled elastic–rigid reference\n"
    )?;
    writeln!(md, "{header}\n")?;
    md.push_str(PAGE_INTRO);
    for c in scenes {
        let t = &c.truth;
        writeln!(md, "\n## {}\n", c.desc.name)?;
        writeln!(md, "{}\n", c.desc.description)?;
        writeln!(
            md,
            "- reference: {} free dofs, every one of its {} elastic modes (dense eigensolve {:.0} s; ~0 s: read from the cache), \
             {:.2} s simulated, penalty k = {:.1e} N/m per point (largest penetration {:.3} mm)",
            t.free_dofs,
            t.modes_available,
            t.eigen_s,
            t.seconds,
            t.params.contact_stiffness,
            t.run.max_penetration * 1e3
        )?;
        let steps: Vec<String> = t
            .levels
            .iter()
            .map(|l| match l.change {
                Some(ch) => format!("{:.2e} s ({:.2} %, {:.0} s)", l.dt, 100.0 * ch, l.wall_s),
                None => format!("{:.2e} s ({:.0} s)", l.dt, l.wall_s),
            })
            .collect();
        writeln!(
            md,
            "- steps (largest outcome change from the previous step, wall time): {}",
            steps.join(", ")
        )?;
        if let Some(h) = &t.double_k {
            writeln!(
                md,
                "- stiffness: with k doubled ({:.1e} N/m) at the finest step the outcomes move by {:.2} % ({:.0} s)",
                2.0 * t.params.contact_stiffness,
                100.0 * h.change.unwrap_or(0.0),
                h.wall_s
            )?;
        }
        if let Some(h) = &t.half_modes {
            writeln!(
                md,
                "- modes: with half the modes ({}) at the finest step the outcomes move by {:.2} % ({:.0} s)",
                h.modes,
                100.0 * h.change.unwrap_or(0.0),
                h.wall_s
            )?;
        }
        // Every run of the refinement with its outcomes.
        let onames: Vec<&String> = t.run.outcomes.keys().collect();
        write!(md, "\n| run | Δt (s) | k (N/m) | modes |")?;
        for n in &onames {
            write!(md, " {n} ({}) |", t.run.outcomes[*n].1)?;
        }
        writeln!(md, " change | wall (s) |")?;
        writeln!(
            md,
            "|---|---|---|---|{}---|---|",
            "---|".repeat(onames.len())
        )?;
        let rows = t
            .levels
            .iter()
            .enumerate()
            .map(|(i, l)| (format!("step {}", i + 1), l))
            .chain(t.double_k.iter().map(|l| ("k doubled".to_string(), l)))
            .chain(
                t.half_modes
                    .iter()
                    .map(|l| ("half the modes".to_string(), l)),
            );
        for (name, l) in rows {
            write!(
                md,
                "| {name} | {:.2e} | {:.1e} | {} |",
                l.dt, l.contact_stiffness, l.modes
            )?;
            for n in &onames {
                write!(
                    md,
                    " {} |",
                    l.outcomes.get(*n).map_or("–".into(), |x| fmt(x.0))
                )?;
            }
            writeln!(
                md,
                " {} | {:.0} |",
                l.change
                    .map_or("–".into(), |c| format!("{:.1} %", 100.0 * c)),
                l.wall_s
            )?;
        }
        writeln!(md)?;
        writeln!(
            md,
            "- **{}** at Δt = {:.2e} s, estimated error {:.2} % (tolerance {:.0} %)\n",
            if t.converged && t.estimated_error() < t.params.tolerance {
                "converged"
            } else {
                "NOT converged"
            },
            t.levels.last().map_or(f64::NAN, |l| l.dt),
            100.0 * t.estimated_error(),
            100.0 * t.params.tolerance
        )?;
        // The table: one row per outcome, reference then each method with its error.
        let names: Vec<&String> = c.methods[0].outcomes.keys().collect();
        write!(md, "| outcome |")?;
        for m in &c.methods {
            write!(md, " {} |", m.label)?;
        }
        writeln!(md)?;
        write!(md, "|---|")?;
        for _ in &c.methods {
            write!(md, "---|")?;
        }
        writeln!(md)?;
        for n in names {
            let (r, unit) = &c.methods[0].outcomes[n];
            write!(md, "| {n} ({unit}) | **{}** |", fmt(*r))?;
            for m in &c.methods[1..] {
                let v = m.outcomes.get(n).map_or(0.0, |x| x.0);
                write!(md, " {} ({}) |", fmt(v), err(v, *r, unit))?;
            }
            writeln!(md)?;
        }
        write!(md, "| energy delivered to the props (J) |")?;
        for m in &c.methods {
            write!(md, " {} |", fmt(m.delivered_j))?;
        }
        writeln!(md)?;
        // Δv per outcome's bodies: the largest over the matching bodies.
        let mut patterns: Vec<&str> = c.desc.outcomes.iter().map(|o| o.bodies.as_str()).collect();
        patterns.dedup();
        for pat in patterns {
            write!(md, "| largest Δv, {pat} (m/s) |")?;
            for m in &c.methods {
                let v = m
                    .delta_v
                    .iter()
                    .filter(|(k, _)| name_matches(pat, k))
                    .map(|(_, v)| *v)
                    .fold(0.0, f64::max);
                write!(md, " {} |", fmt(v))?;
            }
            writeln!(md)?;
        }
        if let Some(svg) = lift_svg(c)? {
            let file = format!("{}_lift.svg", c.desc.name);
            write_atomic(&dir.join(&file), svg.as_bytes())
                .map_err(|e| anyhow::anyhow!("writing {file}: {e}"))?;
            writeln!(md, "\n![lift over time](outcomes/{file})")?;
        }
    }
    write_atomic(&out.join("outcomes.md"), md.as_bytes())
        .map_err(|e| anyhow::anyhow!("writing outcomes.md: {e}"))?;
    Ok(())
}

const PAGE_INTRO: &str = "\
Every figure in `docs/accuracy.md` compares one quantity — the peak displacement under a \
contact over one step — with the full-order truth. This page compares what a user sees: the \
scene's outcome figures (`docs/scenes.md`) under a **coupled reference**, in which the elastic \
object is a linear elastic body (every elastic mode of its mesh, integrated exactly) moving \
under the contacts of the rigid bodies of the same rapier scene, and the props are pushed by \
the moving surface (penalty contacts at a small step; `dcr_lab::scene_truth` has the model and \
why). Beside it: the rigid scene (response off) and the distant response at gain 1 (the \
paper's Eq. 12 unscaled) with 20 modes, with the transfer table (★, the peak of every mode) and \
with spatial attenuation (the scene's settings). Errors are against the reference (absolute \
differences where the reference is near zero). Energy delivered: for the methods the kinetic \
energy the responses gave the props (the world's account); for the reference the work the \
elastic surface's motion did on them (largest running sum per prop, summed). Largest Δv: for the methods the largest response velocity change given to the bodies (Eq. 12, 17–18, after gain and Gauss–Seidel); for the reference the largest upward speed of the elastic surface under the bodies' contacts while they touch — the quantity Δv = peak/h stands for.
";
