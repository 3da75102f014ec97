//! Command-line argument groups and value parsers shared by the `modal-bake` binary and the
//! `dcr-lab` tools (clap derive), so that an option means the same in every tool.

use clap::Args;

use crate::bake::{FixedBelow, FixedNear, MaterialSi};
use crate::fem::MaterialPreset;
use crate::full_order::SystemParams;

/// The object's material, boundary conditions (fixed nodes) and damping (shared by
/// `modal-bake bake` and `check`, and `dcr-lab truth` and `fit-attenuation`).
#[derive(Args, Clone, Debug)]
pub struct ModelOptions {
    /// Material preset: oak, pine, steel, aluminium, brass, cast-iron, glass, ceramic,
    /// concrete, stone, marble, abs, pla, acrylic (typical values and their sources:
    /// docs/artist-guide.md). --youngs, --poisson and --density given with it replace its values.
    /// Without a preset or all three values, 1.1e9 Pa, 0.3, 770 kg/m³ fill in, with a warning.
    #[arg(long, value_name = "NAME", value_parser = preset)]
    pub material: Option<&'static MaterialPreset>,
    /// Young's modulus E (Pa) [default: the --material's, else 1.1e9].
    #[arg(long, value_name = "PA")]
    pub youngs: Option<f64>,
    /// Poisson ratio ν (−1 < ν < 0.5) [default: the --material's, else 0.3].
    #[arg(long, value_name = "NU")]
    pub poisson: Option<f64>,
    /// Density ρ (kg/m³) [default: the --material's, else 770].
    #[arg(long, value_name = "KG_M3")]
    pub density: Option<f64>,
    /// Fix every node of this named physical group (repeatable). Nothing fixed: free-free (the
    /// six rigid-body modes, or the rigid-body part of a response, are excluded).
    #[arg(long, value_name = "NAME")]
    pub fixed: Vec<String>,
    /// Fix every node at or below a coordinate, e.g. `y=0.01` (m, object frame; repeatable;
    /// combines with --fixed and --fixed-box). A selector that fixes no node is an error.
    #[arg(long, value_name = "AXIS=VALUE", value_parser = axis_value, allow_hyphen_values = true)]
    pub fixed_below: Vec<FixedBelow>,
    /// Fix every node inside a box X0,Y0,Z0,X1,Y1,Z1 (m, object frame, bounds included;
    /// repeatable; combines with --fixed and --fixed-below).
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = aabb, allow_hyphen_values = true)]
    pub fixed_box: Vec<[f64; 6]>,
    /// Fix every node within --fixed-near-distance of the points and faces in an OBJ file
    /// (`v x y z` lines in m, object frame; optional `f` faces), e.g. a vertex group's
    /// vertices and faces: exactly the region they cover (repeatable; combines with the other
    /// selectors). The mid-edge node of an edge whose two ends are fixed is fixed too.
    #[arg(long, value_name = "FILE.obj", value_parser = fixed_near)]
    pub fixed_near: Vec<FixedNear>,
    /// Distance (m) for --fixed-near [default: 1/200 of the mesh's bounding-box diagonal].
    #[arg(long, value_name = "M", requires = "fixed_near")]
    pub fixed_near_distance: Option<f64>,
    /// Rayleigh damping: α0 (1/s), α1 (s); `bake` stores it as the base's default.
    #[arg(long, value_name = "A0,A1", value_parser = pair, default_value = "10,1e-7")]
    pub rayleigh: [f64; 2],
    /// Lumped (diagonal) mass instead of the consistent mass.
    #[arg(long)]
    pub lumped: bool,
}

/// The material used when neither `--material` nor all of `--youngs`, `--poisson`,
/// `--density` are given: E 1.1e9 Pa, ν 0.3, ρ 770 kg/m³ (the paper's table).
pub const DEFAULT_MATERIAL: MaterialSi = MaterialSi {
    youngs: 1.1e9,
    poisson: 0.3,
    density: 770.0,
};

/// Parses a `--material` name.
fn preset(s: &str) -> Result<&'static MaterialPreset, String> {
    MaterialPreset::find(s).ok_or_else(|| {
        format!(
            "unknown material `{s}`; presets: {} (or give --youngs, --poisson and --density)",
            MaterialPreset::names()
        )
    })
}

/// Where a bake's material came from: a preset, explicit values, or the default.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialChoice {
    /// The `--material` preset, if one was named.
    pub preset: Option<&'static MaterialPreset>,
    /// The values given explicitly (`youngs`, `poisson`, `density`), which win over the preset.
    pub explicit: Vec<&'static str>,
    /// The values taken from [`DEFAULT_MATERIAL`] (neither the preset nor explicit).
    pub defaulted: Vec<&'static str>,
}

impl MaterialChoice {
    /// One phrase for reports: `steel`, `steel with --youngs`, `given (--youngs, --poisson,
    /// --density)`, `default (no --material given)`.
    pub fn describe(&self) -> String {
        let flags = |v: &[&str]| {
            v.iter()
                .map(|s| format!("--{s}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match (
            self.preset,
            self.explicit.is_empty(),
            self.defaulted.is_empty(),
        ) {
            (Some(p), true, _) => p.name.to_string(),
            (Some(p), false, _) => format!("{} with {}", p.name, flags(&self.explicit)),
            (None, _, true) => format!("given ({})", flags(&self.explicit)),
            (None, true, false) => "default (no --material given)".to_string(),
            (None, false, false) => format!(
                "given ({}), default {}",
                flags(&self.explicit),
                flags(&self.defaulted)
            ),
        }
    }

    /// The record stored in a base's `meta.bake_params.material_choice`:
    /// `{"preset": "steel" | null, "explicit": ["youngs", ...], "defaulted": [...]}`.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "preset": self.preset.map(|p| p.name),
            "explicit": self.explicit,
            "defaulted": self.defaulted,
        })
    }
}

impl ModelOptions {
    /// Where each material value comes from.
    pub fn material_choice(&self) -> MaterialChoice {
        let mut explicit = Vec::new();
        let mut defaulted = Vec::new();
        for (name, given) in [
            ("youngs", self.youngs.is_some()),
            ("poisson", self.poisson.is_some()),
            ("density", self.density.is_some()),
        ] {
            if given {
                explicit.push(name);
            } else if self.material.is_none() {
                defaulted.push(name);
            }
        }
        MaterialChoice {
            preset: self.material,
            explicit,
            defaulted,
        }
    }

    /// The warning (one line, no `warning:` prefix) a bake prints when some material value
    /// falls back to [`DEFAULT_MATERIAL`]: it names the values used and how to choose; `None`
    /// when a preset or all three values were given.
    pub fn default_material_warning(&self) -> Option<String> {
        let choice = self.material_choice();
        if choice.defaulted.is_empty() {
            return None;
        }
        let m = self.material();
        Some(format!(
            "no material given ({} not set): using E {:e} Pa, ν {}, ρ {} kg/m³ (the paper's softened wood); \
             name one with --material {} or give --youngs PA --poisson NU --density KG_M3",
            choice
                .defaulted
                .iter()
                .map(|s| format!("--{s}"))
                .collect::<Vec<_>>()
                .join(", "),
            m.youngs,
            m.poisson,
            m.density,
            MaterialPreset::ALL
                .iter()
                .map(|p| p.name)
                .collect::<Vec<_>>()
                .join("|")
        ))
    }

    /// Refuses a Young's modulus or density outside the supported ranges, naming the option,
    /// and warns (stderr) about values that look like a unit mistake.
    ///
    /// # Errors
    /// A one-line message naming `--youngs` or `--density` and the range that works.
    pub fn check_ranges(&self) -> anyhow::Result<()> {
        use crate::fem::Material;
        let MaterialSi {
            youngs,
            poisson,
            density,
        } = self.material();
        let [elo, ehi] = Material::YOUNGS_RANGE;
        if !(youngs >= elo && youngs <= ehi) {
            anyhow::bail!(
                "--youngs {youngs:e} Pa is outside the supported {elo:e} … {ehi:e} Pa (foams ~1e5, polymers ~1e9, steel 2e11)"
            );
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            anyhow::bail!(
                "--poisson {poisson} must satisfy −1 < ν < 0.5 (rubber ~0.49, metals ~0.3, cork ~0)"
            );
        }
        let [dlo, dhi] = Material::DENSITY_RANGE;
        if !(density >= dlo && density <= dhi) {
            anyhow::bail!(
                "--density {density:e} kg/m³ is outside the supported {dlo} … {dhi:e} kg/m³ (aerogel ~2, wood ~700, steel 7850)"
            );
        }
        if youngs < 1e5 {
            eprintln!(
                "warning: --youngs {youngs} Pa is softer than any solid object (plausible: 1e5 Pa foam … 1.2e12 Pa diamond); \
                 the unit is Pa: did you mean {youngs} GPa = {:e} Pa or {youngs} MPa = {:e} Pa?",
                youngs * 1e9,
                youngs * 1e6
            );
        }
        if density < 100.0 {
            eprintln!(
                "warning: --density {density} kg/m³ is lighter than solids other than foams and aerogels (plausible: 100 … 22600 kg/m³); \
                 the unit is kg/m³: did you mean {density} g/cm³ = {} kg/m³?",
                density * 1000.0
            );
        }
        Ok(())
    }

    /// The material in SI units: each of E, ν, ρ given explicitly, else the preset's, else
    /// [`DEFAULT_MATERIAL`]'s.
    pub fn material(&self) -> MaterialSi {
        let p = self.material;
        MaterialSi {
            youngs: self
                .youngs
                .or(p.map(|p| p.youngs))
                .unwrap_or(DEFAULT_MATERIAL.youngs),
            poisson: self
                .poisson
                .or(p.map(|p| p.poisson))
                .unwrap_or(DEFAULT_MATERIAL.poisson),
            density: self
                .density
                .or(p.map(|p| p.density))
                .unwrap_or(DEFAULT_MATERIAL.density),
        }
    }

    /// The `--fixed-near` sets, each with `--fixed-near-distance` when given.
    pub fn fixed_near(&self) -> Vec<FixedNear> {
        self.fixed_near
            .iter()
            .map(|f| FixedNear {
                distance: self.fixed_near_distance.or(f.distance),
                ..f.clone()
            })
            .collect()
    }

    /// The full-order system these options describe (material, every fixed-node selector,
    /// damping, mass).
    pub fn system(&self) -> SystemParams {
        SystemParams {
            material: self.material(),
            fixed: self.fixed.clone(),
            fixed_below: self.fixed_below.clone(),
            fixed_boxes: self.fixed_box.clone(),
            fixed_near: self.fixed_near(),
            rayleigh: self.rayleigh,
            lumped: self.lumped,
        }
    }
}

/// Parses `AXIS=VALUE` (`x`, `y` or `z`, then a finite number in m), e.g. `y=0.01`.
pub fn axis_value(s: &str) -> Result<FixedBelow, String> {
    let Some((axis, value)) = s.split_once('=') else {
        return Err(format!("expected AXIS=VALUE such as `y=0.01`, got `{s}`"));
    };
    let axis = match axis.trim().to_ascii_lowercase().as_str() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        other => return Err(format!("axis `{other}` must be x, y or z (in `{s}`)")),
    };
    match value.trim().parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(FixedBelow { axis, value }),
        _ => Err(format!(
            "`{value}` is not a finite number of metres (in `{s}`)"
        )),
    }
}

/// Reads a `--fixed-near` file (an OBJ of points and optional faces, m).
pub fn fixed_near(s: &str) -> Result<FixedNear, String> {
    FixedNear::read(s.as_ref()).map_err(|e| e.to_string())
}

/// Parses `X,Y,Z` (three finite numbers).
pub fn vec3(s: &str) -> Result<[f64; 3], String> {
    let v = list(s)?;
    match v.as_slice() {
        [x, y, z] => Ok([*x, *y, *z]),
        _ => Err(format!(
            "expected three comma-separated numbers X,Y,Z, got `{s}`"
        )),
    }
}

/// Parses `A,B` (two finite numbers).
pub fn pair(s: &str) -> Result<[f64; 2], String> {
    let v = list(s)?;
    match v.as_slice() {
        [a, b] => Ok([*a, *b]),
        _ => Err(format!(
            "expected two comma-separated numbers A,B, got `{s}`"
        )),
    }
}

/// Parses `XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX` (six finite numbers, min ≤ max per axis).
pub fn aabb(s: &str) -> Result<[f64; 6], String> {
    let v = list(s)?;
    match v.as_slice() {
        [a, b, c, d, e, f] if a <= d && b <= e && c <= f => Ok([*a, *b, *c, *d, *e, *f]),
        [_, _, _, _, _, _] => Err(format!(
            "box `{s}`: each minimum must be ≤ its maximum (XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX)"
        )),
        _ => Err(format!(
            "expected six comma-separated numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX, got `{s}`"
        )),
    }
}

fn list(s: &str) -> Result<Vec<f64>, String> {
    s.split(',')
        .map(|t| {
            let x: f64 = t
                .trim()
                .parse()
                .map_err(|_| format!("`{t}` is not a number"))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("`{t}` is not finite"))
            }
        })
        .collect()
}

/// An error and its causes on one line, each cause once: a cause whose text the line already
/// holds (a wrapper that prints its source, as `path: error` does) is not repeated. The error
/// line of every tool (`modal-bake`, `dcr-lab`, `dcr-scenes`).
pub fn error_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

/// The command line with every `--option -NUMBER` joined into `--option=-NUMBER`, so that a
/// negative number (`-1`, `-1e-5`, a list `-1,0`) given to an option reaches the option's
/// parser and is refused there with the option's range, instead of clap reading it as an
/// unknown flag ("unexpected argument '-1' found"). Only long options without `=` followed by
/// a value of comma-separated numbers starting with `-` are joined; everything else is kept.
///
/// ```
/// let args = ["tool", "run", "--seconds", "-1", "--rayleigh", "-1,0", "--json", "x"];
/// let joined = modal_bake::args::join_negative_values(args.iter().map(Into::into));
/// let joined: Vec<String> = joined.into_iter().map(|s| s.into_string().unwrap()).collect();
/// assert_eq!(joined, ["tool", "run", "--seconds=-1", "--rayleigh=-1,0", "--json", "x"]);
/// ```
pub fn join_negative_values(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let looks_negative = |s: &str| {
        s.starts_with('-')
            && s.split(',').all(|part| {
                let body = part.strip_prefix('-').unwrap_or(part);
                body.starts_with(|c: char| c.is_ascii_digit() || c == '.')
                    && part.parse::<f64>().is_ok()
            })
    };
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    for arg in args {
        let joined = match (out.last().and_then(|p| p.to_str()), arg.to_str()) {
            (Some(prev), Some(value))
                if prev.starts_with("--")
                    && prev.len() > 2
                    && !prev.contains('=')
                    && looks_negative(value) =>
            {
                Some(format!("{prev}={value}"))
            }
            _ => None,
        };
        match joined {
            Some(j) => *out.last_mut().expect("a previous argument") = j.into(),
            None => out.push(arg),
        }
    }
    out
}
