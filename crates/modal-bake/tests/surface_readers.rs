//! The surface readers read everything a file holds or refuse it with the line: every
//! `solid … endsolid` block of an ASCII STL (two cubes are two shells, refused as OBJ refuses
//! them), a PLY's faces beyond the header's count refused with their line; one decision for
//! binary against ASCII STL (binary exactly when the length is 84 + 50·n, whatever the header
//! says); ASCII STL as exporters write it (no solid name, blank lines, upper case); only
//! regular files opened.

use modal_bake::mesh::surface::{read_surface_bytes, SurfaceError};

#[path = "common/unit_cube.rs"]
mod unit_cube;
use unit_cube::{cube_tris, CUBE_Q, CUBE_V};

/// One ASCII `solid` block of the cube scaled by `k` and shifted by `dx`, keywords through
/// `case`.
fn solid(name: &str, k: f64, dx: f64, case: fn(&str) -> String) -> String {
    let mut s = format!("{} {name}\n", case("solid")).trim_end().to_string() + "\n";
    for t in cube_tris() {
        s += &format!(
            "  {} 0 0 0\n    {}\n",
            case("facet normal"),
            case("outer loop")
        );
        for i in t {
            let p = CUBE_V[i];
            s += &format!(
                "      {} {} {} {}\n",
                case("vertex"),
                k * p[0] + dx,
                k * p[1],
                k * p[2]
            );
        }
        s += &format!("    {}\n  {}\n", case("endloop"), case("endfacet"));
    }
    s + &format!("{} {name}\n", case("endsolid"))
}

fn lower(s: &str) -> String {
    s.to_string()
}
fn upper(s: &str) -> String {
    s.to_ascii_uppercase()
}

fn stl_binary(header: &[u8]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b[..header.len()].copy_from_slice(header);
    let tris = cube_tris();
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for i in t {
            for k in 0..3 {
                b.extend_from_slice(&(CUBE_V[i][k] as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

// Regression: a second `solid … endsolid` block was dropped (exit 0, a base of the first cube
// only). Both are read; as two shells they are refused like an OBJ with two objects.
#[test]
fn stl_with_two_solids_reads_both_and_refuses_two_shells() {
    let text = solid("small", 1.0, 0.0, lower) + &solid("big", 2.0, 5.0, lower);
    let mut s = read_surface_bytes(text.as_bytes(), "two.stl").unwrap();
    assert_eq!(s.triangles.len(), 24, "both solids read");
    assert_eq!(s.vertices.len(), 16);
    let err = s.check_closed("two.stl").unwrap_err();
    assert!(
        matches!(err, SurfaceError::Shells { shells: 2, .. }),
        "{err}"
    );
}

// Regression: a binary STL whose 80-byte header starts with `solid` was parsed as ASCII
// ("stream did not contain valid UTF-8"); ASCII without a solid name, with leading blank lines
// or in upper case was refused with I/O internals. All read as the same cube.
#[test]
fn stl_ascii_and_binary_are_told_apart_by_length_and_exporter_variants_read() {
    let reference = read_surface_bytes(&stl_binary(b""), "plain.stl").unwrap();
    let variants: Vec<(&str, Vec<u8>)> = vec![
        (
            "binary, header `solid`",
            stl_binary(b"solid exported by a CAD tool"),
        ),
        ("ascii, no name", solid("", 1.0, 0.0, lower).into_bytes()),
        (
            "ascii, leading blank lines",
            format!("\n\n  \n{}", solid("c", 1.0, 0.0, lower)).into_bytes(),
        ),
        (
            "ascii, upper case",
            solid("C", 1.0, 0.0, upper).into_bytes(),
        ),
        (
            "ascii, CRLF",
            solid("c", 1.0, 0.0, lower)
                .replace('\n', "\r\n")
                .into_bytes(),
        ),
    ];
    for (what, bytes) in variants {
        let s = read_surface_bytes(&bytes, "v.stl").unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(s.triangles.len(), reference.triangles.len(), "{what}");
        assert_eq!(s.vertices.len(), reference.vertices.len(), "{what}");
        let v = reference
            .triangles
            .iter()
            .zip(&s.triangles)
            .all(|(a, b)| (0..3).all(|k| reference.vertices[a[k]] == s.vertices[b[k]]));
        assert!(v, "{what}: other triangles");
    }
}

#[test]
fn stl_ascii_errors_name_the_line() {
    let text = solid("c", 1.0, 0.0, lower).replacen("vertex 1 0 0", "vertex 1 zero 0", 1);
    let line = text.lines().position(|l| l.contains("zero")).unwrap() + 1;
    let err = read_surface_bytes(text.as_bytes(), "bad.stl")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad.stl") && err.contains(&format!("line {line}")) && err.contains("zero"),
        "{err}"
    );
    let cut = solid("c", 1.0, 0.0, lower).replace("endsolid c\n", "");
    let err = read_surface_bytes(cut.as_bytes(), "cut.stl")
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 1") && err.contains("endsolid"), "{err}");
}

fn ply(declared_faces: usize, faces: &[[usize; 4]]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
         element face {declared_faces}\nproperty list uchar int vertex_indices\nend_header\n"
    );
    for p in CUBE_V {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in faces {
        s += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    s
}

// Regression: faces beyond the header's count were dropped (a PLY declaring 5 faces of 6 was
// read as an open box, or worse, a closed subset). The surplus is refused with its line.
#[test]
fn ply_with_more_faces_than_declared_is_refused_with_the_line() {
    assert!(read_surface_bytes(ply(6, &CUBE_Q).as_bytes(), "ok.ply").is_ok());
    let text = ply(5, &CUBE_Q);
    let err = read_surface_bytes(text.as_bytes(), "more.ply")
        .unwrap_err()
        .to_string();
    // header 9 lines, 8 vertices, 5 faces: the sixth face is line 23.
    assert!(err.contains("more.ply") && err.contains("line 23"), "{err}");
    assert!(err.contains("5 face"), "{err}");
    // Trailing blank lines are not data.
    let blank = ply(6, &CUBE_Q) + "\n\n";
    assert!(read_surface_bytes(blank.as_bytes(), "blank.ply").is_ok());
}

// Regression: a surface asset that is a FIFO blocked forever and `/dev/zero` was read to
// 2 GB; neither is opened.
#[test]
#[cfg(unix)]
fn non_regular_surface_assets_are_refused_before_opening() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("f.stl");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let link = dir.path().join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    for p in [fifo.as_path(), link.as_path(), dir.path()] {
        let err = modal_bake::mesh::surface::read_surface(p)
            .unwrap_err()
            .to_string();
        assert!(err.contains("not a regular file"), "{}: {err}", p.display());
    }
}
