//! The batch manifest: a JSON or TOML file listing the bases to bake, read and checked whole
//! before any work.
//!
//! ```json
//! {
//!   "version": 1,
//!   "entries": [
//!     {"mesh": "meshes/chair.obj", "out": "bases/chair.modes",
//!      "options": {"material": "oak", "modes": 30, "size": 0.01}},
//!     {"mesh": "meshes/beam.msh", "out": "bases/beam.modes",
//!      "options": {"fixed": ["left"], "rayleigh": [10, 1e-7], "fixed-box": [[0,0,0,0.1,1,1]]}}
//!   ]
//! }
//! ```
//!
//! The TOML form is the same tree (`version = 1`, `[[entries]]`, `[entries.options]`). Paths
//! are relative to the manifest's folder. `options` holds `modal-bake bake` options by their
//! long names without `--`: a string or number is the option's value, `true` a flag, an
//! array of numbers one comma-separated value (`rayleigh`, `fixed-box`), any other array a
//! repeated option (`fixed`, `fixed-box` as an array of boxes). The options are parsed by the
//! same argument definitions as `bake`, then checked as `bake` checks them.
//!
//! Refused before anything is baked, naming the file, the entry and the field: a file over
//! [`MAX_MANIFEST_BYTES`] or not a regular file, unknown or duplicate keys, missing `mesh` or
//! `out`, more than [`MAX_ENTRIES`] entries, an option `bake` would refuse, a mesh that is not
//! a regular file, and outputs that are an input (a mesh, the manifest), a device, a FIFO, a
//! folder, or another entry's output.

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use clap::{CommandFactory, FromArgMatches, Parser};
use modal_bake::bake::BakeParams;
use modal_bake::mesh::surface::is_surface_asset;
use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

use crate::cli::bake::BakeArgs;
use crate::cli::budget::BudgetOptions;

/// The largest manifest read (bytes): 16 MiB, tens of thousands of entries.
pub const MAX_MANIFEST_BYTES: u64 = 16 << 20;

/// The most entries a manifest may list.
pub const MAX_ENTRIES: usize = 100_000;

/// The manifest format version this tool reads.
pub const MANIFEST_VERSION: u64 = 1;

/// One base to bake: where its mesh is, where the base goes, and the `bake` arguments.
pub struct Entry {
    /// 0-based position in the manifest (`entries[index]`).
    pub index: usize,
    /// The `bake` arguments of the entry (mesh and output resolved against the manifest's
    /// folder; the budget is the batch's).
    pub args: BakeArgs,
}

/// A manifest value as written, keeping the order of keys and refusing duplicate keys (a
/// JSON object may repeat a key, which a plain map would silently resolve to the last).
#[derive(Debug)]
enum Value {
    Null,
    Bool(bool),
    /// A number, as text that parses back to it.
    Number(String),
    String(String),
    Array(Vec<Value>),
    Map(Vec<(String, Value)>),
}

impl Value {
    fn kind(&self) -> &'static str {
        match self {
            Value::Null => "null",
            Value::Bool(_) => "a boolean",
            Value::Number(_) => "a number",
            Value::String(_) => "a string",
            Value::Array(_) => "an array",
            Value::Map(_) => "a table",
        }
    }
}

struct ValueVisitor;

impl<'de> Visitor<'de> for ValueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a manifest value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Number(v.to_string()))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Number(v.to_string()))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        // The shortest decimal that parses back to `v` (10.0 → `10`, 1e-7 → `0.0000001`).
        Ok(Value::Number(format!("{v}")))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        Value::deserialize(d)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut items = Vec::new();
        while let Some(v) = seq.next_element()? {
            items.push(v);
        }
        Ok(Value::Array(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut items: Vec<(String, Value)> = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if items.iter().any(|(k, _)| *k == key) {
                return Err(de::Error::custom(format!(
                    "the key `{key}` appears twice in one table"
                )));
            }
            let value = map.next_value()?;
            items.push((key, value));
        }
        Ok(Value::Map(items))
    }
}

impl<'de> Deserialize<'de> for Value {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Value, D::Error> {
        d.deserialize_any(ValueVisitor)
    }
}

/// Takes the fields of a table, refusing keys not in `known`.
fn fields(value: Value, at: &str, known: &[&str]) -> anyhow::Result<Vec<(String, Value)>> {
    let Value::Map(items) = value else {
        bail!("{at} must be a table ({{...}}), not {}", value.kind());
    };
    if let Some((key, _)) = items.iter().find(|(k, _)| !known.contains(&k.as_str())) {
        bail!(
            "{at}: unknown key `{key}` (the keys are {})",
            known
                .iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(items)
}

fn take(items: &mut Vec<(String, Value)>, key: &str) -> Option<Value> {
    let i = items.iter().position(|(k, _)| k == key)?;
    Some(items.remove(i).1)
}

/// Reads the manifest's bytes: a regular file of at most [`MAX_MANIFEST_BYTES`].
fn read_text(path: &Path) -> anyhow::Result<String> {
    let (file, len) = dcr_runtime::format::open_regular_file(path)
        .map_err(|e| anyhow!("manifest {}: {e}", path.display()))?;
    if len > MAX_MANIFEST_BYTES {
        bail!(
            "manifest {}: {len} bytes is more than the {} MiB a manifest may hold; split it into several manifests",
            path.display(),
            MAX_MANIFEST_BYTES >> 20
        );
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(MAX_MANIFEST_BYTES + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("manifest {}", path.display()))?;
    if bytes.len() as u64 > MAX_MANIFEST_BYTES {
        bail!(
            "manifest {}: grew past {} MiB while being read",
            path.display(),
            MAX_MANIFEST_BYTES >> 20
        );
    }
    String::from_utf8(bytes).map_err(|e| {
        anyhow!(
            "manifest {}: not UTF-8 text (invalid byte at offset {}); write it as UTF-8 JSON or TOML",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}

/// Parses the manifest text: TOML for a `.toml` file, JSON otherwise.
fn parse_text(path: &Path, text: &str) -> anyhow::Result<Value> {
    let toml = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    if toml {
        toml::from_str::<Value>(text).map_err(|e| {
            anyhow!(
                "manifest {}: not valid TOML: {}",
                path.display(),
                e.to_string().trim().replace('\n', " ")
            )
        })
    } else {
        serde_json::from_str::<Value>(text).map_err(|e| {
            anyhow!(
                "manifest {}: not valid JSON: {e} (a .toml file is read as TOML)",
                path.display()
            )
        })
    }
}

/// The arguments of one entry as `bake` would take them.
#[derive(Parser)]
#[command(
    name = "options",
    no_binary_name = true,
    disable_help_flag = true,
    disable_version_flag = true
)]
struct EntryCli {
    #[command(flatten)]
    bake: BakeArgs,
}

/// Option names an entry may not set, and why.
fn forbidden(key: &str) -> Option<&'static str> {
    Some(match key {
        "out" | "o" => "give the output as the entry's `out` field",
        "json" | "timings" => {
            "the batch reports each entry in its own JSON report (--json, --report)"
        }
        "target-error" => {
            "not supported in a batch; bake such a base with `modal-bake bake --target-error`"
        }
        "max-memory" | "max-time" | "force" => {
            "the budget is the batch's: give it on the `modal-bake batch` command line"
        }
        _ => return None,
    })
}

/// The `bake` options an entry may set (long names).
fn allowed_options() -> Vec<String> {
    EntryCli::command()
        .get_arguments()
        .filter_map(|a| a.get_long())
        .filter(|l| forbidden(l).is_none())
        .map(str::to_string)
        .collect()
}

/// One option value as command-line text.
fn scalar(v: &Value) -> Option<String> {
    match v {
        Value::Number(t) | Value::String(t) => Some(t.clone()),
        _ => None,
    }
}

/// Numbers joined by commas (`[10, 1e-7]` → `1e1,1e-7`), or `None` if not all numbers.
fn number_list(items: &[Value]) -> Option<String> {
    items
        .iter()
        .map(|v| match v {
            Value::Number(t) => Some(t.clone()),
            _ => None,
        })
        .collect::<Option<Vec<_>>>()
        .map(|v| v.join(","))
}

/// The command-line arguments of an entry's `options` table.
fn option_args(options: Value, at: &str, allowed: &[String]) -> anyhow::Result<Vec<String>> {
    let Value::Map(items) = options else {
        bail!(
            "{at} must be a table of bake options, not {}",
            options.kind()
        );
    };
    let mut argv = Vec::new();
    for (key, value) in items {
        let field = format!("{at}.{key}");
        if let Some(why) = forbidden(&key) {
            bail!("{field}: not an option of a batch entry: {why}");
        }
        if !allowed.contains(&key) {
            let near = allowed
                .iter()
                .find(|a| a.replace('-', "_") == key.replace('-', "_").to_lowercase())
                .map_or_else(String::new, |a| format!("; did you mean `{a}`?"));
            bail!(
                "{field}: unknown bake option{near} (the options are {})",
                allowed.join(", ")
            );
        }
        match &value {
            Value::Bool(true) => argv.push(format!("--{key}")),
            Value::Bool(false) => {}
            Value::Number(_) | Value::String(_) => {
                argv.push(format!("--{key}={}", scalar(&value).unwrap_or_default()))
            }
            Value::Array(items) if items.is_empty() => {
                bail!("{field}: an empty array; leave the key out for the default")
            }
            Value::Array(items) => match number_list(items) {
                Some(list) => argv.push(format!("--{key}={list}")),
                None => {
                    for (j, item) in items.iter().enumerate() {
                        let text = match item {
                            Value::Array(inner) => number_list(inner),
                            other => scalar(other),
                        }
                        .ok_or_else(|| {
                            anyhow!(
                                "{field}[{j}]: {} is not a value (a string, a number, or an array of numbers)",
                                item.kind()
                            )
                        })?;
                        argv.push(format!("--{key}={text}"));
                    }
                }
            },
            Value::Null => bail!("{field}: null; leave the key out for the default"),
            Value::Map(_) => bail!(
                "{field}: a table is not an option value (a string, a number, true, or an array)"
            ),
        }
    }
    Ok(argv)
}

/// clap's message for a refused entry: its first lines without usage and help hints, and the
/// option it names.
fn clap_message(e: &clap::Error) -> (Option<String>, String) {
    let key = match e.get(clap::error::ContextKind::InvalidArg) {
        Some(clap::error::ContextValue::String(s)) => s
            .strip_prefix("--")
            .map(|s| s.split([' ', '=']).next().unwrap_or(s).to_string()),
        _ => None,
    };
    let text = e.to_string();
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty())
        .collect();
    let mut msg = String::new();
    for l in lines {
        if !msg.is_empty() {
            msg.push_str(if msg.ends_with(':') { " " } else { "; " });
        }
        msg.push_str(l);
    }
    let msg = msg.strip_prefix("error: ").unwrap_or(&msg).to_string();
    (key, msg)
}

/// Reads and checks the manifest at `path` (see the module docs): every entry, whichever
/// shard it falls in, and every output against every input and each other; `report` is the
/// batch's own output (checked with the others). `budget` becomes every entry's budget.
///
/// # Errors
/// The first problem, naming the file, `entries[i]` and the field.
pub fn read_manifest(
    path: &Path,
    budget: &BudgetOptions,
    report: Option<&Path>,
) -> anyhow::Result<Vec<Entry>> {
    let file = path.display().to_string();
    let text = read_text(path)?;
    let top = parse_text(path, &text)?;
    let mut items = fields(
        top,
        &format!("{file}: the manifest"),
        &["version", "entries"],
    )?;
    match take(&mut items, "version") {
        None => {}
        Some(Value::Number(v)) if v == MANIFEST_VERSION.to_string() => {}
        Some(v) => bail!(
            "{file}: version: {} is not a manifest version this modal-bake reads (it reads version {MANIFEST_VERSION})",
            match &v {
                Value::Number(t) | Value::String(t) => t.clone(),
                other => other.kind().to_string(),
            }
        ),
    }
    let entries = match take(&mut items, "entries") {
        Some(Value::Array(e)) => e,
        Some(other) => bail!(
            "{file}: entries must be an array of tables, not {}",
            other.kind()
        ),
        None => {
            bail!("{file}: no `entries` (an array of {{\"mesh\", \"out\", \"options\"}} tables)")
        }
    };
    if entries.is_empty() {
        bail!("{file}: entries is empty; list at least one base to bake");
    }
    if entries.len() > MAX_ENTRIES {
        bail!(
            "{file}: {} entries is more than the {MAX_ENTRIES} a manifest may list; split it into several manifests",
            entries.len()
        );
    }
    // Entry paths are relative to the manifest's folder (`Path::join` keeps absolute ones).
    let dir = path.parent().unwrap_or(Path::new(""));
    let allowed = allowed_options();
    let mut cmd = EntryCli::command();
    let mut out = Vec::with_capacity(entries.len());
    for (index, value) in entries.into_iter().enumerate() {
        let at = format!("entries[{index}]");
        let entry = read_entry(value, &at, dir, &allowed, &mut cmd)
            .map_err(|e| anyhow!("{file}: {}", super::super::one_line(&e)))?;
        out.push(Entry {
            index,
            args: BakeArgs {
                budget: budget.clone(),
                ..entry
            },
        });
    }
    // Outputs against inputs and each other, before anything is written.
    let mut plan = dcr_files::OutputPlan::new();
    plan.input("the manifest", path);
    for e in &out {
        plan.input(&format!("the mesh of entries[{}]", e.index), &e.args.mesh);
    }
    for e in &out {
        plan.output(&format!("entries[{}].out", e.index), &e.args.out)
            .map_err(|err| anyhow!("{file}: {err}"))?;
    }
    if let Some(r) = report {
        plan.output("--report", r)?;
    }
    Ok(out)
}

/// One entry's `bake` arguments (budget at its default; the caller sets the batch's).
fn read_entry(
    value: Value,
    at: &str,
    dir: &Path,
    allowed: &[String],
    cmd: &mut clap::Command,
) -> anyhow::Result<BakeArgs> {
    let mut items = fields(value, at, &["mesh", "out", "options"])?;
    let path_field =
        |items: &mut Vec<(String, Value)>, key: &str, what: &str| match take(items, key) {
            // Rebuilt from its components: `/` in a manifest is the platform's separator in
            // the paths the batch shows (Windows: `C:\farm\bases\chair.modes`).
            Some(Value::String(s)) if !s.is_empty() => {
                Ok(dir.join(Path::new(&s).components().collect::<PathBuf>()))
            }
            Some(Value::String(_)) => bail!("{at}.{key} is empty; give the path of {what}"),
            Some(other) => bail!(
                "{at}.{key} must be a string (the path of {what}), not {}",
                other.kind()
            ),
            None => bail!("{at}: no `{key}` (the path of {what})"),
        };
    let mesh: PathBuf = path_field(&mut items, "mesh", "the mesh or surface asset")?;
    let out: PathBuf = path_field(&mut items, "out", "the .modes base to write")?;
    let options = take(&mut items, "options").unwrap_or(Value::Map(Vec::new()));
    match std::fs::metadata(&mesh) {
        Ok(m) if m.is_file() => {}
        Ok(m) => bail!(
            "{at}.mesh {} is {}, not a mesh file",
            mesh.display(),
            dcr_files::describe_file_type(m.file_type())
        ),
        Err(e) => bail!("{at}.mesh {}: {e}", mesh.display()),
    }
    let mut argv = option_args(options, &format!("{at}.options"), allowed)?;
    argv.push(format!("--out={}", out.display()));
    argv.push("--".into());
    let mut os: Vec<std::ffi::OsString> = argv.into_iter().map(Into::into).collect();
    os.push(mesh.clone().into_os_string());
    let refused = |e: clap::Error| {
        let (key, msg) = clap_message(&e);
        match key {
            Some(k) => anyhow!("{at}.options.{k}: {msg}"),
            None => anyhow!("{at}.options: {msg}"),
        }
    };
    let matches = cmd.try_get_matches_from_mut(os).map_err(refused)?;
    let cli = EntryCli::from_arg_matches(&matches).map_err(refused)?;
    let mut args = cli.bake;
    // `--out=` took the display form; keep the exact path.
    args.out = out;
    check_entry(&args).map_err(|e| anyhow!("{at}.options: {}", super::super::one_line(&e)))?;
    Ok(args)
}

/// The checks `bake` makes on its options before reading the mesh.
fn check_entry(args: &BakeArgs) -> anyhow::Result<()> {
    args.options.model.check_ranges()?;
    let params = BakeParams {
        transfer: args.transfer.params(),
        ..args.options.params()
    };
    params.check()?;
    if let Some(tp) = &params.transfer {
        tp.check()?;
    }
    if is_surface_asset(&args.mesh) {
        args.asset.params()?;
    } else if args.asset.any_meshing_set() {
        bail!(
            "mesher, size, order, envelope, gmsh, ftetwild, keep-surface, uniform-size and mesher-timeout apply to surface assets (.obj, .stl, .ply, .glb, .gltf), not to the volume mesh {}",
            args.mesh.display()
        );
    } else if args.asset.object.is_some() && modal_bake::mesh::is_json(&args.mesh) {
        bail!(
            "object selects an object of a surface asset or a physical volume of a gmsh .msh, not of the meshio JSON mesh {} (piece selects one of its connected pieces)",
            args.mesh.display()
        );
    }
    Ok(())
}
