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
    // A value starting with `-` is joined to its option (`--fixed-below=y=-0.01`), which no
    // parser can mistake for another option.
    let mut push = |option: &str, value: String| {
        if value.starts_with('-') {
            args.push(shell_word(&format!("{option}={value}")));
        } else {
            args.push(option.to_string());
            if !value.is_empty() {
                args.push(shell_word(&value));
            }
        }
    };
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
    if let Some(sel) = record.get("selection") {
        if let Some(o) = get(sel, "object").as_str() {
            push("--object", o.to_string());
        }
        if let Some(n) = get(sel, "piece").as_u64() {
            push("--piece", n.to_string());
        }
        if get(sel, "straighten").as_bool() == Some(true) {
            push("--straighten", String::new());
        }
        match get(sel, "units").as_str() {
            Some(u) if u != "m" => push("--units", u.to_string()),
            _ => {}
        }
    }
    if let Some(m) = record.get("meshing") {
        match get(m, "mesher").as_str() {
            Some(x) if x != "auto" => push("--mesher", x.to_string()),
            _ => {}
        }
        if let Some(s) = get(m, "size").as_f64() {
            push("--size", num(s));
        }
        if let Some(o) = get(m, "order").as_u64() {
            push("--order", o.to_string());
        }
        if let Some(e) = get(m, "envelope").as_f64() {
            push("--envelope", num(e));
        }
        for (key, flag, when) in [
            ("keep_surface", "--keep-surface", true),
            ("uniform_size", "--uniform-size", true),
            ("thickness_sizing", "--no-thickness-sizing", false),
        ] {
            if get(m, key).as_bool() == Some(when) {
                push(flag, String::new());
            }
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
