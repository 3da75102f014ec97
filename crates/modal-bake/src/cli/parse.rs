//! Small value parsers shared by the subcommands.

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
