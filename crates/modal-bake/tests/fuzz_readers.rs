//! Seeded mutation fuzzing of every reader of untrusted input: gmsh MSH (2.2 and 4.1, ASCII
//! and binary), meshio JSON, `.modes` archives and surface assets (OBJ, ASCII and binary STL,
//! ASCII and binary PLY), on the stable toolchain, as part of
//! `cargo test --release` (bounded: a few thousand inputs, well under a minute).
//!
//! Mutations: byte flips, truncations, duplicated and swapped sections, huge numbers (ASCII
//! tokens and binary words), negative tags, extra tokens, NaN/Inf, tetrahedra repeated with
//! permuted nodes, and for archives corrupted `.npy` headers (lengths, shapes) and zip records.
//!
//! Every mutated input must: not panic; not allocate more than a bound linear in its size
//! (peak bytes over the read, [`alloc_bound`]); and, when refused, give an error naming the
//! file and a location (line, byte offset, element, JSON path; an entry for archives).
//!
//! The peak is measured by a counting global allocator (this file is its own test binary and
//! holds a single test, so no other test thread allocates meanwhile). Written here rather than
//! taken from the `cap` crate, which tracks current bytes and a limit but not the peak, and
//! aborts the process without naming the input when the limit is hit.
//!
//! `DCR_FUZZ_ITERS` (default 600 per seed file) runs longer locally; `DCR_FUZZ_SEED` changes
//! the seed.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Cursor;
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use dcr_runtime::format::ModesFile;
use dcr_runtime::testing::SplitMix64;
use modal_bake::mesh::surface::read_surface_bytes;
use modal_bake::mesh::{read_mesh_bytes, Location, MeshErrorKind};

#[path = "common/gltf_cube.rs"]
mod gltf_cube;

struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = CURRENT.fetch_add(n, Ordering::Relaxed) + n;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
            grew(new_size);
        }
        p
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Peak bytes a read of an `n`-byte input of `kind` may allocate: a constant for set-up plus a
/// multiple of the input (a meshio JSON document tree holds ~20 bytes per input byte, the
/// canonical mesh and its sort buffers fewer). The PLY parser reserves up to 65,536 elements of
/// a declared count before reading them (≈ 4.7 MB for three `f64` properties), whatever the
/// header claims: a larger constant for surface assets.
fn alloc_bound(n: usize, kind: Kind) -> usize {
    let setup = match kind {
        Kind::SurfaceAscii | Kind::SurfaceBinary => 8 << 20,
        _ => 4 << 20,
    };
    setup + 48 * n
}

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(rel)
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Kind {
    MshAscii,
    MshBinary,
    Json,
    Modes,
    /// OBJ, ASCII STL, ASCII PLY, `.gltf`.
    SurfaceAscii,
    /// Binary STL, PLY and glTF.
    SurfaceBinary,
}

/// Random index below `n` (n > 0).
fn below(rng: &mut SplitMix64, n: usize) -> usize {
    (rng.next_u64() % n as u64) as usize
}

/// Byte ranges of the whitespace-separated tokens of `b` that look like numbers.
fn numeric_tokens(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_whitespace() || b[i] == b',' || b[i] == b'[' || b[i] == b']' {
            i += 1;
            continue;
        }
        let s = i;
        while i < b.len()
            && !b[i].is_ascii_whitespace()
            && b[i] != b','
            && b[i] != b'['
            && b[i] != b']'
        {
            i += 1;
        }
        if b[s].is_ascii_digit() || b[s] == b'-' {
            out.push((s, i));
        }
    }
    out
}

/// Byte ranges of `$Name ... $EndName\n` sections.
fn sections(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(off) = b[i..].windows(1).position(|w| w[0] == b'$') {
        let s = i + off;
        if s > 0 && b[s - 1] != b'\n' {
            i = s + 1;
            continue;
        }
        let name_end = b[s..]
            .iter()
            .position(|c| c.is_ascii_whitespace())
            .map_or(b.len(), |p| s + p);
        let name = &b[s + 1..name_end];
        if name.starts_with(b"End") {
            i = name_end;
            continue;
        }
        let mut marker = b"$End".to_vec();
        marker.extend_from_slice(name);
        match b[name_end..]
            .windows(marker.len())
            .position(|w| w == marker.as_slice())
        {
            Some(p) => {
                let mut e = name_end + p + marker.len();
                if b.get(e) == Some(&b'\n') {
                    e += 1;
                }
                out.push((s, e));
                i = e;
            }
            None => break,
        }
    }
    out
}

/// One random mutation of `seed` of kind `kind`; returns the bytes and what was done.
fn mutate(rng: &mut SplitMix64, seed: &[u8], kind: Kind) -> (Vec<u8>, String) {
    let mut b = seed.to_vec();
    let n = b.len().max(1);
    let ascii = matches!(kind, Kind::MshAscii | Kind::Json | Kind::SurfaceAscii);
    let choice = below(rng, 9);
    match choice {
        0 => {
            let flips = 1 + below(rng, 4);
            for _ in 0..flips {
                let at = below(rng, n);
                b[at] ^= 1 + below(rng, 255) as u8;
            }
            (b, format!("{flips} byte flips"))
        }
        1 => {
            let cut = below(rng, n);
            b.truncate(cut);
            (b, format!("truncated to {cut} bytes"))
        }
        2 if matches!(kind, Kind::MshAscii | Kind::MshBinary) => {
            let secs = sections(&b);
            if secs.is_empty() {
                return (b, "no section".into());
            }
            let (s, e) = secs[below(rng, secs.len())];
            if rng.next_u64().is_multiple_of(2) {
                let copy = b[s..e].to_vec();
                let at = secs[below(rng, secs.len())].1;
                b.splice(at..at, copy);
                (b, format!("section at {s} duplicated at {at}"))
            } else {
                let (s2, e2) = secs[below(rng, secs.len())];
                if s2 <= s {
                    return (b, "swap skipped".into());
                }
                let (first, second) = (b[s..e].to_vec(), b[s2..e2].to_vec());
                let mut out = b[..s].to_vec();
                out.extend_from_slice(&second);
                out.extend_from_slice(&b[e..s2]);
                out.extend_from_slice(&first);
                out.extend_from_slice(&b[e2..]);
                (out, format!("sections at {s} and {s2} swapped"))
            }
        }
        3 | 4 if ascii => {
            let toks = numeric_tokens(&b);
            if toks.is_empty() {
                return (b, "no token".into());
            }
            let (s, e) = toks[below(rng, toks.len())];
            let with: &[u8] = if choice == 3 {
                [
                    &b"1e308"[..],
                    b"18446744073709551615",
                    b"18446744073709551616",
                    b"4294967296",
                    b"2147483648",
                    b"99999999999999999999999",
                    b"1e999",
                    b"0",
                ][below(rng, 8)]
            } else {
                [&b"nan"[..], b"inf", b"-inf", b"NaN"][below(rng, 4)]
            };
            let what = format!("token at {s} → {}", String::from_utf8_lossy(with));
            b.splice(s..e, with.iter().copied());
            (b, what)
        }
        5 if ascii => {
            let toks = numeric_tokens(&b);
            if toks.is_empty() {
                return (b, "no token".into());
            }
            let (s, _) = toks[below(rng, toks.len())];
            b.insert(s, b'-');
            (b, format!("minus inserted at {s}"))
        }
        6 if ascii => {
            let lines: Vec<usize> = (0..b.len()).filter(|&i| b[i] == b'\n').collect();
            if lines.is_empty() {
                return (b, "no line".into());
            }
            let at = lines[below(rng, lines.len())];
            b.splice(at..at, b" 7".iter().copied());
            (b, format!("extra token before byte {at}"))
        }
        7 if kind == Kind::MshAscii => permuted_duplicate_tet(rng, b),
        7 if kind == Kind::Json => {
            // Repeat a row of four indices with its first two swapped.
            let text = String::from_utf8_lossy(&b).into_owned();
            let rows: Vec<usize> = text.match_indices("\n[").map(|(i, _)| i + 1).collect();
            for _ in 0..8 {
                if rows.is_empty() {
                    break;
                }
                let s = rows[below(rng, rows.len())];
                let e = s + text[s..].find(']').unwrap_or(0) + 1;
                let v: Vec<&str> = text[s + 1..e - 1].split(',').map(str::trim).collect();
                if v.len() == 4 && v.iter().all(|x| x.parse::<u64>().is_ok()) {
                    let row = format!("[{}, {}, {}, {}],\n", v[1], v[0], v[2], v[3]);
                    let mut out = text.as_bytes().to_vec();
                    out.splice(s..s, row.bytes());
                    return (out, format!("tetra row at {s} repeated, permuted"));
                }
            }
            (b, "no tetra row".into())
        }
        _ if kind == Kind::Modes => modes_mutation(rng, b),
        _ => {
            // Binary words: a huge, negative, NaN or all-ones value at an aligned offset.
            let at = below(rng, n) & !3;
            let words: [&[u8]; 6] = [
                &0xFFFF_FFFFu32.to_le_bytes(),
                &0x7FFF_FFFFu32.to_le_bytes(),
                &0xFFFF_FFF0u32.to_le_bytes(),
                &(-5i32).to_le_bytes(),
                &f64::NAN.to_le_bytes(),
                &1e300f64.to_le_bytes(),
            ];
            let w = words[below(rng, words.len())];
            let end = (at + w.len()).min(b.len());
            b[at..end].copy_from_slice(&w[..end - at]);
            (b, format!("{}-byte word at {at}", w.len()))
        }
    }
}

/// MSH 2.2 ASCII: a tetrahedron line repeated under a new tag with two nodes swapped (the
/// element count raised to match).
fn permuted_duplicate_tet(rng: &mut SplitMix64, b: Vec<u8>) -> (Vec<u8>, String) {
    let text = String::from_utf8_lossy(&b).into_owned();
    let lines: Vec<&str> = text.lines().collect();
    let Some(start) = lines.iter().position(|l| *l == "$Elements") else {
        return (b, "no $Elements".into());
    };
    let tets: Vec<usize> = (start + 2..lines.len())
        .filter(|&i| {
            let f: Vec<&str> = lines[i].split_whitespace().collect();
            f.len() >= 7 && f[1] == "4"
        })
        .collect();
    if tets.is_empty() || !text.starts_with("$MeshFormat\n2.2") {
        return (b, "no 2.2 tet line".into());
    }
    let i = tets[below(rng, tets.len())];
    let mut f: Vec<String> = lines[i].split_whitespace().map(String::from).collect();
    let k = f.len();
    f.swap(k - 1, k - 2);
    f[0] = "99999".into();
    let count: usize = lines[start + 1].trim().parse().unwrap_or(0);
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    out[start + 1] = (count + 1).to_string();
    out.insert(i + 1, f.join(" "));
    (
        (out.join("\n") + "\n").into_bytes(),
        format!("tet line {} repeated with two nodes swapped", i + 1),
    )
}

/// Archive-level mutations of a `.modes` file: `.npy` header lengths and shapes, data words,
/// zip record fields.
fn modes_mutation(rng: &mut SplitMix64, mut b: Vec<u8>) -> (Vec<u8>, String) {
    let npy: Vec<usize> = b
        .windows(6)
        .enumerate()
        .filter(|(_, w)| *w == b"\x93NUMPY")
        .map(|(i, _)| i)
        .collect();
    let records: Vec<usize> = b
        .windows(4)
        .enumerate()
        .filter(|(_, w)| *w == b"PK\x01\x02" || *w == b"PK\x05\x06" || *w == b"PK\x03\x04")
        .map(|(i, _)| i)
        .collect();
    match below(rng, 4) {
        0 if !npy.is_empty() => {
            // Version 2 with a header length of 0xFFFFFFF0 (or another huge value).
            let at = npy[below(rng, npy.len())];
            b[at + 6] = 2;
            let len = [0xFFFF_FFF0u32, 0x7FFF_FFFF, 65_000][below(rng, 3)];
            let end = (at + 12).min(b.len());
            b[at + 8..end].copy_from_slice(&len.to_le_bytes()[..end - at - 8]);
            (b, format!("npy header at {at}: v2 length {len:#x}"))
        }
        1 if !npy.is_empty() => {
            // A shape number replaced by a huge one.
            let at = npy[below(rng, npy.len())];
            let hdr_end = (at + 128).min(b.len());
            match b[at..hdr_end].iter().position(|&c| c == b'(') {
                Some(p) => {
                    let s = at + p + 1;
                    let big =
                        [&b"1000000000000"[..], b"99999999999999999999", b"-1"][below(rng, 3)];
                    b.splice(s..s, big.iter().copied());
                    (b, format!("npy shape at {s} prefixed"))
                }
                None => (b, "no shape".into()),
            }
        }
        2 if !records.is_empty() => {
            // A 4-byte field of a zip record (sizes, offsets, counts) set to a huge value.
            let at = records[below(rng, records.len())] + 4 + 2 * below(rng, 12);
            let end = (at + 4).min(b.len());
            if at < end {
                let v = [0xFFFF_FFFFu32, 0x7FFF_0000, 0x0001_0000][below(rng, 3)];
                b[at..end].copy_from_slice(&v.to_le_bytes()[..end - at]);
            }
            (b, format!("zip field at {at} set huge"))
        }
        _ => {
            // A data word: NaN, infinity, negative or huge.
            let at = below(rng, b.len().max(1)) & !7;
            let w = [f64::NAN, f64::INFINITY, -1.0, 1e300][below(rng, 4)].to_le_bytes();
            let end = (at + 8).min(b.len());
            b[at..end].copy_from_slice(&w[..end - at]);
            (b, format!("8-byte word at {at}"))
        }
    }
}

/// Reads `bytes` as `kind` under `name`, asserting no panic, bounded allocation and, on error, a
/// message naming the file and a location. Returns whether it was refused.
fn check_one(bytes: &[u8], name: &str, kind: Kind, what: &str) -> bool {
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let result = std::panic::catch_unwind(AssertUnwindSafe(|| match kind {
        Kind::Modes => ModesFile::read_from(Cursor::new(bytes), Path::new(name))
            .map(|_| ())
            .map_err(|e| (e.to_string(), true)),
        // Surface readers: the whole check a bake makes before gmsh (read, then closed,
        // manifold, one shell). The parsers' own messages (tobj, ply-rs) carry no line; the
        // file is named.
        Kind::SurfaceAscii | Kind::SurfaceBinary => read_surface_bytes(bytes, name)
            .and_then(|mut s| s.check_closed(name).map(|_| ()))
            .map_err(|e| (e.to_string(), true)),
        _ => read_mesh_bytes(bytes, name).map(|_| ()).map_err(|e| {
            let located = e.location != Location::None
                || matches!(
                    e.kind,
                    MeshErrorKind::NoTets { .. }
                        | MeshErrorKind::OtherVolumeElements { .. }
                        | MeshErrorKind::UnknownFormat
                        | MeshErrorKind::FluentMsh
                );
            (e.to_string(), located)
        }),
    }));
    let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
    let Ok(result) = result else {
        panic!("{name} ({what}): the reader panicked");
    };
    assert!(
        peak <= alloc_bound(bytes.len(), kind),
        "{name} ({what}): allocated {peak} bytes for a {}-byte input (bound {})",
        bytes.len(),
        alloc_bound(bytes.len(), kind)
    );
    match result {
        Ok(()) => false,
        Err((msg, located)) => {
            assert!(
                msg.starts_with(name),
                "{name} ({what}): `{msg}` does not name the file"
            );
            assert!(located, "{name} ({what}): `{msg}` has no location");
            true
        }
    }
}

/// The `.modes` seeds: a baked cube (free-free, 6 modes) and a synthetic plate with a
/// surface order.
fn modes_seeds() -> Vec<(String, Vec<u8>)> {
    let dir = tempfile::tempdir().unwrap();
    let mesh = modal_bake::mesh::read_mesh(&data("meshes/cube_v41.msh")).unwrap();
    let params = modal_bake::bake::BakeParams {
        modes: modal_bake::bake::ModeRequest::Count(6),
        ..Default::default()
    };
    let (base, _) = modal_bake::bake::bake_mesh(mesh, &params, "cube", &mut |_| {}).unwrap();
    let p = dir.path().join("cube.modes");
    base.write_atomic(&p).unwrap();
    let mut plate = dcr_runtime::testing::plate_base();
    plate.surface_order = Some((0..plate.num_surface_vertices() as u32).rev().collect());
    let q = dir.path().join("plate.modes");
    plate.write_atomic(&q).unwrap();
    vec![
        ("cube.modes".into(), std::fs::read(&p).unwrap()),
        ("plate.modes".into(), std::fs::read(&q).unwrap()),
    ]
}

/// The surface seeds: a unit cube as OBJ (quads), ASCII STL (two solids, the second a shifted
/// cube: refused as two shells unless a mutation breaks one), binary STL whose header starts
/// with `solid`, ASCII PLY, binary PLY, GLB and `.gltf` with a base64 data URI.
fn surface_seeds() -> Vec<(String, Vec<u8>, Kind)> {
    use gltf_cube::{Q, V};
    let tris: Vec<[usize; 3]> = Q
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    let mut obj = String::from("o cube\n");
    for p in V {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for q in Q {
        obj += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    let mut stl = String::new();
    for dx in [0.0, 3.0] {
        stl += "solid cube\n";
        for t in &tris {
            stl += "facet normal 0 0 0\nouter loop\n";
            for &i in t {
                stl += &format!("vertex {} {} {}\n", V[i][0] + dx, V[i][1], V[i][2]);
            }
            stl += "endloop\nendfacet\n";
        }
        stl += "endsolid cube\n";
    }
    let mut stlb = b"solid binary".to_vec();
    stlb.resize(80, 0);
    stlb.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in &tris {
        stlb.extend_from_slice(&[0u8; 12]);
        for &i in t {
            for k in 0..3 {
                stlb.extend_from_slice(&(V[i][k] as f32).to_le_bytes());
            }
        }
        stlb.extend_from_slice(&[0u8; 2]);
    }
    let header = |enc: &str, faces: usize| {
        format!(
            "ply\nformat {enc} 1.0\nelement vertex 8\nproperty double x\nproperty double y\n\
             property double z\nelement face {faces}\nproperty list uchar int vertex_indices\n\
             end_header\n"
        )
    };
    let mut ply = header("ascii", 6);
    for p in V {
        ply += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in Q {
        ply += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    let mut plyb = header("binary_little_endian", 12).into_bytes();
    for p in V {
        for x in p {
            plyb.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in &tris {
        plyb.push(3);
        for &i in t {
            plyb.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    vec![
        ("cube.obj".into(), obj.into_bytes(), Kind::SurfaceAscii),
        ("two.stl".into(), stl.into_bytes(), Kind::SurfaceAscii),
        ("cube_bin.stl".into(), stlb, Kind::SurfaceBinary),
        ("cube.ply".into(), ply.into_bytes(), Kind::SurfaceAscii),
        ("cube_bin.ply".into(), plyb, Kind::SurfaceBinary),
        (
            "cube.glb".into(),
            gltf_cube::cube_glb(),
            Kind::SurfaceBinary,
        ),
        (
            "cube.gltf".into(),
            gltf_cube::cube_gltf_embedded(),
            Kind::SurfaceAscii,
        ),
    ]
}

#[test]
fn mutated_inputs_never_panic_allocate_unboundedly_or_go_unlocated() {
    let iters: usize = std::env::var("DCR_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(600);
    let seed: u64 = std::env::var("DCR_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5EED_F022);
    let mut seeds: Vec<(String, Vec<u8>, Kind)> = Vec::new();
    for (rel, kind) in [
        ("meshes/cube_v22.msh", Kind::MshAscii),
        ("meshes/cube_v41.msh", Kind::MshAscii),
        ("meshes/cube_v22_bin.msh", Kind::MshBinary),
        ("meshes/cube_v41_bin.msh", Kind::MshBinary),
        ("meshes/cylinder_v22_bin.msh", Kind::MshBinary),
        ("meshes/cube_cell_sets.json", Kind::Json),
        ("meshes/cube_gmsh_physical.json", Kind::Json),
        ("bad/permuted_duplicate_tet.msh", Kind::MshAscii),
        ("bad/comments_first.msh", Kind::MshAscii),
    ] {
        let name = rel.rsplit('/').next().unwrap().to_string();
        seeds.push((name, std::fs::read(data(rel)).unwrap(), kind));
    }
    for (name, bytes) in modes_seeds() {
        seeds.push((name, bytes, Kind::Modes));
    }
    seeds.extend(surface_seeds());
    let mut rng = SplitMix64(seed);
    let (mut total, mut refused) = (0, 0);
    for (name, bytes, kind) in &seeds {
        // The seed itself reads (or, for the bad file, is refused cleanly).
        check_one(bytes, name, *kind, "unmutated");
        for _ in 0..iters {
            let (mutated, what) = mutate(&mut rng, bytes, *kind);
            // Mutations that keep the kind's first byte keep its format detection.
            if check_one(&mutated, name, *kind, &what) {
                refused += 1;
            }
            total += 1;
        }
    }
    // Most mutations must be refused: a harness whose mutations all read fine tests nothing.
    assert!(
        refused * 2 > total,
        "only {refused} of {total} mutated inputs were refused"
    );
    eprintln!("fuzz: {total} mutated inputs, {refused} refused, seed {seed:#x}");
}
