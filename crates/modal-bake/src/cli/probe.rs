//! `modal-bake probe`: one impact on a baked `.modes` base, the distant response at given
//! contact points (paper §4.2–4.4), printed as a table or JSON.
//!
//! Conventions: the impulse (N·s) acts at t = 0 at `--impact`, along `--direction` or by
//! default into the surface (−normal at the impact). Normals are area-weighted vertex normals
//! interpolated with the barycentric weights and normalised (outward). The peak is
//! max |nᵀu| over t = k·h/S, k = 1..S, S = ⌈h/T⌉ (relative tolerance 1e-9); Δv = peak/h.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{bail, Context};
use dcr_runtime::model::SurfacePoint;
use dcr_runtime::response::{AttenuationParams, Impact, RestingContact, Sampling, Variant};
use dcr_runtime::{DistantResponse, Method, ModalModel, ResponseParams};

/// Distant-response model selectable from the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Modal IIR filters (Eq. 9–13).
    Modal,
    /// Spatial attenuation over heat geodesics (Eq. 14–16; s = r^-1 for r > 1 m, 1 closer).
    Attenuation,
    /// The base's bake-time peak-transfer table (`bake --transfer-h`), modal where it does not
    /// apply (no table, another h or damping, a point outside its region).
    Transfer,
}

/// Peak variant selectable from the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VariantArg {
    /// Peak of the contact's interpolated row (default).
    PerContact,
    /// Eq. 13: barycentric blend of per-vertex peaks.
    PerNode,
}

/// Arguments of `modal-bake probe`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    after_help = "Distant response at contact points to one impact on a .modes base.\n\n\
        Conventions: the impulse (N·s) acts at t = 0 at --impact, along --direction or by default \
        into the surface (−normal at the impact); any impulse > 0 is applied (no threshold). Points \
        are in the base's object frame (m) and must lie within 5% of the bounding-box diagonal of \
        the surface. Normals are area-weighted vertex normals interpolated with the barycentric \
        weights and normalised (outward). Peak = max |nᵀu| over t = k·h/S, k = 1..S, S = ⌈h/T⌉ \
        (relative tolerance 1e-9), T = π/(2 ω_max) unless --substep/--oversample; Δv = peak/h (m/s). \
        distance_m is the heat-method geodesic distance from the impact (m)."
)]
pub struct ProbeArgs {
    /// The `.modes` file.
    pub file: PathBuf,
    /// Impact point X,Y,Z (m, object frame).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub impact: [f64; 3],
    /// Impulse magnitude (N·s, > 0).
    #[arg(long)]
    pub impulse: f64,
    /// Direction DX,DY,DZ the impulse acts on the object (normalised); default −normal.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub direction: Option<[f64; 3]>,
    /// Contact point X,Y,Z (m); repeat for several contacts.
    #[arg(long = "contact", value_parser = parse_vec3, required = true, allow_hyphen_values = true)]
    pub contacts: Vec<[f64; 3]>,
    /// Rigid-body time step h (s).
    #[arg(long, default_value_t = 0.01)]
    pub h: f64,
    /// Filter period T (s) instead of π/(2 ω_max).
    #[arg(long, conflicts_with = "oversample")]
    pub substep: Option<f64>,
    /// Oversampling factor K: T = π/(2 ω_max)/K.
    #[arg(long)]
    pub oversample: Option<f64>,
    /// Response model (default: the base's transfer table where it applies, else modal).
    #[arg(long, value_enum, default_value_t = MethodArg::Transfer)]
    pub method: MethodArg,
    /// Peak variant (modal method).
    #[arg(long, value_enum, default_value_t = VariantArg::PerContact)]
    pub variant: VariantArg,
    /// Rayleigh damping A0,A1 (1/s, s) instead of the base's.
    #[arg(long, value_parser = parse_vec2)]
    pub rayleigh: Option<[f64; 2]>,
    /// Print JSON: {"contacts": [{"point", "triangle", "bary", "distance_m",
    /// "peak_displacement_m", "delta_v_mps"}, ...]}.
    #[arg(long)]
    pub json: bool,
}

fn parse_floats<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != N {
        return Err(format!("expected {N} comma-separated numbers, got `{s}`"));
    }
    let mut out = [0.0; N];
    for (o, p) in out.iter_mut().zip(&parts) {
        *o = p.parse::<f64>().map_err(|e| format!("`{p}`: {e}"))?;
        if !o.is_finite() {
            return Err(format!("`{p}` is not finite"));
        }
    }
    Ok(out)
}

/// Parses `X,Y,Z`.
pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    parse_floats::<3>(s)
}

/// Parses `A,B`.
pub fn parse_vec2(s: &str) -> Result<[f64; 2], String> {
    parse_floats::<2>(s)
}

/// `d` scaled to unit length, for any finite non-zero `d`: scaled by its largest component
/// first, so that neither 1e308 nor 1e-320 components overflow or underflow the length.
fn unit_direction(d: [f64; 3]) -> Option<[f64; 3]> {
    let big = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(big > 0.0 && big.is_finite()) {
        return None;
    }
    let s = d.map(|x| x / big);
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    Some(s.map(|x| x / n))
}

/// Runs `modal-bake probe`.
///
/// # Errors
/// Unreadable or invalid file, invalid parameters, or an impact/contact point too far from the
/// surface (one-line messages).
pub fn run(args: &ProbeArgs) -> anyhow::Result<()> {
    if !(args.impulse.is_finite() && args.impulse > 0.0) {
        bail!(
            "--impulse must be a finite number > 0 (N·s), got {}",
            args.impulse
        );
    }
    // LoadError messages already name the file and the cause: one line, no repeated chain.
    let model = ModalModel::load(&args.file).map_err(|e| anyhow::anyhow!("{e}"))?;
    let sampling = match (args.substep, args.oversample) {
        (Some(t), _) => Sampling::Substep(t),
        (None, Some(k)) => {
            if !(k >= 1.0 && k.is_finite()) {
                bail!("--oversample must be ≥ 1, got {k}");
            }
            Sampling::Oversample(k)
        }
        (None, None) => Sampling::PaperT,
    };
    let method = match args.method {
        MethodArg::Modal => Method::Modal,
        MethodArg::Attenuation => Method::Attenuation(AttenuationParams::default()),
        MethodArg::Transfer => Method::Transfer,
    };
    let params = ResponseParams {
        h: args.h,
        sampling,
        rayleigh: args.rayleigh,
        impact_threshold: 0.0,
        variant: match args.variant {
            VariantArg::PerContact => Variant::PerContact,
            VariantArg::PerNode => Variant::PerNode,
        },
        method,
        ..Default::default()
    };
    let mut resp = DistantResponse::new(Arc::clone(&model), params)
        .with_context(|| format!("{}: invalid parameters", args.file.display()))?;
    let max_map = resp.max_map_distance();
    let impact_sp = model.project(args.impact, max_map).with_context(|| {
        format!(
            "impact point {:?} is farther than {max_map:.4} m from the surface",
            args.impact
        )
    })?;
    let direction = match args.direction {
        Some(d) => unit_direction(d).with_context(|| {
            format!("--direction {d:?} must be a non-zero vector (any finite length)")
        })?,
        None => impact_sp.normal.map(|x| 0.0 - x),
    };
    let mut mapped: Vec<SurfacePoint> = Vec::with_capacity(args.contacts.len());
    for (i, c) in args.contacts.iter().enumerate() {
        let sp = model.project(*c, max_map).with_context(|| {
            format!(
                "contact {} at {c:?} is farther than {max_map:.4} m from the surface",
                i + 1
            )
        })?;
        mapped.push(sp);
    }
    let heat = model
        .heat_geodesic()
        .map_err(|e| anyhow::anyhow!("{}: heat geodesics: {e}", args.file.display()))?;
    let mut field = vec![0.0; model.num_vertices()];
    heat.distances_from_point(&impact_sp, &mut field);
    let resting: Vec<RestingContact> = args
        .contacts
        .iter()
        .enumerate()
        .map(|(i, &p)| RestingContact {
            id: i as u64,
            point: p,
        })
        .collect();
    let impact = Impact {
        point: args.impact,
        direction,
        impulse: args.impulse,
    };
    let out = resp.step(&[impact], &resting).to_vec();
    let rows: Vec<serde_json::Value> = out
        .iter()
        .zip(&mapped)
        .map(|(o, sp)| {
            let d = model.interpolate(&field, sp);
            serde_json::json!({
                "point": sp.point,
                "triangle": sp.triangle,
                "bary": sp.bary,
                "distance_m": d,
                "peak_displacement_m": o.peak_displacement,
                "delta_v_mps": o.delta_v,
                "served_by": o.served_by.name(),
            })
        })
        .collect();
    if args.json {
        outln!("{}", serde_json::json!({ "contacts": rows }));
    } else {
        outln!(
            "{}: {} modes, S = {} samples per step, T = {:.4e} s, impulse {} N·s along {:?}",
            args.file.display(),
            model.num_modes(),
            resp.samples_per_step(),
            resp.substep(),
            args.impulse,
            direction
        );
        outln!(
            "{:>3} {:>8} {:>26} {:>12} {:>14} {:>12}  served_by",
            "#",
            "triangle",
            "bary",
            "distance_m",
            "peak_disp_m",
            "delta_v_mps"
        );
        for (i, r) in rows.iter().enumerate() {
            let b = &r["bary"];
            outln!(
                "{:>3} {:>8} {:>8.5},{:>8.5},{:>8.5} {:>12.5e} {:>14.5e} {:>12.5e}  {}",
                i + 1,
                r["triangle"],
                b[0].as_f64().unwrap_or(0.0),
                b[1].as_f64().unwrap_or(0.0),
                b[2].as_f64().unwrap_or(0.0),
                r["distance_m"].as_f64().unwrap_or(0.0),
                r["peak_displacement_m"].as_f64().unwrap_or(0.0),
                r["delta_v_mps"].as_f64().unwrap_or(0.0),
                r["served_by"].as_str().unwrap_or("?"),
            );
        }
    }
    Ok(())
}
