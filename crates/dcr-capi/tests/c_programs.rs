//! The C examples and test programs, built with `cc` against `include/dcr.h` and the library
//! (static and shared), run plain and under AddressSanitizer with leak detection:
//! - `examples/probe.c` prints what `modal-bake probe --json` reports, to 1e-12 relative;
//! - `examples/world.c` gets from the C world exactly the events the Rust `DcrWorld` gives for
//!   the inputs it printed, and they are the physically expected ones;
//! - `tests/c/error_paths.c` checks every documented error status (missing file, corrupt base,
//!   too-small buffers, NULL, wrong sizes, bad handles) without a leak or invalid access;
//! - the header compiles as C99 and C++17 with `-Wall -Wextra -Werror -pedantic`.
//!
//! These tests fail, never skip, when no C compiler is installed.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{asan_env, assert_clean, bake_cube, build_c, crate_dir, modal_bake, run_ok, Link};
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, ElasticObjectDesc, Method, ModalModel, Pose, WorldParams,
};

fn example(name: &str) -> PathBuf {
    crate_dir().join("examples").join(name)
}

fn test_src(name: &str) -> PathBuf {
    crate_dir().join("tests/c").join(name)
}

fn run(bin: &Path, args: &[&str], sanitized: bool) -> Output {
    let mut cmd = Command::new(bin);
    // cargo test puts target/<profile> (which may hold an older libdcr_capi.so) on
    // LD_LIBRARY_PATH, which outranks the binaries' rpath to the fresh library.
    cmd.args(args).env_remove("LD_LIBRARY_PATH");
    if sanitized {
        asan_env(&mut cmd);
    }
    cmd.output()
        .unwrap_or_else(|e| panic!("{}: {e}", bin.display()))
}

/// Impact and contacts on the unit cube's top face and one on a side face, as CLI strings.
const IMPACT: [&str; 3] = ["0.5", "0.5", "1"];
const IMPULSE: &str = "1.5";
const CONTACTS: [[&str; 3]; 4] = [
    ["0.2", "0.3", "1"],
    ["0.9", "0.9", "1"],
    ["0", "0.5", "0.5"],
    ["0.75", "0.1", "1.0"],
];

fn probe_args(base: &str) -> Vec<String> {
    let mut a = vec![base.to_string()];
    a.extend(IMPACT.iter().map(|s| s.to_string()));
    a.push(IMPULSE.into());
    for c in CONTACTS {
        a.extend(c.iter().map(|s| s.to_string()));
    }
    a
}

/// `(delta_v, peak)` per contact from `modal-bake probe --json` on the same input.
fn modal_bake_probe(base: &Path) -> Vec<(f64, f64)> {
    let mut cmd = Command::new(modal_bake());
    cmd.arg("probe")
        .arg(base)
        .arg("--impact")
        .arg(IMPACT.join(","))
        .arg("--impulse")
        .arg(IMPULSE);
    for c in CONTACTS {
        cmd.arg("--contact").arg(c.join(","));
    }
    cmd.arg("--json");
    let o = run_ok(&mut cmd);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("probe --json output");
    v["contacts"]
        .as_array()
        .expect("contacts array")
        .iter()
        .map(|c| {
            (
                c["delta_v_mps"].as_f64().unwrap(),
                c["peak_displacement_m"].as_f64().unwrap(),
            )
        })
        .collect()
}

fn parse_probe(stdout: &[u8]) -> Vec<(usize, f64, f64)> {
    String::from_utf8_lossy(stdout)
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(f.len(), 3, "probe line `{l}`");
            (
                f[0].parse().unwrap(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
            )
        })
        .collect()
}

fn assert_rel(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol * a.abs().max(b.abs()),
        "{what}: {a:e} vs {b:e} (relative tolerance {tol:e})"
    );
}

/// `probe.c` linked statically and dynamically prints, per contact, the Δv and peak that
/// `modal-bake probe --json` reports for the same impact, to 1e-12 relative (the contacts sit
/// at different distances from the impact, so the values differ by orders of magnitude).
#[test]
fn probe_c_equals_modal_bake_probe_json() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    let want = modal_bake_probe(&base);
    assert_eq!(want.len(), CONTACTS.len());
    assert!(want.iter().all(|&(dv, peak)| dv > 0.0 && peak > 0.0));
    let args = probe_args(base.to_str().unwrap());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    for link in [Link::Static, Link::Shared] {
        let bin = dir.path().join(format!("probe-{link:?}"));
        build_c(&[example("probe.c")], &bin, link, false);
        let o = run(&bin, &args, false);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let got = parse_probe(&o.stdout);
        assert_eq!(got.len(), want.len(), "{link:?}: one line per contact");
        for (i, (&(idx, dv, peak), &(dv0, peak0))) in got.iter().zip(&want).enumerate() {
            assert_eq!(idx, i);
            assert_rel(dv, dv0, 1e-12, &format!("{link:?} contact {i} delta_v"));
            assert_rel(peak, peak0, 1e-12, &format!("{link:?} contact {i} peak"));
        }
    }
}

/// `probe.c` under AddressSanitizer: the success path and every error path (missing file,
/// corrupt and truncated bases, a contact off the surface, bad arguments) exit with their
/// documented code, say what failed (naming the file), and leak nothing.
#[test]
fn probe_c_is_clean_under_asan_on_success_and_error_paths() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    let bin = dir.path().join("probe-asan");
    build_c(&[example("probe.c")], &bin, Link::Static, true);
    let b = base.to_str().unwrap();
    let args = probe_args(b);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&bin, &args, true);
    assert_clean(&o, "probe success");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(parse_probe(&o.stdout).len(), CONTACTS.len());

    let missing = dir.path().join("missing.modes");
    let corrupt = dir.path().join("corrupt.modes");
    std::fs::write(&corrupt, b"PK\x03\x04 this is not a modes archive").unwrap();
    let truncated = dir.path().join("truncated.modes");
    let bytes = std::fs::read(&base).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let (m, c, t) = (
        missing.to_str().unwrap(),
        corrupt.to_str().unwrap(),
        truncated.to_str().unwrap(),
    );
    let cases: [(&str, Vec<&str>, i32, &str); 6] = [
        (
            "missing file",
            vec![m, "0.5", "0.5", "1", "1", "0.5", "0.5", "1"],
            1,
            m,
        ),
        (
            "corrupt base",
            vec![c, "0.5", "0.5", "1", "1", "0.5", "0.5", "1"],
            1,
            c,
        ),
        (
            "truncated base",
            vec![t, "0.5", "0.5", "1", "1", "0.5", "0.5", "1"],
            1,
            t,
        ),
        (
            "contact off the surface",
            vec![b, "0.5", "0.5", "1", "1", "5", "5", "5"],
            1,
            "contact 0",
        ),
        (
            "impact off the surface",
            vec![b, "9", "9", "9", "1", "0.5", "0.5", "1"],
            1,
            "impact",
        ),
        (
            "negative impulse",
            vec![b, "0.5", "0.5", "1", "-1", "0.5", "0.5", "1"],
            2,
            "IMPULSE",
        ),
    ];
    for (what, a, code, needle) in cases {
        let o = run(&bin, &a, true);
        assert_clean(&o, what);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{what}: {err}");
        assert!(err.contains(needle), "{what}: `{needle}` not in `{err}`");
        assert!(o.stdout.is_empty(), "{what}: printed results");
    }
    // Usage: wrong argument count.
    let o = run(&bin, &[b, "1", "2"], true);
    assert_clean(&o, "usage");
    assert_eq!(o.status.code(), Some(2));
}

/// One `event` line of `world.c`.
#[derive(Debug, PartialEq)]
struct Event {
    body: u64,
    point: [f64; 3],
    impulse: [f64; 3],
    normal: [f64; 3],
    delta_v: f64,
    object: u32,
    served_by: u8,
    contact: u64,
    chained: bool,
}

fn nums(f: &[&str]) -> Vec<f64> {
    f.iter().map(|s| s.parse::<f64>().unwrap()).collect()
}

fn v3(x: &[f64]) -> [f64; 3] {
    [x[0], x[1], x[2]]
}

/// `examples/world.c`, linked both ways (the shared build under AddressSanitizer), returns
/// exactly the events the Rust `DcrWorld` returns for the contacts and bodies it reported
/// (replayed from its output), and they are what the set-up implies: one impulse on the
/// resting box at the impact step only, along the rotated face normal (world +x), equal to
/// 1 kg × Δv.
#[test]
fn world_c_events_equal_the_rust_world() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    let mut outputs = Vec::new();
    for (link, asan) in [(Link::Static, false), (Link::Shared, true)] {
        let bin = dir.path().join(format!("world-{link:?}"));
        build_c(&[example("world.c")], &bin, link, asan);
        let o = run(&bin, &[base.to_str().unwrap(), "10"], asan);
        assert_clean(&o, "world");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outputs.push(String::from_utf8(o.stdout).unwrap());
    }
    assert_eq!(outputs[0], outputs[1], "static and shared builds disagree");
    let text = &outputs[0];

    // Replay through the Rust world.
    let model = ModalModel::load(&base).unwrap();
    let mut pose = Pose::IDENTITY;
    let mut bodies = Vec::new();
    let mut steps: Vec<(Vec<ContactReport>, Vec<Event>)> = Vec::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f[0] {
            "pose" => {
                let x = nums(&f[1..]);
                pose = Pose::new([x[0], x[1], x[2], x[3]], [x[4], x[5], x[6]]);
            }
            "body" => {
                let x = nums(&f[2..]);
                bodies.push(BodyState {
                    id: f[1].parse().unwrap(),
                    inv_mass: x[0],
                    inv_inertia: [v3(&x[1..]), v3(&x[4..]), v3(&x[7..])],
                    center_of_mass: v3(&x[10..]),
                    linvel: v3(&x[13..]),
                    angvel: v3(&x[16..]),
                });
            }
            "step" => steps.push((Vec::new(), Vec::new())),
            "contact" => {
                let x = nums(&f[4..14]);
                steps.last_mut().unwrap().0.push(ContactReport {
                    id: f[1].parse().unwrap(),
                    body1: f[2].parse().unwrap(),
                    body2: f[3].parse().unwrap(),
                    point1: v3(&x[0..]),
                    point2: v3(&x[3..]),
                    normal: v3(&x[6..]),
                    impulse: x[9],
                    is_new: f[14] == "1",
                });
            }
            "event" => {
                let x = nums(&f[2..12]);
                steps.last_mut().unwrap().1.push(Event {
                    body: f[1].parse().unwrap(),
                    point: v3(&x[0..]),
                    impulse: v3(&x[3..]),
                    normal: v3(&x[6..]),
                    delta_v: x[9],
                    object: f[12].parse().unwrap(),
                    served_by: f[13].parse().unwrap(),
                    contact: f[14].parse().unwrap(),
                    chained: f[15] == "1",
                });
            }
            other => panic!("unexpected line kind `{other}`"),
        }
    }
    assert_eq!(steps.len(), 10);
    assert_eq!(bodies.len(), 2);
    let mut world = DcrWorld::new(WorldParams::with_gravity([0.0; 3])).unwrap();
    let mut desc = ElasticObjectDesc::new(model, 1);
    desc.response.method = Method::Modal;
    desc.response.impact_threshold = 0.05;
    desc.pose = pose;
    world.add_object(desc).unwrap();
    for (s, (contacts, c_events)) in steps.iter().enumerate() {
        let rust: Vec<Event> = world
            .step(contacts, &bodies)
            .iter()
            .map(|e| Event {
                body: e.body,
                point: e.point,
                impulse: e.impulse,
                normal: e.normal,
                delta_v: e.delta_v,
                object: e.object.index(),
                served_by: served(e.served_by),
                contact: e.contact,
                chained: e.chained,
            })
            .collect();
        assert_eq!(&rust, c_events, "step {s}: C and Rust worlds differ");
        if s == 5 {
            assert_eq!(c_events.len(), 1, "step 5: one impulse on the box");
            let e = &c_events[0];
            assert_eq!((e.body, e.contact, e.object, e.chained), (7, 70, 0, false));
            assert_eq!(e.served_by, dcr_capi::DCR_SERVED_BY_MODAL);
            // The face's outward normal +z (object frame), rotated 90° about +y: world +x.
            for (k, want) in [1.0, 0.0, 0.0].iter().enumerate() {
                assert!((e.normal[k] - want).abs() < 1e-12, "normal {:?}", e.normal);
            }
            assert!(e.delta_v > 0.0);
            for k in 0..3 {
                // 1 kg box, no inverse inertia: j = m Δv n.
                assert!((e.impulse[k] - e.delta_v * e.normal[k]).abs() <= 1e-15);
            }
        } else {
            assert!(c_events.is_empty(), "step {s}: events without an impact");
        }
    }
}

fn served(s: dcr_runtime::response::ServedBy) -> u8 {
    match s {
        dcr_runtime::response::ServedBy::Modal => dcr_capi::DCR_SERVED_BY_MODAL,
        dcr_runtime::response::ServedBy::Attenuation => dcr_capi::DCR_SERVED_BY_ATTENUATION,
        dcr_runtime::response::ServedBy::TransferTable => dcr_capi::DCR_SERVED_BY_TRANSFER_TABLE,
        dcr_runtime::response::ServedBy::Unmapped => dcr_capi::DCR_SERVED_BY_UNMAPPED,
    }
}

/// `tests/c/error_paths.c` under AddressSanitizer, linked both ways: every documented error
/// status, message and out-parameter, no leak, no invalid access.
#[test]
fn error_paths_c_is_clean_under_asan() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    let corrupt = dir.path().join("corrupt.modes");
    std::fs::write(&corrupt, b"PK\x03\x04 not an archive").unwrap();
    let missing = dir.path().join("no-such-dir/missing.modes");
    for link in [Link::Static, Link::Shared] {
        let bin = dir.path().join(format!("error-paths-{link:?}"));
        build_c(&[test_src("error_paths.c")], &bin, link, true);
        let o = run(
            &bin,
            &[
                base.to_str().unwrap(),
                corrupt.to_str().unwrap(),
                missing.to_str().unwrap(),
            ],
            true,
        );
        assert_clean(&o, "error_paths");
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success() && out.starts_with("ok "),
            "{link:?}: {out}\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// The header compiles as C++17 with `-Wall -Wextra -Werror -pedantic`, links against the
/// shared library and answers a query (with the size-query idiom) through RAII owners.
#[test]
fn header_compiles_and_runs_as_cpp17() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    let bin = dir.path().join("cxx_smoke");
    let lib = common::shared_lib();
    let libdir = lib.parent().unwrap();
    run_ok(
        Command::new(common::cxx())
            .args(["-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic"])
            .arg("-I")
            .arg(crate_dir().join("include"))
            .arg(test_src("cxx_smoke.cpp"))
            .arg("-o")
            .arg(&bin)
            .arg("-L")
            .arg(libdir)
            .arg("-ldcr_capi")
            .arg(format!("-Wl,-rpath,{}", libdir.display())),
    );
    let o = run(&bin, &[base.to_str().unwrap()], false);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 2);
}

/// The header alone compiles as strict C99 and C11 in a translation unit that includes it
/// twice (include guard) and uses every struct type.
#[test]
fn header_compiles_as_strict_c99() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("only_header.c");
    std::fs::write(
        &src,
        "#include \"dcr.h\"\n#include \"dcr.h\"\n\
         int main(void) {\n\
           DcrResponseParams p; DcrWorldParams w; DcrElasticObjectDesc d; DcrContactReport c;\n\
           DcrBodyState b; DcrImpulseEvent e; DcrModelInfo i; DcrObjectStepInfo o;\n\
           (void)p; (void)w; (void)d; (void)c; (void)b; (void)e; (void)i; (void)o;\n\
           return DCR_STATUS_OK;\n\
         }\n",
    )
    .unwrap();
    for std in ["-std=c99", "-std=c11"] {
        run_ok(
            Command::new(common::cc())
                .args([std, "-Wall", "-Wextra", "-Werror", "-pedantic", "-c"])
                .arg("-I")
                .arg(crate_dir().join("include"))
                .arg(&src)
                .arg("-o")
                .arg(dir.path().join("only_header.o")),
        );
    }
}

/// `tests/c/lifecycle.c` under AddressSanitizer, linked both ways: an elastic object disabled,
/// enabled (filters at rest) with gain 2 (exactly twice the first push), its threshold raised
/// above a hit and lowered again, removed (every call with its handle refused as stale, its
/// body's contacts harmless), and replaced on the same body (same slot, next generation, the
/// first push again); no leak, no invalid access.
#[test]
fn lifecycle_c_is_clean_under_asan() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    for link in [Link::Static, Link::Shared] {
        let bin = dir.path().join(format!("lifecycle-{link:?}"));
        build_c(&[test_src("lifecycle.c")], &bin, link, true);
        let o = run(&bin, &[base.to_str().unwrap()], true);
        assert_clean(&o, "lifecycle");
        assert!(
            o.status.success() && o.stdout == b"ok\n",
            "{link:?}: {}\n{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// `examples/world.c` on the scenes' table (y-up): told the wrong up axis (`z`, its default)
/// it reports contacts that miss the table, gets no event and warns on stderr that the
/// contacts were not mapped, naming the axis; told `y` it pushes the box at the impact step
/// and prints no warning.
#[test]
fn world_c_warns_when_its_contacts_are_not_mapped() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("table.modes");
    run_ok(
        Command::new(modal_bake())
            .arg("bake")
            .arg(common::workspace().join("data/scenes/table.msh"))
            .arg("-o")
            .arg(&base)
            .args(["--fixed", "feet", "--modes", "8"]),
    );
    let bin = dir.path().join("world-asan");
    build_c(&[example("world.c")], &bin, Link::Static, true);
    let b = base.to_str().unwrap();
    let events = |o: &Output| {
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter(|l| l.starts_with("event "))
            .count()
    };

    let wrong = run(&bin, &[b, "10"], true);
    assert_clean(&wrong, "world, wrong up axis");
    let err = String::from_utf8_lossy(&wrong.stderr);
    assert!(wrong.status.success(), "{err}");
    assert_eq!(events(&wrong), 0, "no response off the surface");
    assert!(
        err.contains("warning") && err.contains("not mapped") && err.contains("`z`"),
        "no unmapped-contact warning naming the axis: {err}"
    );

    let right = run(&bin, &[b, "10", "y"], true);
    assert_clean(&right, "world, up y");
    let err = String::from_utf8_lossy(&right.stderr);
    assert!(right.status.success(), "{err}");
    assert_eq!(events(&right), 1, "the box is pushed once: {err}");
    assert!(!err.contains("warning"), "{err}");

    let bad = run(&bin, &[b, "10", "up"], true);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("UP `up`"));
}

/// The fenced ```c blocks of `docs/engine-integration.md` and `crates/dcr-capi/README.md`,
/// each a translation unit on its own: every block compiles as C99 with `-Wall -Wextra -Werror
/// -pedantic` against `include/dcr.h`; a block with a `main` is linked (static library, under
/// AddressSanitizer) and run with a base as its only argument, and must exit 0 without a
/// sanitizer report. Both documents hold at least one block, and at least one is complete.
#[test]
fn c_snippets_of_the_docs_compile_and_the_complete_ones_run() {
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    let mut complete = 0;
    for doc in ["docs/engine-integration.md", "crates/dcr-capi/README.md"] {
        let text = std::fs::read_to_string(common::workspace().join(doc)).unwrap();
        let blocks = c_blocks(&text);
        assert!(!blocks.is_empty(), "{doc}: no ```c block");
        for (i, (line, src)) in blocks.iter().enumerate() {
            let stem = format!(
                "{}_{i}",
                doc.replace(['/', '.', '-'], "_").trim_end_matches("_md")
            );
            let file = dir.path().join(format!("{stem}.c"));
            std::fs::write(&file, src).unwrap();
            let what = format!("{doc}:{line}");
            if src.contains("int main(") {
                complete += 1;
                let bin = dir.path().join(&stem);
                build_c(std::slice::from_ref(&file), &bin, Link::Static, true);
                let o = run(&bin, &[base.to_str().unwrap()], true);
                assert_clean(&o, &what);
                assert!(
                    o.status.success(),
                    "{what}: exit {}\n{}",
                    o.status,
                    String::from_utf8_lossy(&o.stderr)
                );
            } else {
                run_ok(
                    Command::new(common::cc())
                        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c"])
                        .arg("-I")
                        .arg(crate_dir().join("include"))
                        .arg(&file)
                        .arg("-o")
                        .arg(dir.path().join(format!("{stem}.o"))),
                );
            }
        }
    }
    assert!(complete >= 1, "no complete C program in the docs");
}

/// The ```c fenced blocks of a Markdown text: (line of the fence, source).
fn c_blocks(text: &str) -> Vec<(usize, String)> {
    let mut blocks = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (n, line) in text.lines().enumerate() {
        match &mut current {
            None if line.trim_start() == "```c" => current = Some((n + 1, String::new())),
            Some((start, src)) if line.trim_start() == "```" => {
                blocks.push((*start, std::mem::take(src)));
                current = None;
            }
            Some((_, src)) => {
                src.push_str(line);
                src.push('\n');
            }
            None => {}
        }
    }
    assert!(current.is_none(), "an unclosed ```c block");
    blocks
}
