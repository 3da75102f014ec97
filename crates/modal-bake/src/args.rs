//! Command-line argument groups and value parsers shared by the `modal-bake` binary and the
//! `dcr-lab` tools (clap derive), so that an option means the same in every tool.

use clap::Args;

use crate::bake::MaterialSi;
use crate::full_order::SystemParams;

/// The object's material, boundary conditions and damping (shared by `modal-bake bake`
/// and `check`, and `dcr-lab truth` and `fit-attenuation`).
#[derive(Args, Clone, Debug)]
pub struct ModelOptions {
    /// Young's modulus E (Pa).
    #[arg(long, value_name = "PA", default_value_t = 1.1e9)]
    pub youngs: f64,
    /// Poisson ratio ν (−1 < ν < 0.5).
    #[arg(long, value_name = "NU", default_value_t = 0.3)]
    pub poisson: f64,
    /// Density ρ (kg/m³).
    #[arg(long, value_name = "KG_M3", default_value_t = 770.0)]
    pub density: f64,
    /// Fix every node of this named physical group (repeatable). Nothing fixed: free-free (the
    /// six rigid-body modes, or the rigid-body part of a response, are excluded).
    #[arg(long, value_name = "NAME")]
    pub fixed: Vec<String>,
    /// Rayleigh damping: α0 (1/s), α1 (s); `bake` stores it as the base's default.
    #[arg(long, value_name = "A0,A1", value_parser = pair, default_value = "10,1e-7")]
    pub rayleigh: [f64; 2],
    /// Lumped (diagonal) mass instead of the consistent mass.
    #[arg(long)]
    pub lumped: bool,
}

impl ModelOptions {
    /// Refuses a Young's modulus or density outside the supported ranges, naming the option,
    /// and warns (stderr) about values that look like a unit mistake.
    ///
    /// # Errors
    /// A one-line message naming `--youngs` or `--density` and the range that works.
    pub fn check_ranges(&self) -> anyhow::Result<()> {
        use crate::fem::Material;
        let [elo, ehi] = Material::YOUNGS_RANGE;
        if !(self.youngs >= elo && self.youngs <= ehi) {
            anyhow::bail!(
                "--youngs {:e} Pa is outside the supported {elo:e} … {ehi:e} Pa (foams ~1e5, polymers ~1e9, steel 2e11)",
                self.youngs
            );
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            anyhow::bail!(
                "--poisson {} must satisfy −1 < ν < 0.5 (rubber ~0.49, metals ~0.3, cork ~0)",
                self.poisson
            );
        }
        let [dlo, dhi] = Material::DENSITY_RANGE;
        if !(self.density >= dlo && self.density <= dhi) {
            anyhow::bail!(
                "--density {:e} kg/m³ is outside the supported {dlo} … {dhi:e} kg/m³ (aerogel ~2, wood ~700, steel 7850)",
                self.density
            );
        }
        if self.youngs < 1e5 {
            eprintln!(
                "warning: --youngs {} Pa is softer than any solid object (plausible: 1e5 Pa foam … 1.2e12 Pa diamond); \
                 the unit is Pa: did you mean {} GPa = {:e} Pa or {} MPa = {:e} Pa?",
                self.youngs,
                self.youngs,
                self.youngs * 1e9,
                self.youngs,
                self.youngs * 1e6
            );
        }
        if self.density < 100.0 {
            eprintln!(
                "warning: --density {} kg/m³ is lighter than solids other than foams and aerogels (plausible: 100 … 22600 kg/m³); \
                 the unit is kg/m³: did you mean {} g/cm³ = {} kg/m³?",
                self.density,
                self.density,
                self.density * 1000.0
            );
        }
        Ok(())
    }

    /// The material in SI units.
    pub fn material(&self) -> MaterialSi {
        MaterialSi {
            youngs: self.youngs,
            poisson: self.poisson,
            density: self.density,
        }
    }

    /// The full-order system these options describe (material, fixed groups, damping, mass).
    pub fn system(&self) -> SystemParams {
        SystemParams {
            material: self.material(),
            fixed: self.fixed.clone(),
            rayleigh: self.rayleigh,
            lumped: self.lumped,
        }
    }
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
