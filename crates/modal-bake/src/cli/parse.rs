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
