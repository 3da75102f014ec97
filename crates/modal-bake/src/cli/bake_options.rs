//! The options a base was baked with, rebuilt from what it records (`meta.bake_params`: the
//! parameters, `selection`, `meshing`, `transfer`): what `info` prints as the `check` command
//! that finds the base up to date (and the `bake` command that makes it again) — so a base
//! found on a farm, or made by `--target-error`, says how to check it.

use dcr_runtime::format::ModesFile;
use modal_bake::bake::{option_number as num, BakeParams, ModeRequest, ModesPrecision};

/// The options of a base, and what it does not record (a `--fixed-near` file's name: the
/// base keeps its points).
pub struct BakeOptionsOf {
    /// The options, one shell word each (quoted where the shell needs it).
    pub args: Vec<String>,
    /// What must be added by hand, in words.
    pub missing: Vec<String>,
}

/// The options `base` was baked with.
///
/// # Errors
/// A record this tool does not read (`meta.bake_params` not a bake's, e.g. written elsewhere).
pub fn bake_options_of(base: &ModesFile) -> Result<BakeOptionsOf, String> {
    let record = &base.meta.bake_params;
    let p: BakeParams = serde_json::from_value(record.clone())
        .map_err(|e| format!("its recorded parameters do not read as a bake's: {e}"))?;
    let mut args: Vec<String> = Vec::new();
    let mut push = |option: &str, value: String| push_option(&mut args, option, &value);
    push("--youngs", num(p.material.youngs));
    push("--poisson", num(p.material.poisson));
    push("--density", num(p.material.density));
    match p.modes {
        ModeRequest::Count(n) => push("--modes", n.to_string()),
        ModeRequest::MaxFreqHz(f) => push("--max-freq", num(f)),
    }
    for g in &p.fixed {
        push("--fixed", g.clone());
    }
    for b in &p.fixed_below {
        push("--fixed-below", b.to_string());
    }
    for b in &p.fixed_boxes {
        push("--fixed-box", join(b));
    }
    let mut missing = Vec::new();
    if !p.fixed_near.is_empty() {
        for n in &p.fixed_near {
            missing.push(format!(
                "--fixed-near FILE.obj (the base records its {} points and {} faces, not the file)",
                n.points.len(),
                n.triangles.len()
            ));
        }
        if let Some(d) = p.fixed_near.iter().find_map(|n| n.distance) {
            push("--fixed-near-distance", num(d));
        }
    }
    push("--rayleigh", join(&p.rayleigh));
    if p.lumped {
        push("--lumped", String::new());
    }
    if p.precision == ModesPrecision::F32 {
        push("--f32", String::new());
    }
    let get = |v: &serde_json::Value, k: &str| v.get(k).cloned().unwrap_or_default();
    let empty = serde_json::Map::new();
    let as_map = |k: &str| record.get(k).and_then(|v| v.as_object()).unwrap_or(&empty);
    for (option, value) in selection_pairs(as_map("selection")) {
        push(option, value);
    }
    for (option, value) in meshing_pairs(as_map("meshing")) {
        // `auto` is the default.
        if (option, value.as_str()) != ("--mesher", "auto") {
            push(option, value);
        }
    }
    if let Some(t) = record.get("transfer") {
        let value = |v: serde_json::Value| match v {
            serde_json::Value::String(s) => s,
            serde_json::Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), num),
            other => other.to_string(),
        };
        if let Some(h) = get(t, "h").as_f64() {
            push("--transfer-h", num(h));
        }
        push("--transfer-modes", value(get(t, "modes")));
        for r in get(t, "regions").as_array().into_iter().flatten() {
            if let Ok(b) = serde_json::from_value::<[f64; 6]>(r.clone()) {
                push("--transfer-region", join(&b));
            }
        }
        if let Ok(u) = serde_json::from_value::<[f64; 3]>(get(t, "up")) {
            push("--transfer-up", join(&u));
        }
        match get(t, "oversample").as_f64() {
            Some(k) if k != 1.0 => push("--transfer-oversample", num(k)),
            _ => {}
        }
        push("--transfer-order", value(get(t, "order")));
    }
    Ok(BakeOptionsOf { args, missing })
}

/// A recorded `selection` (`meta.bake_params.selection`) as (option, value) pairs, a flag's
/// value empty: `--object`, `--piece`, `--straighten`, and `--units` other than metres.
pub fn selection_pairs(
    selection: &serde_json::Map<String, serde_json::Value>,
) -> Vec<(&'static str, String)> {
    let mut pairs = Vec::new();
    if let Some(o) = selection.get("object").and_then(|v| v.as_str()) {
        pairs.push(("--object", o.to_string()));
    }
    if let Some(n) = selection.get("piece").and_then(serde_json::Value::as_u64) {
        pairs.push(("--piece", n.to_string()));
    }
    if selection
        .get("straighten")
        .and_then(serde_json::Value::as_bool)
        == Some(true)
    {
        pairs.push(("--straighten", String::new()));
    }
    match selection.get("units").and_then(|v| v.as_str()) {
        Some(u) if u != "m" => pairs.push(("--units", u.to_string())),
        _ => {}
    }
    pairs
}

/// A recorded `meshing` (`meta.bake_params.meshing`) as (option, value) pairs: `--mesher`
/// (always), `--size` and `--envelope` when not the default, `--order`, and the flags
/// `--keep-surface`, `--uniform-size`, `--no-thickness-sizing` when set.
pub fn meshing_pairs(
    meshing: &serde_json::Map<String, serde_json::Value>,
) -> Vec<(&'static str, String)> {
    let mut pairs = Vec::new();
    let number = |k: &str| meshing.get(k).and_then(serde_json::Value::as_f64);
    if let Some(m) = meshing.get("mesher").and_then(|v| v.as_str()) {
        pairs.push(("--mesher", m.to_string()));
    }
    if let Some(s) = number("size") {
        pairs.push(("--size", num(s)));
    }
    if let Some(o) = meshing.get("order").and_then(serde_json::Value::as_u64) {
        pairs.push(("--order", o.to_string()));
    }
    if let Some(e) = number("envelope") {
        pairs.push(("--envelope", num(e)));
    }
    for (key, flag, when) in [
        ("keep_surface", "--keep-surface", true),
        ("uniform_size", "--uniform-size", true),
        ("thickness_sizing", "--no-thickness-sizing", false),
    ] {
        if meshing.get(key).and_then(serde_json::Value::as_bool) == Some(when) {
            pairs.push((flag, String::new()));
        }
    }
    pairs
}

/// (option, value) pairs as one line of shell words (`--piece 2 --units mm`).
pub fn options_line(pairs: Vec<(&'static str, String)>) -> String {
    let mut words = Vec::new();
    for (option, value) in pairs {
        push_option(&mut words, option, &value);
    }
    words.join(" ")
}

/// Appends `option` and its `value` (none for a flag's empty value) as shell words; a value
/// starting with `-` is joined to its option (`--fixed-below=y=-0.01`), which no parser can
/// mistake for another option.
fn push_option(words: &mut Vec<String>, option: &str, value: &str) {
    if value.starts_with('-') {
        words.push(shell_word(&format!("{option}={value}")));
    } else {
        words.push(option.to_string());
        if !value.is_empty() {
            words.push(shell_word(value));
        }
    }
}

/// Numbers joined by commas, as a list option is typed (`0,0,1`).
fn join(values: &[f64]) -> String {
    values.iter().map(|&x| num(x)).collect::<Vec<_>>().join(",")
}

/// `s` as one POSIX shell word: as it is when it holds only safe characters, else in single
/// quotes.
fn shell_word(s: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "._,=+-/:@%".contains(c);
    if !s.is_empty() && s.chars().all(safe) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::shell_word;

    #[test]
    fn words_are_quoted_only_when_the_shell_needs_it() {
        assert_eq!(shell_word("y=0.01"), "y=0.01");
        assert_eq!(shell_word("-1.5,0,2e-3"), "-1.5,0,2e-3");
        assert_eq!(shell_word("My surface"), "'My surface'");
        assert_eq!(shell_word("it's"), r"'it'\''s'");
        assert_eq!(shell_word(""), "''");
    }
}
