//! Round-trip, determinism and hostile-input tests of the `.modes` format.

use super::*;
use std::io::Cursor;
use std::path::Path;

/// A small valid base: a unit right tetrahedron surface with 2 synthetic modes.
pub(crate) fn tiny_base() -> ModesFile {
    let m = 2;
    let ns = 4;
    let modes = (0..ns * 3 * m).map(|i| 0.01 * (i as f64 + 1.0)).collect();
    ModesFile {
        eigenvalues: vec![100.0, 400.0],
        surface_vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        surface_triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        surface_to_volume: vec![0, 1, 2, 3],
        modes,
        material: MaterialSi {
            youngs: 1e9,
            poisson: 0.3,
            density: 700.0,
        },
        rayleigh: [10.0, 1e-7],
        fixed_nodes: vec![],
        residuals: vec![1e-12, 2e-12],
        meta: ModesMeta {
            format_version: FORMAT_VERSION,
            tool_version: "test".into(),
            source_hash: "sha256:00".into(),
            params_hash: "sha256:11".into(),
            bake_params: serde_json::json!({"modes": 2}),
            volume_nodes: 4,
            volume_tets: 1,
            rigid_modes_excluded: 6,
            mass_kg: 700.0 / 6.0,
            reoriented_tets: 0,
            accuracy: None,
        },
        precision: ModesPrecision::F64,
        transfer: None,
        surface_order: None,
        quadratic: None,
    }
}

#[test]
fn round_trip_is_exact_and_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.modes");
    let b = dir.path().join("b.modes");
    let base = tiny_base();
    base.write_atomic(&a).unwrap();
    base.write_atomic(&b).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let back = ModesFile::read(&a).unwrap();
    assert_eq!(back, base);
    // No temporary file is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn f32_storage_rounds_modes_only() {
    let mut base = tiny_base();
    base.precision = ModesPrecision::F32;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("f.modes");
    base.write_atomic(&p).unwrap();
    let back = ModesFile::read(&p).unwrap();
    assert_eq!(back.precision, ModesPrecision::F32);
    for (x, y) in back.modes.iter().zip(&base.modes) {
        assert!((x - y).abs() <= 1e-7 * y.abs());
        assert_ne!(x.to_bits(), 0);
    }
    assert_eq!(back.eigenvalues, base.eigenvalues);
}

#[test]
fn every_truncation_is_a_clean_error() {
    let bytes = tiny_base().to_bytes().unwrap();
    for cut in (0..bytes.len()).step_by(7) {
        let r = ModesFile::read_from(Cursor::new(&bytes[..cut]), Path::new("cut.modes"));
        let err = r.expect_err("a truncated archive must not read");
        assert!(err.to_string().starts_with("cut.modes"), "{err}");
        // Cut before the end-of-central-directory record: the message says where it looked.
        if cut + 22 <= bytes.len() {
            assert!(
                err.to_string()
                    .contains(&format!("the file's end at byte {cut}")),
                "{err}"
            );
        }
    }
}

#[test]
fn flipped_bytes_never_panic() {
    let bytes = tiny_base().to_bytes().unwrap();
    for i in (0..bytes.len()).step_by(3) {
        let mut b = bytes.clone();
        b[i] ^= 0xA5;
        let _ = ModesFile::read_from(Cursor::new(&b[..]), Path::new("flip.modes"));
    }
}

#[test]
fn nan_and_mismatch_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.modes");
    let mut base = tiny_base();
    base.modes[5] = f64::NAN;
    let err = base.write_atomic(&p).unwrap_err().to_string();
    assert!(
        err.contains("modes[0][2][1] = NaN (must be finite)"),
        "{err}"
    );
    assert!(!p.exists(), "nothing is written for invalid content");

    let mut base = tiny_base();
    base.modes.pop();
    assert!(base
        .write_atomic(&p)
        .unwrap_err()
        .to_string()
        .contains("ns×3×m"));

    let mut base = tiny_base();
    base.surface_triangles[1][2] = 9;
    assert!(base
        .write_atomic(&p)
        .unwrap_err()
        .to_string()
        .contains("surface_triangles[1][2] = 9 (must be < 4 surface vertices)"));

    let mut base = tiny_base();
    base.meta.format_version = 99;
    assert!(matches!(
        base.write_atomic(&p),
        Err(FormatError::Version { found: 99, .. })
    ));
}

#[test]
fn missing_entry_is_named() {
    // Archive with only a version entry.
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let mut npz = ndarray_npy::NpzWriter::new_with_options(Cursor::new(Vec::new()), opts);
    npz.add_array(
        "format_version",
        &ndarray::Array0::from_elem((), FORMAT_VERSION),
    )
    .unwrap();
    let bytes = npz.finish().unwrap().into_inner();
    let err = ModesFile::read_from(Cursor::new(bytes), Path::new("x.modes")).unwrap_err();
    assert!(
        matches!(err, FormatError::Missing { entry: "meta", .. }),
        "{err}"
    );
}

#[test]
fn hostile_header_is_not_allocated() {
    // An eigenvalues entry whose header declares 10^12 elements but carries 16 bytes.
    let mut npy = Vec::new();
    let header = "{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000,), }";
    let mut h = header.to_string();
    while !(10 + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    npy.extend_from_slice(b"\x93NUMPY\x01\x00");
    npy.extend_from_slice(&(h.len() as u16).to_le_bytes());
    npy.extend_from_slice(h.as_bytes());
    npy.extend_from_slice(&[0u8; 16]);
    let base = tiny_base();
    let good = base.to_bytes().unwrap();
    let mut zin = zip::ZipArchive::new(Cursor::new(good)).unwrap();
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..zin.len() {
        let mut f = zin.by_index(i).unwrap();
        let name = f.name().to_string();
        w.start_file(name.as_str(), opts).unwrap();
        if name == "eigenvalues.npy" {
            std::io::Write::write_all(&mut w, &npy).unwrap();
        } else {
            std::io::copy(&mut f, &mut w).unwrap();
        }
    }
    let bytes = w.finish().unwrap().into_inner();
    let err = ModesFile::read_from(Cursor::new(bytes), Path::new("h.modes"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("eigenvalues") && err.contains("bytes"),
        "{err}"
    );
}

/// `tiny_base` with a 3-vertex transfer table (vertices 0, 1, 3).
fn tiny_with_table() -> ModesFile {
    let mut b = tiny_base();
    b.transfer = Some(TransferTable {
        h: 0.01,
        rayleigh: [10.0, 1e-7],
        modes: 40,
        samples: 123,
        vertices: vec![0, 1, 3],
        order: 1,
        edges: Vec::new(),
        faces: Vec::new(),
        peaks: vec![1e-4, 2e-5, 3e-6, 4e-4, 5e-5, 6e-4],
    });
    b
}

/// Copies the archive `bytes` without the entries named in `drop` (`name.npy`).
fn without_entries(bytes: &[u8], drop: &[&str]) -> Vec<u8> {
    let mut zin = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
    let mut zout = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..zin.len() {
        let f = zin.by_index_raw(i).unwrap();
        if drop.iter().any(|d| f.name() == format!("{d}.npy")) {
            continue;
        }
        zout.raw_copy_file(f).unwrap();
    }
    zout.finish().unwrap().into_inner()
}

#[test]
fn transfer_table_round_trips_exactly_and_deterministically() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.modes"), dir.path().join("b.modes"));
    let base = tiny_with_table();
    base.write_atomic(&a).unwrap();
    base.write_atomic(&b).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let back = ModesFile::read(&a).unwrap();
    assert_eq!(back, base);
    let t = back.transfer.unwrap();
    // Packed upper triangle: (0,0) (0,1) (0,2) (1,1) (1,2) (2,2); symmetric lookup.
    assert_eq!(t.peak(1, 2), f64::from(5e-5f32));
    assert_eq!(t.peak(2, 1), t.peak(1, 2));
    assert_eq!(t.peak(2, 2), f64::from(6e-4f32));
    // The modal entries are untouched and a base without a table still reads as before.
    let plain = tiny_base();
    let bytes = plain.to_bytes().unwrap();
    let r = ModesFile::read_from(Cursor::new(bytes), Path::new("p.modes")).unwrap();
    assert_eq!(r.transfer, None);
    // With midpoints: edges round-trip; a table written before `transfer_edges` existed (the
    // entry absent) reads as a vertex-only table.
    let mut with_edges = tiny_with_table();
    let t = with_edges.transfer.as_mut().unwrap();
    t.order = 2;
    t.edges = vec![[0, 1], [1, 2]];
    t.peaks = (0..TransferTable::packed_len(5))
        .map(|k| 1e-5 * (1 + k) as f32)
        .collect();
    let bytes = with_edges.to_bytes().unwrap();
    let r = ModesFile::read_from(Cursor::new(bytes), Path::new("e.modes")).unwrap();
    assert_eq!(r, with_edges);
    // Order 3: two points per edge and face centroids round-trip; order-2 files carry no
    // `transfer_order` entry (their bytes are those of a reader that predates it).
    let mut cubic = tiny_with_table();
    let t = cubic.transfer.as_mut().unwrap();
    t.order = 3;
    t.edges = vec![[0, 1], [0, 2], [1, 2]];
    t.faces = vec![[0, 1, 2]];
    t.peaks = (0..TransferTable::packed_len(3 + 6 + 1))
        .map(|k| 1e-5 * (1 + k) as f32)
        .collect();
    assert_eq!(t.point_support(3), ([0, 1, 0], [2.0 / 3.0, 1.0 / 3.0, 0.0]));
    assert_eq!(t.point_support(4), ([0, 1, 0], [1.0 / 3.0, 2.0 / 3.0, 0.0]));
    assert_eq!(t.point_support(9), ([0, 1, 2], [1.0 / 3.0; 3]));
    let bytes = cubic.to_bytes().unwrap();
    let r = ModesFile::read_from(Cursor::new(bytes), Path::new("c.modes")).unwrap();
    assert_eq!(r, cubic);
    let names = |b: &ModesFile| -> Vec<String> {
        let bytes = b.to_bytes().unwrap();
        let z = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
        z.file_names().map(str::to_string).collect()
    };
    assert!(names(&cubic).contains(&"transfer_order.npy".to_string()));
    assert!(!names(&with_edges).contains(&"transfer_order.npy".to_string()));
    let bytes = without_entries(&base.to_bytes().unwrap(), &["transfer_edges"]);
    let r = ModesFile::read_from(Cursor::new(bytes), Path::new("o.modes")).unwrap();
    assert_eq!(r, base);
    // Dropping every transfer entry gives back the plain base.
    let mut all = transfer_table::TRANSFER_ENTRIES.to_vec();
    all.push(transfer_table::TRANSFER_EDGES_ENTRY);
    let bytes = without_entries(&base.to_bytes().unwrap(), &all);
    let r = ModesFile::read_from(Cursor::new(bytes), Path::new("d.modes")).unwrap();
    assert_eq!(r, plain);
}

#[test]
fn partial_transfer_table_names_the_missing_entry() {
    let bytes = without_entries(&tiny_with_table().to_bytes().unwrap(), &["transfer_h"]);
    let err = ModesFile::read_from(Cursor::new(bytes), Path::new("x.modes")).unwrap_err();
    assert!(
        matches!(
            err,
            FormatError::Missing {
                entry: "transfer_h",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn corrupted_transfer_table_is_rejected_with_a_clear_error() {
    type Corrupt = fn(&mut TransferTable);
    let cases: [(Corrupt, &str); 14] = [
        (|t| t.order = 4, "transfer_order = 4"),
        (
            |t| {
                t.order = 2;
                t.faces = vec![[0, 1, 2]];
            },
            "transfer_faces is not empty",
        ),
        (
            |t| {
                t.order = 3;
                t.edges = vec![[0, 1], [0, 2], [1, 2]];
                t.faces = vec![[0, 2, 1]];
                t.peaks = vec![1e-5; TransferTable::packed_len(10)];
            },
            "transfer_faces row 0",
        ),
        (|t| t.peaks[2] = f32::NAN, "transfer_peaks[2]"),
        (|t| t.peaks[4] = -1e-6, "transfer_peaks[4]"),
        (|t| t.peaks[1] = f32::INFINITY, "transfer_peaks[1]"),
        (|t| t.peaks.truncate(5), "expected np(np+1)/2 = 6"),
        (
            |t| {
                t.order = 2;
                t.edges = vec![[0, 3]];
            },
            "transfer_edges row 0",
        ),
        (
            |t| {
                t.order = 2;
                t.edges = vec![[0, 2], [0, 1]];
            },
            "transfer_edges row 1",
        ),
        (
            |t| t.edges = vec![[0, 1]],
            "transfer_order = 1 but transfer_edges",
        ),
        (|t| t.vertices[2] = 4, "names vertex 4"),
        (|t| t.vertices = vec![0, 3, 1], "not strictly ascending"),
        (|t| t.h = 0.0, "transfer_h"),
        (|t| t.rayleigh[1] = f64::NAN, "transfer_rayleigh"),
    ];
    for (corrupt, needle) in cases {
        let mut b = tiny_with_table();
        corrupt(b.transfer.as_mut().unwrap());
        assert_refused(&b, needle);
    }
}

/// `b`, written bypassing validation (as a hostile or buggy writer would), is refused on read
/// as invalid with a message containing `needle`, and `write_atomic` never writes it.
fn assert_refused(b: &ModesFile, needle: &str) {
    let bytes = b.to_bytes().unwrap();
    let err = ModesFile::read_from(Cursor::new(bytes), Path::new("c.modes")).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(err, FormatError::Invalid { .. }) && msg.contains(needle),
        "{needle}: {msg}"
    );
    let dir = tempfile::tempdir().unwrap();
    assert!(b.write_atomic(&dir.path().join("w.modes")).is_err());
}

#[test]
fn surface_order_round_trips_and_a_bad_one_is_named() {
    let mut b = tiny_base();
    b.surface_order = Some(vec![2, 0, 3, 1]);
    let bytes = b.to_bytes().unwrap();
    let back = ModesFile::read_from(Cursor::new(&bytes[..]), Path::new("o.modes")).unwrap();
    assert_eq!(back, b);
    // Absent entry: None (bases baked before it existed still load).
    assert_eq!(
        ModesFile::read_from(Cursor::new(tiny_base().to_bytes().unwrap()), Path::new("o"))
            .unwrap()
            .surface_order,
        None
    );
    for (order, needle) in [
        (
            vec![2, 0, 3],
            "surface_order has 3 entries for 4 surface vertices",
        ),
        (vec![2, 0, 2, 1], "entry 2 is 2 (repeated"),
        (vec![2, 0, 4, 1], "entry 2 is 4 (repeated or ≥ 4)"),
    ] {
        b.surface_order = Some(order);
        assert_refused(&b, needle);
    }
}

/// `bytes` (a valid archive) with entry `name.npy` replaced by `npy`.
fn with_entry(bytes: &[u8], name: &str, npy: &[u8]) -> Vec<u8> {
    let mut zin = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..zin.len() {
        let mut f = zin.by_index(i).unwrap();
        let entry = f.name().to_string();
        w.start_file(entry.as_str(), opts).unwrap();
        if entry == format!("{name}.npy") {
            std::io::Write::write_all(&mut w, npy).unwrap();
        } else {
            std::io::copy(&mut f, &mut w).unwrap();
        }
    }
    w.finish().unwrap().into_inner()
}

// Regression: a version-2 `.npy` header declaring a 0xFFFFFFF0-byte header made every reader
// (info, probe, geodesic, check, ModalModel::load) allocate 4 GiB before failing. The header
// length is checked against the entry's real size (and numpy's 10,000-byte limit) first.
#[test]
fn npy_header_length_is_bounded_by_the_entry() {
    let good = tiny_base().to_bytes().unwrap();
    for (version, len) in [(2u8, 0xFFFF_FFF0u32), (3, 0x7FFF_0000), (2, 20_000)] {
        let mut npy = b"\x93NUMPY".to_vec();
        npy.extend_from_slice(&[version, 0]);
        npy.extend_from_slice(&len.to_le_bytes());
        npy.extend_from_slice(&[b' '; 64]);
        let bytes = with_entry(&good, "residuals", &npy);
        let err = ModesFile::read_from(Cursor::new(bytes), Path::new("h.modes")).unwrap_err();
        let msg = err.to_string();
        assert!(
            matches!(
                err,
                FormatError::Entry {
                    entry: "residuals",
                    ..
                }
            ) && msg.contains(&format!("header of {len} bytes")),
            "{msg}"
        );
    }
    // Deeply nested header text is refused before it reaches the recursive parser.
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    let h = format!("{}\n", "(".repeat(3000));
    npy.extend_from_slice(&(h.len() as u16).to_le_bytes());
    npy.extend_from_slice(h.as_bytes());
    let bytes = with_entry(&good, "residuals", &npy);
    let err = ModesFile::read_from(Cursor::new(bytes), Path::new("n.modes")).unwrap_err();
    assert!(err.to_string().contains("nest"), "{err}");
}

// Regression: NaN, infinite and negative residuals were accepted although the format says
// values are validated on read; so were indices past the volume mesh, coordinates far outside
// any object (a surface scaled by 1e150 made geodesic distances all zero) and meta values
// that cannot be. Each is refused naming the entry, the index and the range that holds.
#[test]
fn content_out_of_range_is_refused_naming_entry_index_and_range() {
    type Corrupt = fn(&mut ModesFile);
    let cases: [(Corrupt, &str); 12] = [
        (|b| b.residuals[1] = f64::NAN, "residuals[1] = NaN"),
        (|b| b.residuals[0] = f64::INFINITY, "residuals[0] = inf"),
        (
            |b| b.residuals[1] = -1e-12,
            "residuals[1] = -1e-12 (must be finite and ≥ 0)",
        ),
        (|b| b.eigenvalues[0] = -1.0, "eigenvalues[0] = -1"),
        (|b| b.surface_to_volume[2] = 4, "surface_to_volume[2] = 4"),
        (|b| b.fixed_nodes = vec![1, 7], "fixed_nodes[1] = 7"),
        (
            |b| {
                for p in &mut b.surface_vertices {
                    *p = p.map(|x| x * 1e150);
                }
            },
            "surface_vertices[1][0] = 1e150 (must be within ±1e6 m)",
        ),
        (
            |b| {
                for p in &mut b.surface_vertices {
                    *p = p.map(|x| x * 1e-9);
                }
            },
            "surface extent 1.73e-9 m (bounding-box diagonal) is below the supported 1e-6 m",
        ),
        (
            |b| b.meta.mass_kg = -1.0,
            "meta.mass_kg = -1 (must be finite and > 0)",
        ),
        (|b| b.meta.volume_nodes = 3, "volume_nodes"),
        (|b| b.meta.rigid_modes_excluded = 5, "rigid_modes_excluded"),
        (|b| b.modes[5] = f64::NAN, "modes[0][2][1] = NaN"),
    ];
    for (corrupt, needle) in cases {
        let mut b = tiny_base();
        corrupt(&mut b);
        assert_refused(&b, needle);
    }
    // The ends of the supported coordinate range load.
    for scale in [1e-5, 3e5] {
        let mut b = tiny_base();
        for p in &mut b.surface_vertices {
            *p = p.map(|x| x * scale);
        }
        let bytes = b.to_bytes().unwrap();
        ModesFile::read_from(Cursor::new(bytes), Path::new("s.modes")).unwrap();
    }
}

// Regression: reading a `.modes` path that is a device, FIFO or directory opened it (a FIFO
// blocks, `/dev/zero` never ends); it is refused by name before opening. On Windows its
// devices (`NUL`; `CON`, whose reading would wait for the console) are refused too: Windows
// answers their type with an error, which is the message.
#[test]
fn only_regular_files_are_read() {
    let dir = tempfile::tempdir().unwrap();
    #[cfg(unix)]
    let devices = [Path::new("/dev/zero")];
    #[cfg(windows)]
    let devices = [Path::new("NUL"), Path::new("CON"), Path::new(r"\\.\NUL")];
    #[cfg(not(any(unix, windows)))]
    let devices: [&Path; 0] = [];
    for path in devices.into_iter().chain([dir.path()]) {
        let err = ModesFile::read(path).unwrap_err().to_string();
        assert!(err.starts_with(&path.display().to_string()), "{err}");
        assert!(
            (cfg!(windows) && path != dir.path()) || err.contains("not a regular file"),
            "{err}"
        );
    }
}

// Regression: `-o` onto a character device replaced the device node with the base (as root,
// exit 0). Writes replace regular files only.
#[test]
#[cfg(unix)]
fn writes_never_replace_what_is_not_a_regular_file() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.modes");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let sub = dir.path().join("sub.modes");
    std::fs::create_dir(&sub).unwrap();
    for (path, what) in [(&fifo, "a FIFO"), (&sub, "a directory")] {
        let err = tiny_base().write_atomic(path).unwrap_err();
        assert!(
            matches!(&err, FormatError::Clobber { what: w, .. } if *w == what),
            "{err}"
        );
    }
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(sub.is_dir());
    // Only the FIFO, the folder and nothing else: no temporary left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

// Regression (found by the fuzz harness): an end-of-central-directory record declaring 65,535
// entries made the zip reader reserve ~7 MB for a 58 kB archive (~200 bytes per declared
// entry). Declared counts are checked first.
#[test]
fn zip_entry_counts_are_bounded_before_the_zip_reader_trusts_them() {
    let mut bytes = tiny_base().to_bytes().unwrap();
    let eocd = bytes.len() - 22;
    assert_eq!(&bytes[eocd..eocd + 4], b"PK\x05\x06");
    bytes[eocd + 8..eocd + 12].copy_from_slice(&[0xFF; 4]);
    let err = ModesFile::read_from(Cursor::new(bytes), Path::new("z.modes")).unwrap_err();
    assert!(
        matches!(err, FormatError::Archive { .. })
            && err.to_string().contains(&format!(
                "end-of-central-directory record at byte {eocd}) declares 65535 entries"
            )),
        "{err}"
    );
}
