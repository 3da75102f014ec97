//! `include/dcr.h` is what cbindgen generates from this crate today (regenerate it with
//! `DCR_UPDATE_HEADER=1 cargo test --release -p dcr-capi --test header`).

use std::path::Path;

/// The committed header equals cbindgen's output for the current sources and cbindgen.toml.
#[test]
fn header_is_up_to_date() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut fresh = Vec::new();
    bindings.write(&mut fresh);
    let path = dir.join("include/dcr.h");
    if std::env::var_os("DCR_UPDATE_HEADER").is_some() {
        std::fs::write(&path, &fresh).expect("write include/dcr.h");
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    if committed != fresh {
        let (a, b) = (
            String::from_utf8_lossy(&committed),
            String::from_utf8_lossy(&fresh),
        );
        let line = a
            .lines()
            .zip(b.lines())
            .position(|(x, y)| x != y)
            .map_or(a.lines().count().min(b.lines().count()), |i| i);
        panic!(
            "{} is stale (first difference at line {}: committed `{}`, generated `{}`); \
             regenerate it with `DCR_UPDATE_HEADER=1 cargo test --release -p dcr-capi --test header`",
            path.display(),
            line + 1,
            a.lines().nth(line).unwrap_or("<end>"),
            b.lines().nth(line).unwrap_or("<end>"),
        );
    }
}
