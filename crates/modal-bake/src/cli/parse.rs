//! Small value parsers shared by the subcommands (the general ones are defined once in
//! [`modal_bake::args`]).

pub use modal_bake::args::{aabb, vec3};

/// Parses `AXIS=VALUE` (`x`, `y` or `z`, then a finite number in m), e.g. `y=0.01`.
pub fn axis_value(s: &str) -> Result<modal_bake::bake::FixedBelow, String> {
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
        Ok(value) if value.is_finite() => Ok(modal_bake::bake::FixedBelow { axis, value }),
        _ => Err(format!(
            "`{value}` is not a finite number of metres (in `{s}`)"
        )),
    }
}

/// Reads a `--fixed-near` file (an OBJ of points and optional faces, m).
pub fn fixed_near(s: &str) -> Result<modal_bake::bake::FixedNear, String> {
    modal_bake::bake::FixedNear::read(s.as_ref()).map_err(|e| e.to_string())
}
