//! dcr in a released C++ physics engine: `examples/bullet_dinner.cpp` runs the dinner scene in
//! Bullet (Debian's `libbullet-dev`, found with `pkg-config bullet`) with the table's base from
//! `data/scenes/table.msh`, through the header-only adapter
//! `integrations/bullet/dcr_bullet.hpp` over the C ABI, and the plates lift by what the
//! response asked:
//! - without the response nothing lifts and nothing is sent; with it the plates jump, every
//!   contact maps onto the base and the responses inject no more energy than the pot's impact
//!   dissipated;
//! - each plate leaving the table rises as high as free flight from the velocity the response's
//!   events gave it (Bullet's own integrator), to 1 %: Bullet's contact solver keeps the push;
//! - the support compensation is what makes that true: it adds g·h to a plate that leaves, and
//!   without it (`--no-support`) the same plates rise at most 80 % as high (28–56 % here: the
//!   loss, g·h of the push, matters most for the small ones);
//! - with the adapter's own tick callback (its default) the run is the same as through the
//!   program's;
//! - stepped as a game steps, `stepSimulation(1/60 s, 16, 10 ms)`, the adapter runs in every
//!   substep and the outcome is bit-identical to one `stepSimulation(10 ms, 0)` per step;
//! - a Bullet step other than the world's h (5 ms against 10 ms) is re-derived once
//!   (`h_changes` 1) and the support compensation follows it (g · 5 ms);
//! - a table body whose frame is 0.5 m above the mesh's (shapes shifted down, as in a
//!   centre-of-mass frame) gives the same lift when the adapter is told where the mesh's frame
//!   is, and no response, every contact unmapped, when it is not;
//! - a dynamic table (a base baked without fixed nodes) sliding 1.5 m across a frictionless
//!   floor keeps every contact mapped: the adapter follows its pose every step;
//! - the adapter's minimum approach speed (2 g h) leaves out the points Bullet re-creates
//!   under the sliding legs (fewer than 60 % of the events without it) and nothing of the
//!   pot's impact on the static table (the same outcome without it);
//! - removing the table's elastic object mid-run (`World::remove`) stops its responses: none
//!   when removed before the pot lands, only the landing step's when removed after it (also
//!   under AddressSanitizer), and a second removal finds nothing.
//!
//! `tests/c/bullet_alloc.cpp` checks that the adapter's step allocates nothing once its buffers
//! have grown. The program is built with `-Wall -Wextra -Werror -pedantic` against the static library and
//! run once more linked to the shared library under AddressSanitizer (no leak, no invalid
//! access); the first checks are repeated with Bullet built for double precision
//! (`pkg-config bullet-float64`). Without Bullet the test skips with the command that installs it, and fails instead
//! under `DCR_REQUIRE_BULLET=1` (as CI sets it).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{asan_env, assert_clean, crate_dir, cxx, modal_bake, run_ok, shared_lib, static_lib};
use common::{workspace, NATIVE_LIBS};

/// Gravity (m/s²) and step (s) of the example.
const G: f64 = 9.81;
const H: f64 = 0.01;

/// `pkg-config --cflags --libs PACKAGE` (`bullet`: float `btScalar`; `bullet-float64`: double,
/// both in Debian's `libbullet-dev`), split into compiler and linker flags; `None` (after
/// saying how to install it) when Bullet is missing and `DCR_REQUIRE_BULLET` is not 1.
fn bullet_flags(package: &str) -> Option<(Vec<String>, Vec<String>)> {
    let o = Command::new("pkg-config")
        .args(["--cflags", "--libs", package])
        .output();
    let flags = match o {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).into_owned(),
        _ => {
            let msg = format!(
                "Bullet is not installed (`pkg-config --cflags --libs {package}` failed): \
                 `apt-get install libbullet-dev pkg-config` (.ci/run installs them)"
            );
            assert!(
                std::env::var("DCR_REQUIRE_BULLET").as_deref() != Ok("1"),
                "{msg}"
            );
            eprintln!("SKIP: {msg}");
            return None;
        }
    };
    let (mut cflags, mut libs) = (Vec::new(), Vec::new());
    for f in flags.split_whitespace() {
        if let Some(dir) = f.strip_prefix("-I") {
            // Bullet's headers as system headers: -Werror covers the example, not Bullet.
            cflags.extend(["-isystem".to_string(), dir.to_string()]);
        } else if f.starts_with("-l") || f.starts_with("-L") {
            libs.push(f.to_string());
        } else {
            cflags.push(f.to_string());
        }
    }
    Some((cflags, libs))
}

/// Builds the example into `out`: statically linked, or linked to the shared library under
/// AddressSanitizer.
fn build(out: &Path, bullet: &(Vec<String>, Vec<String>), sanitize: bool) {
    build_source(
        &crate_dir().join("examples/bullet_dinner.cpp"),
        out,
        bullet,
        sanitize,
    );
}

/// Builds the C++ program `src` into `out` as [`build`] does.
fn build_source(src: &Path, out: &Path, bullet: &(Vec<String>, Vec<String>), sanitize: bool) {
    let mut cmd = Command::new(cxx());
    cmd.args(["-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg("-I")
        .arg(crate_dir().join("include"))
        .arg("-I")
        .arg(crate_dir().join("integrations/bullet"))
        .args(&bullet.0)
        .arg(src)
        .arg("-o")
        .arg(out);
    if sanitize {
        let dir = shared_lib().parent().unwrap().to_path_buf();
        cmd.args(["-O1", "-g", "-fsanitize=address", "-fno-omit-frame-pointer"])
            .arg("-L")
            .arg(&dir)
            .arg("-ldcr_capi")
            .arg(format!("-Wl,-rpath,{}", dir.display()))
            .args(&bullet.1);
    } else {
        cmd.arg("-O2")
            .arg(static_lib())
            .args(&bullet.1)
            .args(NATIVE_LIBS);
    }
    run_ok(&mut cmd);
}

/// The dinner table's base (the scene's material, 20 modes, feet fixed, or none fixed when
/// `free`) baked into `dir`.
fn bake_table(dir: &Path, free: bool) -> PathBuf {
    let out = dir.join(if free { "free.modes" } else { "table.modes" });
    run_ok(
        Command::new(modal_bake())
            .arg("bake")
            .arg(workspace().join("data/scenes/table.msh"))
            .arg("-o")
            .arg(&out)
            .args(["--youngs", "1.1e9", "--poisson", "0.3", "--density", "770"])
            .args(["--modes", "20", "--rayleigh", "10,1e-7"])
            .args(if free {
                &[][..]
            } else {
                &["--fixed", "feet"][..]
            }),
    );
    out
}

/// Runs `bin` on `base` with `args`; returns its JSON output.
fn run(bin: &Path, base: &Path, args: &[&str], sanitized: bool) -> serde_json::Value {
    let mut cmd = Command::new(bin);
    cmd.arg(base).args(args).env_remove("LD_LIBRARY_PATH");
    if sanitized {
        asan_env(&mut cmd);
    }
    let o = cmd.output().unwrap();
    assert_clean(&o, "bullet_dinner");
    assert!(
        o.status.success(),
        "bullet_dinner failed ({}): {}",
        o.status,
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "bullet_dinner's output is not JSON ({e}): {}",
            String::from_utf8_lossy(&o.stdout)
        )
    })
}

/// Each plate's first launch: `(plate, asked, support, rise, ballistic)` (m/s, m/s, mm, mm).
fn first_launches(outcome: &serde_json::Value) -> Vec<(u64, f64, f64, f64, f64)> {
    let mut seen = Vec::new();
    let mut out = Vec::new();
    for l in outcome["launches"].as_array().expect("launches") {
        let plate = l["plate"].as_u64().unwrap();
        if seen.contains(&plate) {
            continue;
        }
        seen.push(plate);
        let f = |k: &str| l[k].as_f64().unwrap_or_else(|| panic!("launch field {k}"));
        out.push((
            plate,
            f("asked_mps"),
            f("support_mps"),
            f("rise_mm"),
            f("ballistic_mm"),
        ));
    }
    out
}

/// The checks of one run's output `v` (with and without the response) that hold for every
/// Bullet build; `support_tol` is the relative tolerance of the support compensation against
/// g·h. Returns the plates' first launches.
fn plates_lift_as_asked(v: &serde_json::Value, support_tol: f64) -> Vec<(u64, f64, f64, f64, f64)> {
    let (on, off) = (&v["on"], &v["off"]);

    // Without the response: the plates rest (Bullet settles them without a jump).
    assert!(off["lift_mm"].as_f64().unwrap() < 0.01, "off: {off}");
    assert_eq!(off["events"], 0);

    // With it: the plates jump, every contact mapped, passive.
    let lift = on["lift_mm"].as_f64().unwrap();
    assert!((1.0..50.0).contains(&lift), "on: lift {lift} mm: {on}");
    assert!(on["plate_events"].as_u64().unwrap() > 0, "{on}");
    assert_eq!(on["unmapped"], 0, "contacts off the base: {on}");
    let (injected, dissipated) = (
        on["injected_J"].as_f64().unwrap(),
        on["dissipated_J"].as_f64().unwrap(),
    );
    assert!(
        injected > 0.0 && injected <= dissipated,
        "injected {injected} J, dissipated {dissipated} J"
    );

    // Each plate that leaves rises as free flight from what the response asked for.
    let launches = first_launches(on);
    assert!(launches.len() >= 4, "plates launched: {launches:?}");
    for &(plate, asked, support, rise, ballistic) in &launches {
        assert!(asked > 0.0, "plate {plate}: asked {asked} m/s");
        assert!(
            (support - G * H).abs() < support_tol * G * H,
            "plate {plate}: support compensation {support} m/s, not g·h = {} m/s",
            G * H
        );
        assert!(
            (rise - ballistic).abs() <= 0.01 * ballistic + 1e-3,
            "plate {plate}: rose {rise} mm, free flight from {asked} m/s gives {ballistic} mm"
        );
    }
    launches
}

#[test]
fn bullet_plates_lift_by_what_the_response_asked() {
    let Some(bullet) = bullet_flags("bullet") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let base = bake_table(dir.path(), false);
    let bin = dir.path().join("bullet_dinner");
    build(&bin, &bullet, false);
    let v = run(&bin, &base, &[], false);
    assert!(v["engine"].as_str().unwrap().ends_with("(float)"), "{v}");
    let (on, off) = (&v["on"], &v["off"]);
    let lift = on["lift_mm"].as_f64().unwrap();
    // Bullet's gravity is a float: 9.81 to 1e-7.
    let launches = plates_lift_as_asked(&v, 1e-6);

    // Without the support compensation the same pushes lift the plates at most 80 % as high.
    let bare = run(&bin, &base, &["--no-support"], false);
    let bare_launches = first_launches(&bare["on"]);
    for &(plate, _, _, rise, ballistic) in &launches {
        let (_, _, support, bare_rise, _) = bare_launches
            .iter()
            .copied()
            .find(|l| l.0 == plate)
            .unwrap_or_else(|| panic!("plate {plate} did not leave without the compensation"));
        assert_eq!(support, 0.0);
        assert!(
            bare_rise < 0.8 * rise,
            "plate {plate}: {bare_rise} mm without the compensation, {rise} mm with it \
             ({ballistic} mm asked)"
        );
    }

    // dcr_bullet's own tick callback (its default) instead of the program's: the same run.
    let installed = run(&bin, &base, &["--installed-callback"], false);
    for key in ["lift_mm", "events", "plate_events", "injected_J"] {
        assert_eq!(
            installed["on"][key], on[key],
            "{key} with the installed callback"
        );
    }
    assert_eq!(
        first_launches(&installed["on"]).len(),
        launches.len(),
        "{installed}"
    );

    // Stepped at 60 frames a second with 10 ms substeps: bit-identical.
    let framed = run(&bin, &base, &["--frame-dt", "0.0166666667"], false);
    assert_eq!(framed["on"], *on, "frames of 1/60 s with substeps");
    assert_eq!(framed["off"], *off);
    assert_eq!(on["h_changes"], 0);

    // Bullet at 5 ms against the world's 10 ms: re-derived once, the support follows h.
    let fine = run(
        &bin,
        &base,
        &["--fixed-dt", "0.005", "--steps", "300"],
        false,
    );
    assert_eq!(fine["on"]["h_changes"], 1, "{fine}");
    let fine_launches = first_launches(&fine["on"]);
    assert!(!fine_launches.is_empty(), "{fine}");
    for &(plate, _, support, _, _) in &fine_launches {
        assert!(
            (support - G * 0.005).abs() < 1e-6 * G * 0.005,
            "plate {plate}: support {support} m/s at h = 5 ms"
        );
    }

    // The table's body frame 0.5 m above the mesh's: the same outcome when the adapter is told.
    let shifted = run(&bin, &base, &["--table-origin", "0.5"], false);
    let lift_shifted = shifted["on"]["lift_mm"].as_f64().unwrap();
    assert!(
        (lift_shifted - lift).abs() <= 1e-6 * lift && shifted["on"]["unmapped"] == 0,
        "{lift_shifted} mm with the body frame shifted, {lift} mm without: {shifted}"
    );
    let wrong = run(
        &bin,
        &base,
        &["--table-origin", "0.5", "--ignore-origin"],
        false,
    );
    assert!(
        wrong["on"]["unmapped"].as_u64().unwrap() > 0 && wrong["on"]["plate_events"] == 0,
        "a base in the wrong frame: {wrong}"
    );

    // A dynamic table sliding at 1 m/s for 1.5 s: its pose is followed, every contact mapped.
    let free = bake_table(dir.path(), true);
    let sliding = run(
        &bin,
        &free,
        &["--moving-table", "1", "--table-origin", "0.6"],
        false,
    );
    let moved = sliding["on"]["table_moved_m"].as_f64().unwrap();
    assert!(
        (moved - 1.5).abs() < 0.05,
        "the table moved {moved} m: {sliding}"
    );
    assert_eq!(sliding["on"]["unmapped"], 0, "{sliding}");
    assert!(
        sliding["on"]["lift_mm"].as_f64().unwrap() > 1.0,
        "{sliding}"
    );
    let any_speed = run(
        &bin,
        &free,
        &[
            "--moving-table",
            "1",
            "--table-origin",
            "0.6",
            "--min-approach",
            "1e-9",
        ],
        false,
    );
    let (with, without) = (
        sliding["on"]["events"].as_f64().unwrap(),
        any_speed["on"]["events"].as_f64().unwrap(),
    );
    assert!(
        with < 0.6 * without,
        "{with} events with the minimum approach speed, {without} without"
    );
    let static_any = run(&bin, &base, &["--min-approach", "1e-9"], false);
    assert_eq!(static_any["on"], *on, "the pot's impact is fast");

    // The same run linked to the shared library under AddressSanitizer: the same outcome.
    let asan = dir.path().join("bullet_dinner_asan");
    build(&asan, &bullet, true);
    let va = run(&asan, &base, &[], true);
    assert_eq!(va["on"], *on, "static and shared (sanitized) builds");

    // The table's elastic object removed before the pot lands (step 10) and after (step 21).
    let early = run(&bin, &base, &["--remove-at", "10"], false);
    assert_eq!(early["on"]["removed"], true, "{early}");
    assert_eq!(early["on"]["events"], 0, "{early}");
    assert!(early["on"]["lift_mm"].as_f64().unwrap() < 0.01, "{early}");
    let late = run(&asan, &base, &["--remove-at", "21"], true);
    assert_eq!(late["on"]["removed"], true, "{late}");
    let (late_events, all_events) = (
        late["on"]["events"].as_u64().unwrap(),
        on["events"].as_u64().unwrap(),
    );
    assert!(
        late_events > 0 && late_events < all_events,
        "{late_events} events removed after the landing, {all_events} kept"
    );

    // The same with Bullet built for double precision (its normals under a tilted plate are
    // not exactly vertical, so the support, g_n h along n, is within 1 % of g h).
    let Some(bullet64) = bullet_flags("bullet-float64") else {
        return;
    };
    let bin64 = dir.path().join("bullet_dinner64");
    build(&bin64, &bullet64, false);
    let v64 = run(&bin64, &base, &[], false);
    assert!(
        v64["engine"].as_str().unwrap().ends_with("(double)"),
        "{v64}"
    );
    plates_lift_as_asked(&v64, 1e-2);
}

/// `tests/c/bullet_alloc.cpp`: once the first drop has grown its buffers, `World::tick`
/// allocates nothing (a counting global `operator new`) over four more drops with responses.
#[test]
fn bullet_adapter_allocates_nothing_after_warm_up() {
    let Some(bullet) = bullet_flags("bullet") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let base = bake_table(dir.path(), false);
    let bin = dir.path().join("bullet_alloc");
    build_source(
        &crate_dir().join("tests/c/bullet_alloc.cpp"),
        &bin,
        &bullet,
        false,
    );
    let o = Command::new(&bin)
        .arg(&base)
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("allocations after warm-up 0"),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Usage and load errors exit with their documented codes and say what is wrong.
#[test]
fn bullet_example_reports_bad_arguments() {
    let Some(bullet) = bullet_flags("bullet") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bullet_dinner");
    build(&bin, &bullet, false);
    let missing = dir.path().join("missing.modes");
    let cases: [(Vec<&str>, i32, &str); 3] = [
        (vec![missing.to_str().unwrap()], 1, "missing.modes"),
        (
            vec![missing.to_str().unwrap(), "--steps", "x"],
            2,
            "--steps",
        ),
        (vec![], 2, "usage"),
    ];
    for (args, code, needle) in cases {
        let o = Command::new(&bin).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: `{needle}` not in `{err}`");
        assert!(o.stdout.is_empty(), "{args:?}: printed results");
    }
}
