//! Mesh readers over the committed corpus (`data/meshes`, `data/bad`, made by
//! `scripts/gen_test_meshes.py`): every form of one geometry reads to the same canonical mesh,
//! counts match gmsh's, every bad input is a clean located error, and no prefix or byte flip
//! of a valid file panics.

use std::path::{Path, PathBuf};

#[path = "common/check_args.rs"]
mod check_args;
use check_args::check_args;
#[path = "common/gmsh_gate.rs"]
mod gmsh_gate;
#[path = "common/meshio_gate.rs"]
mod meshio_gate;

use modal_bake::mesh::{
    read_json, read_mesh, read_mesh_bytes, read_msh, read_msh_bytes, signed_volume, Location,
    MeshError, MeshErrorKind, TetMesh, DEFAULT_DEGENERATE_REL_TOL, DEFAULT_STRAIGHT_REL_TOL,
};

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(rel)
}

fn read_ok(rel: &str) -> TetMesh {
    read_mesh(&data(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn read_err(rel: &str) -> MeshError {
    match read_mesh(&data(rel)) {
        Ok(m) => panic!("{rel} read fine ({} tets), expected an error", m.tets.len()),
        Err(e) => e,
    }
}

/// 1-based line of the first line of `rel` that starts with `prefix`.
fn line_of(rel: &str, prefix: &str) -> usize {
    let text = std::fs::read_to_string(data(rel)).unwrap();
    1 + text
        .lines()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("{rel} has no line starting with {prefix:?}"))
}

const CUBE_FORMS: [&str; 6] = [
    "meshes/cube_v41.msh",
    "meshes/cube_v22.msh",
    "meshes/cube_v41_bin.msh",
    "meshes/cube_v22_bin.msh",
    "meshes/cube_cell_sets.json",
    "meshes/cube_gmsh_physical.json",
];

// Expectation: MSH 2.2/4.1 ASCII/binary and both JSON group layouts give the same canonical
// mesh — node positions bit for bit, tets, triangles and groups — so a bake is byte-identical.
#[test]
fn all_cube_forms_give_identical_meshes() {
    let reference = read_ok(CUBE_FORMS[0]);
    for form in &CUBE_FORMS[1..] {
        let m = read_ok(form);
        assert_eq!(m.nodes.len(), reference.nodes.len(), "{form}: node count");
        for (i, (a, b)) in m.nodes.iter().zip(&reference.nodes).enumerate() {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{form}: node {i}");
        }
        assert_eq!(m.tets, reference.tets, "{form}: tets");
        assert_eq!(m.triangles, reference.triangles, "{form}: triangles");
        assert_eq!(m.groups, reference.groups, "{form}: groups");
        if form.ends_with(".msh") {
            assert_eq!(m.tet_ids, reference.tet_ids, "{form}: element tags");
        } else {
            // JSON ids are 1-based positions in the file, listed in canonical tet order.
            let mut ids = m.tet_ids.clone();
            ids.sort_unstable();
            let positions: Vec<u64> = (1..=m.tets.len() as u64).collect();
            assert_eq!(ids, positions, "{form}: JSON tet ids are 1-based positions");
        }
    }
}

// Expectation: node, tet, triangle and group sizes equal what gmsh reported when it wrote the
// files (data/meshes/cube_counts.json).
#[test]
fn cube_counts_match_gmsh() {
    let counts: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data("meshes/cube_counts.json")).unwrap()).unwrap();
    for form in CUBE_FORMS {
        let m = read_ok(form);
        assert_eq!(
            m.nodes.len() as u64,
            counts["nodes"].as_u64().unwrap(),
            "{form}"
        );
        assert_eq!(
            m.tets.len() as u64,
            counts["tets"].as_u64().unwrap(),
            "{form}"
        );
        assert_eq!(
            m.triangles.len() as u64,
            counts["triangles_in_groups"].as_u64().unwrap(),
            "{form}"
        );
        let groups = counts["groups"].as_object().unwrap();
        let names: Vec<&String> = groups.keys().collect();
        assert_eq!(
            m.groups.keys().collect::<Vec<_>>(),
            names,
            "{form}: group names"
        );
        for (name, n) in groups {
            assert_eq!(
                m.groups[name].len() as u64,
                n.as_u64().unwrap(),
                "{form}: {name}"
            );
        }
        assert!(
            (m.volume() - 1.0).abs() < 1e-12,
            "{form}: volume {}",
            m.volume()
        );
        assert_eq!(m.connected_components(), 1);
    }
}

// Expectation: groups are the right node sets in the right places, unnamed groups are named
// by tag, and skipped element types leave one note each.
#[test]
fn cube_groups_geometry_and_notes() {
    let m = read_ok("meshes/cube_v41.msh");
    for &v in &m.groups["bottom"] {
        assert_eq!(m.nodes[v][2], 0.0);
    }
    for &v in &m.groups["top"] {
        assert_eq!(m.nodes[v][2], 1.0);
    }
    for &v in &m.groups["77"] {
        assert_eq!(m.nodes[v][0], 0.0);
    }
    assert_eq!(m.nodes[m.groups["corner"][0]], [0.0, 0.0, 0.0]);
    let on_z0 = m.nodes.iter().filter(|x| x[2] == 0.0).count();
    assert_eq!(m.groups["bottom"].len(), on_z0);
    for g in m.groups.values() {
        assert!(g.windows(2).all(|w| w[0] < w[1]), "sorted, deduplicated");
    }
    for form in ["meshes/cube_v41.msh", "meshes/cube_v22_bin.msh"] {
        let m = read_ok(form);
        assert!(
            m.notes
                .contains(&"skipped 1 element of gmsh type 15 (1-node point)".to_string()),
            "{form}: {:?}",
            m.notes
        );
        assert!(
            m.notes
                .iter()
                .any(|n| n.contains("gmsh type 1 (2-node line)")),
            "{form}: {:?}",
            m.notes
        );
    }
}

// Expectation: the cantilever beam is 1.0 × 0.1 × 0.1 m, positively oriented as gmsh writes
// it, one piece, clamped at x = 0.
#[test]
fn beam_reads_with_clamp_group() {
    let mut m = read_msh(&data("meshes/beam.msh")).unwrap();
    assert!((m.volume() - 0.01).abs() < 1e-12);
    assert_eq!(m.orient_tets(DEFAULT_DEGENERATE_REL_TOL).unwrap(), 0);
    assert_eq!(m.connected_components(), 1);
    let clamp = m.group_nodes("clamp").unwrap();
    assert!(clamp.len() >= 9);
    assert!(clamp.iter().all(|&v| m.nodes[v][0] == 0.0));
    assert!(m.group_nodes("volume").unwrap().len() == m.nodes.len());
    let max = m
        .nodes
        .iter()
        .fold([f64::MIN; 3], |a, x| [0, 1, 2].map(|k| a[k].max(x[k])));
    assert_eq!(max, [1.0, 0.1, 0.1]);
}

// Expectation: canonical form does not depend on node order or tag numbering in the file,
// and drops nodes that no tetrahedron uses (with a note).
#[test]
fn canonical_form_ignores_node_order_and_drops_unused_nodes() {
    let ordered = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n\
                   3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n$Elements\n2\n\
                   1 4 0 1 2 3 4\n2 4 0 2 3 4 5\n$EndElements\n";
    // Same geometry: tags ×10, listed backwards, plus an unused node 25 in the middle.
    let shuffled = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n50 1 1 1\n40 0 0 1\n\
                    25 9 9 9\n30 0 1 0\n20 1 0 0\n10 0 0 0\n$EndNodes\n$Elements\n2\n\
                    2 4 0 20 30 40 50\n1 4 0 10 20 30 40\n$EndElements\n";
    let a = read_msh_bytes(ordered.as_bytes(), "ordered.msh").unwrap();
    let b = read_msh_bytes(shuffled.as_bytes(), "shuffled.msh").unwrap();
    assert_eq!(a.nodes, b.nodes);
    assert_eq!(a.tets, b.tets);
    assert_eq!(a.tet_ids, vec![1, 2]);
    assert!(
        b.notes.iter().any(|n| n.contains("dropped 1 nodes")),
        "{:?}",
        b.notes
    );
}

/// Asserts `e` is located at `location` and its message starts with the file name.
fn assert_located(e: &MeshError, rel: &str, location: Location) {
    assert_eq!(e.location, location, "{rel}: {e}");
    let shown = e.to_string();
    assert!(
        shown.starts_with(&data(rel).display().to_string()),
        "message does not name the file: {shown}"
    );
}

// Expectation: each defect of data/bad gives its own error kind, located by line (ASCII) or
// element, with a message that names the file.
#[test]
fn bad_msh_files_give_located_errors() {
    let e = read_err("bad/nan_coordinate.msh");
    assert_eq!(e.kind, MeshErrorKind::NonFiniteCoordinate { node: 5 });
    let line = line_of("bad/nan_coordinate.msh", "5 1.0 nan");
    assert_located(&e, "bad/nan_coordinate.msh", Location::Line(line));
    let expected = format!(
        "{}:{line}: non-finite coordinate in node 5",
        data("bad/nan_coordinate.msh").display()
    );
    assert_eq!(e.to_string(), expected);

    let e = read_err("bad/inf_coordinate.msh");
    assert_eq!(e.kind, MeshErrorKind::NonFiniteCoordinate { node: 2 });

    let e = read_err("bad/non_numeric.msh");
    assert!(
        matches!(&e.kind, MeshErrorKind::NotANumber { found, .. } if found == "1.O"),
        "{e}"
    );
    let line = line_of("bad/non_numeric.msh", "3 0.0 1.O");
    assert_located(&e, "bad/non_numeric.msh", Location::Line(line));

    let e = read_err("bad/truncated.msh");
    assert!(matches!(e.kind, MeshErrorKind::Truncated(_)), "{e}");

    let e = read_err("bad/missing_node.msh");
    assert_eq!(
        e.kind,
        MeshErrorKind::MissingNode {
            element: 6,
            node: 99
        }
    );
    let line = line_of("bad/missing_node.msh", "6 4 ");
    assert_located(&e, "bad/missing_node.msh", Location::Line(line));
    assert!(e.to_string().contains("element 6 names node 99"), "{e}");

    let e = read_err("bad/no_tets.msh");
    assert!(
        matches!(&e.kind, MeshErrorKind::NoTets { found, .. } if found == "2 triangles"),
        "{e}"
    );
    assert!(e.to_string().contains("`gmsh FILE.geo -3`"), "{e}");
    // A 10-node tet reads as second-order; its mid-edge nodes are off the edges (curved).
    let m = read_ok("bad/second_order_only.msh");
    assert!(m.is_quadratic() && m.tets.len() == 1 && m.nodes.len() == 10);
    let e = m.check_straight(1e-6).unwrap_err();
    assert!(
        matches!(e.kind, MeshErrorKind::CurvedTet { element: 1, .. }),
        "{e}"
    );

    let e = read_err("bad/huge_count.msh");
    assert_eq!(
        e.kind,
        MeshErrorKind::CountTooLarge {
            what: "nodes",
            count: 1_000_000_000_000
        }
    );
    assert_located(
        &e,
        "bad/huge_count.msh",
        Location::Line(line_of("bad/huge_count.msh", "1000000000000")),
    );

    let e = read_err("bad/bad_version.msh");
    assert_eq!(e.kind, MeshErrorKind::UnsupportedVersion("3.0".into()));
    assert_located(&e, "bad/bad_version.msh", Location::Line(2));

    let e = read_err("bad/missing_elements.msh");
    assert_eq!(e.kind, MeshErrorKind::MissingSection("$Elements"));

    let e = read_err("bad/duplicate_node.msh");
    assert_eq!(e.kind, MeshErrorKind::DuplicateNode { node: 3 });

    let e = read_err("bad/not_a_mesh.msh");
    assert!(matches!(e.kind, MeshErrorKind::MissingSection(_)), "{e}");
}

// Expectation: JSON with wrong shapes, types, ragged rows, negative or dangling indices is a
// clean error located by a JSON path (or a line for syntax errors).
#[test]
fn bad_json_files_give_located_errors() {
    let path = |p: &str| Location::Path(p.to_string());
    let e = read_err("bad/bad_shape.json");
    assert!(matches!(e.kind, MeshErrorKind::Shape(_)), "{e}");
    assert_located(&e, "bad/bad_shape.json", path("points[2]"));

    let e = read_err("bad/ragged.json");
    assert!(matches!(e.kind, MeshErrorKind::Shape(_)), "{e}");
    assert_located(&e, "bad/ragged.json", path("cells[0].data[1]"));

    let e = read_err("bad/wrong_type.json");
    assert!(matches!(e.kind, MeshErrorKind::Shape(_)), "{e}");
    assert_located(&e, "bad/wrong_type.json", path("points[1][0]"));

    let e = read_err("bad/negative_index.json");
    assert_eq!(e.kind, MeshErrorKind::NegativeIndex(-3));
    assert_located(&e, "bad/negative_index.json", path("cells[0].data[1][2]"));

    let e = read_json(&data("bad/missing_node.json")).unwrap_err();
    assert_eq!(
        e.kind,
        MeshErrorKind::MissingNode {
            element: 2,
            node: 9
        }
    );

    let e = read_err("bad/cells_not_list.json");
    assert!(matches!(e.kind, MeshErrorKind::Shape(_)), "{e}");

    let e = read_err("bad/syntax_error.json");
    assert!(matches!(e.kind, MeshErrorKind::Json(_)), "{e}");
    assert_located(&e, "bad/syntax_error.json", Location::Line(2));
}

// Expectation: an inverted tet reads fine and orient_tets flips exactly it; a flat tet is an
// error naming its element tag; two disjoint pieces count as two components.
#[test]
fn orientation_degeneracy_and_components() {
    let mut m = read_ok("bad/inverted_tet.msh");
    assert_eq!(m.orient_tets(DEFAULT_DEGENERATE_REL_TOL).unwrap(), 1);
    for t in &m.tets {
        assert!(signed_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]) > 0.0);
    }
    assert_eq!(m.orient_tets(DEFAULT_DEGENERATE_REL_TOL).unwrap(), 0);

    let mut m = read_ok("bad/zero_volume.msh");
    let before = m.clone();
    let e = m.orient_tets(DEFAULT_DEGENERATE_REL_TOL).unwrap_err();
    assert!(
        matches!(e.kind, MeshErrorKind::DegenerateTet { element: 7, .. }),
        "{e}"
    );
    assert_eq!(e.location, Location::Element(7));
    assert!(e.to_string().starts_with("element 7: degenerate"), "{e}");
    assert_eq!(m, before, "mesh unchanged on error");

    let mut nan = read_ok("bad/inverted_tet.msh");
    nan.nodes[0][0] = f64::NAN;
    assert!(nan.orient_tets(DEFAULT_DEGENERATE_REL_TOL).is_err());

    let m = read_ok("bad/two_pieces.msh");
    assert_eq!(m.connected_components(), 2);
    assert_eq!(read_ok("bad/inverted_tet.msh").connected_components(), 1);
}

// Expectation: asking for a missing group lists the groups there are.
#[test]
fn unknown_group_lists_available_names() {
    let m = read_ok("meshes/cube_v22.msh");
    let e = m.group_nodes("clamp").unwrap_err();
    assert_eq!(
        e.to_string(),
        "no node group named \"clamp\"; available groups: 77, bottom, corner, edge, top, volume"
    );
    assert_eq!(m.group_nodes("top").unwrap(), m.groups["top"].as_slice());
}

/// Position just after the first occurrence of `needle` in `hay`.
fn after(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).position(|w| w == needle).unwrap() + needle.len()
}

// Expectation: binary count fields are distrusted too: a 10^12 node count is refused before
// any allocation, and a wrong endianness word is reported at its byte offset.
#[test]
fn binary_counts_and_endianness_are_checked() {
    let orig = std::fs::read(data("meshes/cube_v41_bin.msh")).unwrap();
    let mut bytes = orig.clone();
    let at = after(&bytes, b"$Nodes\n");
    // numEntityBlocks, numNodes, minTag, maxTag (size_t, little-endian).
    bytes[at + 8..at + 16].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
    let e = read_msh_bytes(&bytes, "huge.msh").unwrap_err();
    assert_eq!(
        e.kind,
        MeshErrorKind::CountTooLarge {
            what: "nodes",
            count: 1_000_000_000_000
        }
    );
    assert_eq!(e.location, Location::Byte(at));

    let mut bytes = orig.clone();
    let at = after(&bytes, b"4.1 1 8\n");
    bytes[at..at + 4].copy_from_slice(&2u32.to_le_bytes());
    let e = read_msh_bytes(&bytes, "endian.msh").unwrap_err();
    assert_eq!(e.kind, MeshErrorKind::BadEndianness(2));
    assert_eq!(
        e.to_string(),
        format!("endian.msh: byte {at}: bad endianness check integer 0x00000002 (expected 1)")
    );
}

// Expectation: the same mesh written big-endian (every 4/8-byte binary value byte-swapped)
// reads to the same canonical mesh. Built here from the little-endian 2.2 file by walking its
// documented layout.
#[test]
fn big_endian_msh22_matches_little_endian() {
    let le = std::fs::read(data("meshes/cube_v22_bin.msh")).unwrap();
    let mut be = le.clone();
    let swap = |b: &mut [u8], at: usize, n: usize| b[at..at + n].reverse();
    let rd = |b: &[u8], at: usize| i32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let at = after(&le, b"2.2 1 8\n");
    swap(&mut be, at, 4);
    let nodes_at = after(&le, b"$Nodes\n");
    let nl = nodes_at + le[nodes_at..].iter().position(|&c| c == b'\n').unwrap();
    let n: usize = std::str::from_utf8(&le[nodes_at..nl])
        .unwrap()
        .parse()
        .unwrap();
    let mut p = nl + 1;
    for _ in 0..n {
        swap(&mut be, p, 4);
        for k in 0..3 {
            swap(&mut be, p + 4 + 8 * k, 8);
        }
        p += 28;
    }
    let el_at = after(&le, b"$Elements\n");
    let nl = el_at + le[el_at..].iter().position(|&c| c == b'\n').unwrap();
    let total: usize = std::str::from_utf8(&le[el_at..nl])
        .unwrap()
        .parse()
        .unwrap();
    let mut p = nl + 1;
    let mut read = 0;
    while read < total {
        let (ty, follow, ntags) = (rd(&le, p), rd(&le, p + 4), rd(&le, p + 8));
        for k in 0..3 {
            swap(&mut be, p + 4 * k, 4);
        }
        p += 12;
        let nn = match ty {
            15 => 1,
            1 => 2,
            2 => 3,
            4 => 4,
            other => panic!("unexpected type {other}"),
        };
        for _ in 0..follow as usize * (1 + ntags as usize + nn) {
            swap(&mut be, p, 4);
            p += 4;
        }
        read += follow as usize;
    }
    assert_ne!(be, le);
    let a = read_msh_bytes(&le, "le.msh").unwrap();
    let b = read_msh_bytes(&be, "be.msh").unwrap();
    assert_eq!(a, b);
}

/// Reads `bytes` and fails the test with `what` if the reader panics.
fn must_not_panic(bytes: &[u8], name: &str, what: &str) {
    let r = std::panic::catch_unwind(|| {
        let _ = read_mesh_bytes(bytes, name);
    });
    assert!(r.is_ok(), "{name}: reader panicked on {what}");
}

// Expectation: every prefix (every ~50th byte) and many single-byte corruptions of every
// valid file give Ok or Err, never a panic or runaway allocation.
#[test]
fn truncation_and_byte_flips_never_panic() {
    let mut files: Vec<&str> = CUBE_FORMS.to_vec();
    files.push("meshes/beam.msh");
    let mut prefixes_ok = 0;
    for rel in files {
        let bytes = std::fs::read(data(rel)).unwrap();
        let name = rel.rsplit('/').next().unwrap();
        for cut in (0..bytes.len()).step_by(47) {
            must_not_panic(&bytes[..cut], name, &format!("prefix of {cut} bytes"));
            if read_mesh_bytes(&bytes[..cut], name).is_ok() {
                prefixes_ok += 1;
            }
        }
        for (i, at) in (0..bytes.len()).step_by(53).enumerate() {
            for flip in [0xFFu8, 0x01, 0x80] {
                let mut b = bytes.clone();
                b[at] ^= flip;
                must_not_panic(&b, name, &format!("byte {at} ^ {flip:#x}"));
            }
            // Also a digit, a minus sign and a huge byte run in a count-sized window.
            let mut b = bytes.clone();
            b[at] = [b'9', b'-', b'.', b'$'][i % 4];
            must_not_panic(&b, name, &format!("byte {at} replaced"));
            if at + 8 <= b.len() {
                b[at..at + 8].copy_from_slice(&[0x7F; 8]);
                must_not_panic(&b, name, &format!("8 bytes at {at} set to 0x7f"));
            }
        }
    }
    // Truncated files must fail (a prefix cut just before trailing newlines may still read).
    assert!(
        prefixes_ok <= 7,
        "{prefixes_ok} prefixes read as complete meshes"
    );
}

// Regression: MSH 2.2 has one physical tag per element, so gmsh writes an element of two
// physical groups twice under different tags. It must count once and join both groups.
#[test]
fn msh22_element_in_two_groups_is_one_tet() {
    let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 2 \"b\"\n\
                $EndPhysicalNames\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n\
                $Elements\n2\n7 4 2 1 1 1 2 3 4\n8 4 2 2 1 1 2 3 4\n$EndElements\n";
    let m = read_msh_bytes(text.as_bytes(), "two_groups.msh").unwrap();
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(m.tet_ids, vec![7]);
    assert_eq!(m.groups["1"], vec![0, 1, 2, 3]);
    assert_eq!(m.groups["b"], vec![0, 1, 2, 3]);
    assert!(
        m.notes.iter().any(|n| n.contains("removed 1 duplicated")),
        "{:?}",
        m.notes
    );
}

// Expectation: a NaN in binary node data is reported at the byte offset of its node record.
#[test]
fn binary_nan_is_located_by_byte_offset() {
    let mut bytes = std::fs::read(data("meshes/cube_v22_bin.msh")).unwrap();
    let at = after(&bytes, b"$Nodes\n");
    let first = at + bytes[at..].iter().position(|&c| c == b'\n').unwrap() + 1;
    // Third node record: int tag + 3 doubles = 28 bytes each; poison its y.
    let record = first + 2 * 28;
    let tag = i32::from_le_bytes(bytes[record..record + 4].try_into().unwrap()) as u64;
    bytes[record + 12..record + 20].copy_from_slice(&f64::NAN.to_le_bytes());
    let e = read_msh_bytes(&bytes, "nan_bin.msh").unwrap_err();
    assert_eq!(e.kind, MeshErrorKind::NonFiniteCoordinate { node: tag });
    assert_eq!(e.location, Location::Byte(record));
    assert_eq!(
        e.to_string(),
        format!("nan_bin.msh: byte {record}: non-finite coordinate in node {tag}")
    );
}

// Regression: a section repeated after the data that depends on it (a second `$Nodes` after
// `$Elements`, MSH 2.2 and 4.1) replaced the node table under the elements and panicked; an
// `$Elements` before `$Nodes` cannot be read. Each is refused at the offending header's line.
#[test]
fn repeated_or_out_of_order_sections_are_refused_at_their_line() {
    for rel in ["bad/repeated_nodes.msh", "bad/repeated_nodes_v41.msh"] {
        let e = read_err(rel);
        let first = line_of(rel, "$Nodes");
        assert_eq!(
            e.kind,
            MeshErrorKind::DuplicateSection {
                section: "Nodes",
                first
            },
            "{rel}: {e}"
        );
        let text = std::fs::read_to_string(data(rel)).unwrap();
        let second = 1 + text
            .lines()
            .enumerate()
            .filter(|(_, l)| *l == "$Nodes")
            .nth(1)
            .unwrap()
            .0;
        assert_located(&e, rel, Location::Line(second));
    }
    let rel = "bad/elements_before_nodes.msh";
    let e = read_err(rel);
    assert!(
        matches!(e.kind, MeshErrorKind::MissingSection(s) if s.contains("$Nodes")),
        "{e}"
    );
    assert_located(&e, rel, Location::Line(line_of(rel, "$Elements")));
}

// Regression: tags and records are read as written, never guessed. A negative node tag in an
// element was read as node 0, a tag 0 accepted, an extra value on an element line swallowed the
// next element, a short line borrowed the next line's first value.
#[test]
fn bad_tags_and_records_are_refused_at_their_line() {
    let rel = "bad/negative_node_tag.msh";
    let e = read_err(rel);
    assert_eq!(
        e.kind,
        MeshErrorKind::InvalidTag {
            what: "element node tag",
            found: "-5".into()
        },
        "{e}"
    );
    assert_located(&e, rel, Location::Line(line_of(rel, "6 4 ")));

    let rel = "bad/zero_node_tag.msh";
    let e = read_err(rel);
    assert!(
        matches!(&e.kind, MeshErrorKind::InvalidTag { what: "node tag", found } if found == "0"),
        "{e}"
    );
    assert_located(&e, rel, Location::Line(line_of(rel, "0 0.0")));

    let rel = "bad/extra_value.msh";
    let e = read_err(rel);
    assert!(
        matches!(&e.kind, MeshErrorKind::ExtraValue { found, .. } if found == "5"),
        "{e}"
    );
    assert_located(&e, rel, Location::Line(line_of(rel, "5 4 ")));

    let rel = "bad/short_record.msh";
    let e = read_err(rel);
    assert!(matches!(e.kind, MeshErrorKind::ShortLine(_)), "{e}");
    assert_located(&e, rel, Location::Line(line_of(rel, "5 4 ")));

    // The same defects in MSH 4.1 ASCII: an extra value on a node coordinate line, a node tag
    // line holding two tags, a tag 0.
    let good = std::fs::read_to_string(data("bad/repeated_nodes_v41.msh")).unwrap();
    let good = &good[..good.find("$EndElements").unwrap() + "$EndElements\n".len()];
    read_msh_bytes(good.as_bytes(), "v41.msh").unwrap();
    for (from, to, line) in [
        ("\n1.0 0.0 0.0\n", "\n1.0 0.0 0.0 7\n", 13),
        ("\n2\n3\n", "\n2 3\n", 8),
        ("\n5 1 2 3 4\n", "\n0 1 2 3 4\n", 21),
        ("\n6 2 3 4 5\n", "\n6 2 3 4 5 1\n", 22),
    ] {
        let text = good.replacen(from, to, 1);
        let e = read_msh_bytes(text.as_bytes(), "v41.msh").unwrap_err();
        assert_eq!(e.location, Location::Line(line), "{to:?}: {e}");
    }
}

// Regression: a tetrahedron repeated with its nodes in another order was kept as a second,
// overlapping element (mass 513 kg read as 642 kg); it is refused naming both elements. Two
// distinct tetrahedra on the same side of a shared face overlap too: the mesh check names both.
#[test]
fn overlapping_tets_are_refused_naming_both_elements() {
    let e = read_err("bad/permuted_duplicate_tet.msh");
    assert_eq!(
        e.kind,
        MeshErrorKind::DuplicateTet {
            first: 5,
            second: 7
        },
        "{e}"
    );
    assert_located(&e, "bad/permuted_duplicate_tet.msh", Location::Element(7));

    let mut m = read_ok("bad/overlapping_tets.msh");
    m.orient_tets(DEFAULT_DEGENERATE_REL_TOL).unwrap();
    let e = m.check_overlaps().unwrap_err();
    assert_eq!(
        e.kind,
        MeshErrorKind::OverlappingTets {
            first: 5,
            second: 7
        },
        "{e}"
    );
    // Valid meshes pass: every interior face is shared once from each side.
    for form in CUBE_FORMS {
        read_ok(form).check_overlaps().unwrap();
    }
    let mut m = read_ok("bad/inverted_tet.msh");
    m.orient_tets(DEFAULT_DEGENERATE_REL_TOL).unwrap();
    m.check_overlaps().unwrap();
}

// Expectation: gmsh skips sections it does not know wherever they are, also before
// `$MeshFormat` (it stores `$Comments` as a model attribute); so do the readers.
#[test]
fn unknown_sections_are_skipped_anywhere() {
    let m = read_ok("bad/comments_first.msh");
    assert_eq!(m.tets.len(), 2);
    let plain = std::fs::read_to_string(data("bad/comments_first.msh")).unwrap();
    let plain = &plain[plain.find("$MeshFormat").unwrap()..];
    assert_eq!(m, read_msh_bytes(plain.as_bytes(), "plain.msh").unwrap());
    // A known section before `$MeshFormat` is refused.
    let early = format!("$Nodes\n0\n$EndNodes\n{plain}");
    let e = read_msh_bytes(early.as_bytes(), "early.msh").unwrap_err();
    assert_eq!(e.location, Location::Line(1), "{e}");
}

// Regression: `bake /dev/zero` read 2 GB before failing. Only regular files are read (their
// size bounds the read); a directory, a device or a FIFO is refused by name, at once.
#[test]
#[cfg(unix)]
fn only_regular_files_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.msh");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(status.success());
    for path in [
        std::path::PathBuf::from("/dev/zero"),
        dir.path().to_path_buf(),
        fifo,
    ] {
        let e = read_mesh(&path).unwrap_err();
        assert!(
            matches!(e.kind, MeshErrorKind::NotARegularFile(_)),
            "{}: {e}",
            path.display()
        );
        assert!(
            e.to_string().starts_with(&path.display().to_string()),
            "{e}"
        );
    }
}

// Regression: one gmsh mesh written as MSH 4.1 ASCII and as MSH 2.2 binary carried coordinates
// one ulp apart (gmsh prints ASCII with `%.16g`), so the geometry hash differed and `check`
// called a base stale. The hash keys coordinates at 16 significant digits: both forms hash
// alike, while the bits really differ.
#[test]
fn gmsh_ascii_and_binary_forms_hash_alike() {
    use modal_bake::bake::geometry_hash;
    let ascii = read_ok("meshes/cylinder_v41.msh");
    let binary = read_ok("meshes/cylinder_v22_bin.msh");
    assert_eq!(ascii.tets, binary.tets);
    let differ = ascii
        .nodes
        .iter()
        .flatten()
        .zip(binary.nodes.iter().flatten())
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert!(differ > 0, "the two forms should differ in some bits");
    let fixed = ascii.groups["bottom"].clone();
    assert_eq!(
        geometry_hash(&ascii, &fixed),
        geometry_hash(&binary, &fixed)
    );
    // A real change of geometry (one coordinate moved by 1e-12 m) still changes the hash.
    let mut moved = binary.clone();
    moved.nodes[3][1] += 1e-12;
    assert_ne!(
        geometry_hash(&moved, &fixed),
        geometry_hash(&binary, &fixed)
    );
}

/// MSH 2.2 ASCII: a tetrahedron (nodes 1–4) under the face 1-2-3, `extra` element lines after
/// it (numbered from 2), and seven nodes (5–7 above the face, for a prism).
fn tet_and(extra: &[&str]) -> String {
    let mut s = String::from(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n7\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
         4 0 0 -1\n5 0 0 1\n6 1 0 1\n7 0 1 1\n$EndNodes\n$Elements\n",
    );
    s += &format!("{}\n1 4 2 1 1 1 2 3 4\n", 1 + extra.len());
    for (i, e) in extra.iter().enumerate() {
        s += &format!("{} {e}\n", i + 2);
    }
    s + "$EndElements\n"
}

// Expectation: volume elements other than 4- and 10-node tetrahedra (prisms, hexahedra,
// pyramids, higher-order tetrahedra) beside the tetrahedra are refused, naming their count
// and type, in MSH and meshio JSON alike: leaving them out would bake part of the object (a
// lighter object with other modes). Points, lines and quadrangles are still skipped with a
// note.
#[test]
fn other_volume_elements_are_refused_not_left_out() {
    // The same file without the prism reads, with the line and the quadrangle as notes.
    let m = read_msh_bytes(
        tet_and(&["1 2 1 1 1 2", "3 2 1 1 5 6 7 5"]).as_bytes(),
        "ok.msh",
    )
    .unwrap();
    assert_eq!(m.tets.len(), 1);
    assert_eq!(m.notes.len(), 3, "{:?}", m.notes);
    for (extra, what) in [
        (
            "6 2 1 1 1 2 3 5 6 7",
            "1 element of gmsh type 6 (6-node prism)",
        ),
        (
            "7 2 1 1 1 2 6 5 4",
            "1 element of gmsh type 7 (5-node pyramid)",
        ),
    ] {
        let e =
            read_msh_bytes(tet_and(&["1 2 1 1 1 2", extra]).as_bytes(), "mixed.msh").unwrap_err();
        assert_eq!(
            e.kind,
            MeshErrorKind::OtherVolumeElements { found: what.into() },
            "{extra}"
        );
        let text = e.to_string();
        assert!(text.starts_with("mixed.msh"), "{text}");
        assert!(text.contains("Recombine"), "{text}");
    }
    // meshio JSON: a tetra block and a wedge block.
    let json = |second: &str| {
        format!(
            r#"{{"points": [[0,0,0],[1,0,0],[0,1,0],[0,0,-1],[0,0,1],[1,0,1],[0,1,1]],
                "cells": [{{"type": "tetra", "data": [[0,1,2,3]]}}, {second}]}}"#
        )
    };
    let ok = json(r#"{"type": "quad", "data": [[0,1,5,4]]}"#);
    assert_eq!(
        read_mesh_bytes(ok.as_bytes(), "ok.json")
            .unwrap()
            .tets
            .len(),
        1
    );
    let bad = json(r#"{"type": "wedge", "data": [[0,1,2,4,5,6], [0,1,2,4,5,6]]}"#);
    let e = read_mesh_bytes(bad.as_bytes(), "mixed.json").unwrap_err();
    assert_eq!(
        e.kind,
        MeshErrorKind::OtherVolumeElements {
            found: "2 cells of type \"wedge\"".into()
        }
    );
}

// Expectation: a file without tetrahedra says what it holds instead (a surface mesh's
// triangles and lines) and how to mesh the volume.
#[test]
fn a_mesh_without_tetrahedra_says_what_it_holds() {
    let surface = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
                   4 0 0 1\n$EndNodes\n$Elements\n3\n1 1 2 1 1 1 2\n2 2 2 1 1 1 2 3\n\
                   3 3 2 1 1 1 2 3 4\n$EndElements\n";
    let e = read_msh_bytes(surface.as_bytes(), "t1.msh").unwrap_err();
    let found = "1 triangle, 1 element of gmsh type 1 (2-node line), 1 element of gmsh type 3 \
                 (4-node quadrangle)";
    assert!(
        matches!(&e.kind, MeshErrorKind::NoTets { found: f, .. } if f == found),
        "{e}"
    );
    assert!(e.to_string().contains("a `Volume` in the geometry"), "{e}");
    let e = read_mesh_bytes(br#"{"points": [[0,0,0]], "cells": []}"#, "empty.json").unwrap_err();
    assert!(
        matches!(&e.kind, MeshErrorKind::NoTets { found, .. } if found == "no elements"),
        "{e}"
    );
    // Only volume elements of another kind (gmsh `-order 3`: 20-node tetrahedra): the fix is
    // the element order, not a volume.
    let p3 = tet_and(&[]).replace(
        "1 4 2 1 1 1 2 3 4",
        "1 29 2 1 1 1 2 3 4 5 6 7 1 2 3 4 5 6 7 1 2 3 4 5 6",
    );
    let e = read_msh_bytes(p3.as_bytes(), "p3.msh").unwrap_err();
    assert!(
        matches!(&e.kind, MeshErrorKind::NoTets { found, .. }
            if found == "1 element of gmsh type 29 (20-node tetrahedron)"),
        "{e}"
    );
    assert!(e.to_string().contains("`-order 1` or `-order 2`"), "{e}");
}

/// A box 0.1 × 0.1 × 0.05 m as gmsh tutorial t3 builds its volumes: a square extruded 0.02 m
/// in 2 layers (`Recombine`: prisms; without it, tetrahedra), then the top face extruded
/// 0.03 m as a free volume (tetrahedra). Written by the real gmsh as binary MSH 4.1.
fn gmsh_extruded_box(dir: &Path, recombine: bool) -> PathBuf {
    let recombine = if recombine { " Recombine;" } else { "" };
    let geo = format!(
        "SetFactory(\"Built-in\");\nMesh.MshFileVersion = 4.1;\nMesh.Binary = 1;\n\
         lc = 0.02;\nPoint(1) = {{0, 0, 0, lc}};\nPoint(2) = {{0.1, 0, 0, lc}};\n\
         Point(3) = {{0.1, 0.1, 0, lc}};\nPoint(4) = {{0, 0.1, 0, lc}};\n\
         Line(1) = {{1, 2}};\nLine(2) = {{2, 3}};\nLine(3) = {{3, 4}};\nLine(4) = {{4, 1}};\n\
         Curve Loop(1) = {{1, 2, 3, 4}};\nPlane Surface(1) = {{1}};\n\
         out[] = Extrude {{0, 0, 0.02}} {{ Surface{{1}}; Layers{{2}};{recombine} }};\n\
         Extrude {{0, 0, 0.03}} {{ Surface{{out[0]}}; }}\n"
    );
    gmsh_volume_mesh(dir, "box", &geo)
}

/// Runs the real gmsh with its command line `args`: the `gmsh` launcher, or the PyPI module
/// through Python when the launcher is not on PATH (as `modal-bake` itself runs it); whether
/// it succeeded.
fn run_gmsh(args: &[&std::ffi::OsStr]) -> bool {
    match std::process::Command::new("gmsh").args(args).output() {
        Ok(out) => out.status.success(),
        Err(_) => std::process::Command::new("python3")
            .args([
                "-c",
                "import gmsh, sys; gmsh.initialize(['gmsh'] + sys.argv[1:], \
                 readConfigFiles=False, run=True); gmsh.finalize()",
            ])
            .args(args)
            .output()
            .is_ok_and(|o| o.status.success()),
    }
}

/// The real gmsh's volume mesh of the `.geo` script `geo` (its text), both written in `dir`
/// as `STEM.geo` and `STEM.msh`.
fn gmsh_volume_mesh(dir: &Path, stem: &str, geo: &str) -> PathBuf {
    let (geo_path, msh) = (
        dir.join(format!("{stem}.geo")),
        dir.join(format!("{stem}.msh")),
    );
    std::fs::write(&geo_path, geo).unwrap();
    let ok = run_gmsh(&[
        geo_path.as_os_str(),
        "-3".as_ref(),
        "-o".as_ref(),
        msh.as_os_str(),
    ]);
    assert!(
        ok && msh.exists(),
        "gmsh could not mesh {}",
        geo_path.display()
    );
    msh
}

// Expectation (real gmsh): a volume extruded in layers with `Recombine` (prisms) next to a
// tetrahedral one, as gmsh tutorial t3 makes, is refused with the prisms' count — it used to
// read as the tetrahedral part alone, 60 % of the volume — and the fix the message gives
// (no `Recombine`) reads as the whole box, 5e-4 m³.
#[test]
fn gmsh_extruded_prisms_are_refused_and_the_fix_reads_the_whole_volume() {
    if !gmsh_gate::have_gmsh("gmsh_extruded_prisms_are_refused_and_the_fix_reads_the_whole_volume")
    {
        return;
    }
    let tmp = std::env::temp_dir().join(format!("dcr-mixed-volume-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let msh = gmsh_extruded_box(&tmp, true);
    let e = read_mesh(&msh).unwrap_err();
    match &e.kind {
        MeshErrorKind::OtherVolumeElements { found } => {
            assert!(found.contains("(6-node prism)"), "{found}")
        }
        other => panic!("expected the prisms refused, got {other:?}"),
    }
    assert!(e.to_string().contains("Recombine"), "{e}");
    let m = read_mesh(&gmsh_extruded_box(&tmp, false)).unwrap();
    let volume = m.volume();
    assert!((volume - 5e-4).abs() < 1e-12, "volume {volume:e} m³");
    std::fs::remove_dir_all(&tmp).unwrap();
}

// Expectation: `read_msh_object` keeps the tetrahedra of one 3-D physical group, named or by
// its number, and only the nodes they use; an element of two groups (MSH 2.2 writes it twice)
// belongs to both; a name no tetrahedron has is refused with the groups the file has.
#[test]
fn one_physical_volume_of_a_msh_is_read_alone() {
    use modal_bake::mesh::read_msh_object_bytes;
    let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n3 1 \"left\"\n\
               3 3 \"both\"\n$EndPhysicalNames\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
               4 0 0 1\n5 5 0 0\n6 6 0 0\n7 5 1 0\n8 5 0 1\n$EndNodes\n$Elements\n4\n\
               1 4 2 1 1 1 2 3 4\n2 4 2 3 1 1 2 3 4\n3 4 2 2 2 5 6 7 8\n4 4 2 3 2 5 6 7 8\n\
               $EndElements\n";
    let whole = read_msh_bytes(msh.as_bytes(), "two.msh").unwrap();
    assert_eq!(whole.tets.len(), 2);
    let left = read_msh_object_bytes(msh.as_bytes(), "two.msh", "left").unwrap();
    assert_eq!((left.tets.len(), left.nodes.len()), (1, 4));
    assert_eq!(left.nodes[1], [1.0, 0.0, 0.0]);
    let right = read_msh_object_bytes(msh.as_bytes(), "two.msh", "2").unwrap();
    assert_eq!((right.tets.len(), right.nodes.len()), (1, 4));
    assert_eq!(right.nodes[0], [5.0, 0.0, 0.0]);
    let both = read_msh_object_bytes(msh.as_bytes(), "two.msh", "both").unwrap();
    assert_eq!(both.tets.len(), 2);
    let e = read_msh_object_bytes(msh.as_bytes(), "two.msh", "Left").unwrap_err();
    assert_eq!(
        e.kind,
        MeshErrorKind::UnknownObject {
            name: "Left".into(),
            available: "2, both, left".into()
        }
    );
    assert!(e.to_string().starts_with("two.msh: "), "{e}");
}

// Expectation (real gmsh, MSH 4.1 binary): two 0.1 m boxes 0.3 m apart, each its own
// `Physical Volume`: `bake` refuses the whole file (two pieces) and names `--object`; each
// box bakes alone with its own mass (ρ·1e-3 m³), `check` with the same `--object` finds the
// base up to date and the other box's base stale.
#[test]
fn gmsh_physical_volumes_bake_one_at_a_time() {
    if !gmsh_gate::have_gmsh("gmsh_physical_volumes_bake_one_at_a_time") {
        return;
    }
    let tmp = std::env::temp_dir().join(format!("dcr-two-volumes-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let msh = gmsh_volume_mesh(
        &tmp,
        "two",
        "SetFactory(\"OpenCASCADE\");\nMesh.MshFileVersion = 4.1;\nMesh.Binary = 1;\n\
         Mesh.MeshSizeMax = 0.04;\nBox(1) = {0, 0, 0, 0.1, 0.1, 0.1};\n\
         Box(2) = {0.4, 0, 0, 0.1, 0.1, 0.1};\nPhysical Volume(\"left\") = {1};\n\
         Physical Volume(\"right\") = {2};\n",
    );
    let left = modal_bake::mesh::read_msh_object(&msh, "left").unwrap();
    let right = modal_bake::mesh::read_msh_object(&msh, "right").unwrap();
    for (m, name) in [(&left, "left"), (&right, "right")] {
        assert!(
            (m.volume() - 1e-3).abs() < 1e-12,
            "{name}: {} m³",
            m.volume()
        );
    }
    assert!(left.nodes.iter().all(|p| p[0] <= 0.1 + 1e-12));
    assert!(right.nodes.iter().all(|p| p[0] >= 0.4 - 1e-12));
    let bake = |extra: &[&str], out: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_modal-bake"))
            .arg("bake")
            .arg(&msh)
            .arg("-o")
            .arg(tmp.join(out))
            .args(["--material", "steel", "--modes", "4"])
            .args(extra)
            .output()
            .unwrap()
    };
    let whole = bake(&[], "whole.modes");
    let text = String::from_utf8_lossy(&whole.stderr);
    assert!(
        !whole.status.success() && text.contains("--object NAME"),
        "{text}"
    );
    assert!(!tmp.join("whole.modes").exists());
    for name in ["left", "right"] {
        let out = bake(&["--object", name], &format!("{name}.modes"));
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("mass 7.850000 kg"), "{name}: {text}");
    }
    let check = |object: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_modal-bake"))
            .arg("check")
            .arg(&msh)
            .arg(tmp.join("left.modes"))
            .args(["--material", "steel", "--modes", "4", "--object", object])
            .status()
            .unwrap()
            .code()
    };
    assert_eq!(check("left"), Some(0));
    assert_eq!(check("right"), Some(1));
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// `b` then `a` moved by `dx` (m) along x as one mesh: nodes, tets, element ids 1…n and groups
/// of both (a group of `a` joins `b`'s group of the same name).
fn side_by_side(b: &TetMesh, a: &TetMesh, dx: f64) -> TetMesh {
    let n = b.nodes.len();
    let mut m = b.clone();
    m.nodes
        .extend(a.nodes.iter().map(|p| [p[0] + dx, p[1], p[2]]));
    m.tets.extend(a.tets.iter().map(|t| t.map(|v| v + n)));
    m.tet_ids = (1..=m.tets.len() as u64).collect();
    for (name, nodes) in &a.groups {
        let g = m.groups.entry(name.clone()).or_default();
        g.extend(nodes.iter().map(|v| v + n));
    }
    m
}

// Expectation: a mesh of two boxes has two pieces, numbered largest first whatever their
// order in the file, each with its tetrahedra, volume and bounding box; keeping one gives
// exactly the mesh of that box alone — nodes, tetrahedra, mid-edge nodes of a second-order
// mesh and groups — and a number the mesh has no piece for is refused with the list.
#[test]
fn connected_pieces_are_numbered_largest_first_and_kept_alone() {
    let small = TetMesh::structured_box([1, 1, 1], [0.1, 0.1, 0.1]);
    let large = TetMesh::structured_box([2, 1, 1], [0.2, 0.1, 0.1]);
    let two = side_by_side(&small, &large, 0.5);
    let pieces = two.pieces();
    assert_eq!(pieces.len(), 2);
    assert_eq!(two.connected_components(), 2);
    assert_eq!(
        (
            pieces[0].number,
            pieces[0].tets,
            pieces[1].number,
            pieces[1].tets
        ),
        (1, 12, 2, 6)
    );
    assert!((pieces[0].volume - 2e-3).abs() < 1e-15 && (pieces[1].volume - 1e-3).abs() < 1e-15);
    assert_eq!(pieces[0].bbox, [[0.5, 0.0, 0.0], [0.7, 0.1, 0.1]]);
    let moved = side_by_side(&TetMesh::default(), &large, 0.5);
    for (p1, alone) in [(false, &moved), (true, &moved)] {
        let whole = if p1 { two.to_quadratic() } else { two.clone() };
        let alone = if p1 {
            alone.to_quadratic()
        } else {
            alone.clone()
        };
        let kept = whole.keep_piece(1).unwrap();
        assert_eq!(kept.nodes, alone.nodes, "second order: {p1}");
        assert_eq!(kept.tets, alone.tets);
        assert_eq!(kept.mid_edges, alone.mid_edges);
        assert_eq!(kept.groups, alone.groups);
        assert_eq!(kept.tet_ids, (7..=18).collect::<Vec<u64>>());
        assert!(
            kept.notes.last().unwrap().starts_with(
                "kept piece 1: 12 tetrahedra, 0.002 m³, from (0.5, 0, 0) to (0.7, 0.1, 0.1) m"
            ),
            "{:?}",
            kept.notes
        );
        let kept = whole.keep_piece(2).unwrap();
        assert_eq!(
            (kept.nodes.len(), kept.tets.len()),
            (small.nodes.len() + if p1 { 19 } else { 0 }, 6)
        );
        assert_eq!(
            kept.groups,
            if p1 {
                small.to_quadratic().groups
            } else {
                small.groups.clone()
            }
        );
    }
    for asked in [0, 3] {
        let e = two.keep_piece(asked).unwrap_err();
        match &e.kind {
            MeshErrorKind::NoSuchPiece {
                asked: a,
                count,
                list,
            } => {
                assert_eq!((*a, *count), (asked, 2));
                assert!(
                    list.contains(
                        "piece 2: 6 tetrahedra, 0.001 m³, from (0, 0, 0) to (0.1, 0.1, 0.1) m"
                    ),
                    "{list}"
                );
            }
            other => panic!("{other:?}"),
        }
    }
    // Tetrahedra sharing one node only are one piece.
    let mut touching = small.clone();
    let n = touching.nodes.len();
    touching
        .nodes
        .extend([[0.2, 0.1, 0.1], [0.3, 0.1, 0.1], [0.2, 0.2, 0.1]]);
    touching.tets.push([7, n, n + 1, n + 2]);
    assert_eq!(touching.pieces().len(), 1);
}

/// Runs `modal-bake` with `args` (paths and words alike).
fn run_bake(args: &[&dyn AsRef<std::ffi::OsStr>]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args(args.iter().map(|a| a.as_ref()))
        .output()
        .unwrap()
}

const STEEL_4: [&str; 4] = ["--material", "steel", "--modes", "4"];

// Expectation: `bake`/`check --piece N` on a meshio JSON of two boxes: the whole file is refused
// listing both pieces and naming --piece; piece 2 bakes to a base `check` finds up to date
// against a file holding that box alone (the same canonical mesh) and stale against the other;
// a piece the file does not have, and --piece with a surface asset, are refused before any work.
#[test]
fn a_volume_mesh_of_several_pieces_bakes_piece_by_piece() {
    let tmp = std::env::temp_dir().join(format!("dcr-pieces-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let small = TetMesh::structured_box([1, 1, 1], [0.1, 0.1, 0.1]);
    let large = TetMesh::structured_box([2, 1, 1], [0.2, 0.1, 0.1]);
    let write = |m: &TetMesh, name: &str| {
        let path = tmp.join(name);
        std::fs::write(&path, m.to_meshio_json("zmin", "bottom").to_string()).unwrap();
        path
    };
    let two = write(&side_by_side(&small, &large, 0.5), "two.json");
    let alone_small = write(&small, "small.json");
    let alone_large = write(
        &side_by_side(&TetMesh::default(), &large, 0.5),
        "large.json",
    );
    let modes = tmp.join("p2.modes");
    let bake = |extra: &[&str]| {
        let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"bake", &two, &"-o", &modes];
        a.extend(
            STEEL_4
                .iter()
                .chain(extra)
                .map(|s| s as &dyn AsRef<std::ffi::OsStr>),
        );
        run_bake(&a)
    };
    let whole = bake(&[]);
    let text = String::from_utf8_lossy(&whole.stderr);
    assert!(!whole.status.success(), "{text}");
    assert!(
        text.contains("2 disconnected pieces, largest first: piece 1: 12 tetrahedra, 0.002 m³")
            && text.contains("piece 2: 6 tetrahedra, 0.001 m³")
            && text.contains("--piece N bakes piece N alone"),
        "{text}"
    );
    assert!(!modes.exists());
    let out = bake(&["--piece", "2"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("mass 7.850000 kg") && text.contains("kept piece 2"),
        "{text}"
    );
    // The base says which part of its file it is.
    let info = run_bake(&[&"info", &modes]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(text.contains("  input: its file with --piece 2"), "{text}");
    let check = |mesh: &Path, piece: Option<&str>| {
        let piece: Vec<&str> = piece.map_or(vec![], |p| vec!["--piece", p]);
        let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"check", &mesh, &modes];
        a.extend(
            STEEL_4
                .iter()
                .chain(&piece)
                .map(|s| s as &dyn AsRef<std::ffi::OsStr>),
        );
        let o = run_bake(&a);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
        )
    };
    assert_eq!(check(&alone_small, None).0, Some(0));
    assert_eq!(check(&two, Some("2")).0, Some(0));
    assert_eq!(check(&two, Some("1")).0, Some(1));
    // `info` gives the options that check it, --piece included.
    let args = check_args(&modes);
    assert!(args.windows(2).any(|w| w == ["--piece", "2"]), "{args:?}");
    let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"check", &two, &modes];
    a.extend(args.iter().map(|s| s as &dyn AsRef<std::ffi::OsStr>));
    assert_eq!(run_bake(&a).status.code(), Some(0), "{args:?}");
    // A stale check names the selection the base was read with.
    let (code, text) = check(&alone_large, None);
    assert_eq!(code, Some(1));
    assert!(
        text.contains("stale (geometry changed): the base was read from its file as `--piece 2`, this as the whole file in metres"),
        "{text}"
    );
    let missing = bake(&["--piece", "3"]);
    let text = String::from_utf8_lossy(&missing.stderr);
    assert!(
        !missing.status.success()
            && text.contains("two.json: no piece 3: the mesh has 2 connected piece(s)"),
        "{text}"
    );
    let asset = data("assets/hp_body.obj");
    let out = run_bake(&[
        &"bake",
        &asset,
        &"-o",
        &tmp.join("asset.modes"),
        &"--piece",
        &"1",
    ]);
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && text.contains("--piece 1 selects a connected piece of a volume mesh")
            && text.contains("--object NAME"),
        "{text}"
    );
    std::fs::remove_dir_all(&tmp).unwrap();
}

// Expectation (real gmsh): two boxes of different sizes meshed without any physical group (as
// gmsh's tutorials t18 and t19 are) cannot be selected by --object; --piece bakes each, the
// larger first: 7.85 kg and 0.98 kg of steel, the volumes of the boxes.
#[test]
fn gmsh_volumes_without_physical_groups_bake_piece_by_piece() {
    if !gmsh_gate::have_gmsh("gmsh_volumes_without_physical_groups_bake_piece_by_piece") {
        return;
    }
    let tmp = std::env::temp_dir().join(format!("dcr-gmsh-pieces-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let msh = gmsh_volume_mesh(
        &tmp,
        "two",
        "SetFactory(\"OpenCASCADE\");\nMesh.MshFileVersion = 4.1;\nMesh.MeshSizeMax = 0.03;\n\
         Box(1) = {0.4, 0, 0, 0.05, 0.05, 0.05};\nBox(2) = {0, 0, 0, 0.1, 0.1, 0.1};\n",
    );
    let e = modal_bake::mesh::read_msh_object(&msh, "1").unwrap_err();
    assert!(e.to_string().contains("no physical group"), "{e}");
    for (piece, mass) in [("1", "mass 7.850000 kg"), ("2", "mass 0.981250 kg")] {
        let out_path = tmp.join(format!("p{piece}.modes"));
        let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"bake", &msh, &"-o", &out_path];
        a.extend(STEEL_4.iter().map(|s| s as &dyn AsRef<std::ffi::OsStr>));
        a.extend([&"--piece" as &dyn AsRef<std::ffi::OsStr>, &piece]);
        let out = run_bake(&a);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.contains(mass),
            "piece {piece}: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    std::fs::remove_dir_all(&tmp).unwrap();
}

// Expectation: a file the readers cannot take says what they read and how to convert — and a
// `.msh` that is an ANSYS Fluent mesh (what meshio writes for a `.msh` name unless told the
// format, by `meshio.write` and `meshio convert` alike) is named as such with the conversion,
// not refused for a missing `$MeshFormat`. With meshio installed (CI), the real meshio's
// default `.msh` is refused so, and its `file_format="gmsh"` one reads as the mesh it was.
#[test]
#[cfg_attr(
    windows,
    ignore = "needs python3 with meshio or vtk; the Python cross-checks run on Linux"
)]
fn other_formats_are_named_with_their_conversion() {
    let e = read_mesh_bytes(b"(1 \"meshio 5.3.5\")\n(2 3)\n", "a.msh").unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::FluentMsh), "{e}");
    assert!(
        e.to_string().starts_with("a.msh: an ANSYS Fluent mesh")
            && e.to_string().contains("-o gmsh")
    );
    for name in ["a.vtu", "a.inp", "a.fbx"] {
        let e = read_mesh_bytes(b"<VTKFile>", name).unwrap_err();
        assert!(matches!(e.kind, MeshErrorKind::UnknownFormat), "{e}");
        assert!(
            e.to_string().contains("meshio convert IN OUT.msh -o gmsh"),
            "{e}"
        );
    }
    let tmp = tempfile::tempdir().unwrap();
    let body = r#"
m = meshio.read(sys.argv[1])
m = meshio.Mesh(m.points, [c for c in m.cells if c.type == "tetra"])
meshio.write(sys.argv[2], m)
meshio.write(sys.argv[3], m, file_format="gmsh")
"#;
    let (default, gmsh) = (tmp.path().join("default.msh"), tmp.path().join("gmsh.msh"));
    let cube = data("meshes/cube_v41.msh");
    let args = [cube.as_os_str(), default.as_os_str(), gmsh.as_os_str()];
    if meshio_gate::run_with_meshio(body, &args).is_none() {
        return;
    }
    let e = read_mesh(&default).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::FluentMsh), "{e}");
    let original = read_ok("meshes/cube_v41.msh");
    let converted = read_mesh(&gmsh).unwrap();
    assert_eq!(converted.nodes, original.nodes);
    assert_eq!(converted.tets, original.tets);
}

// Expectation: MSH 2.0 and 2.1 headers, and the version written as other tools write it
// (Netgen's "Gmsh2 Format": "2.000000"), read as the 2.2 file they equal; MSH 4.0 and gmsh's
// MSH 1 (`$NOD`, Netgen's "Gmsh Format") are refused at their line with gmsh's re-save
// command — and (real gmsh) that command turns an MSH 1 file into one that reads.
#[test]
fn older_msh_versions_read_or_are_refused_with_the_resave() {
    let text = std::fs::read_to_string(data("meshes/cube_v22.msh")).unwrap();
    let original = read_ok("meshes/cube_v22.msh");
    for version in ["2.0", "2.1", "2", "2.000000"] {
        let other = text.replacen("2.2 0 8", &format!("{version} 0 8"), 1);
        let m =
            read_msh_bytes(other.as_bytes(), "v.msh").unwrap_or_else(|e| panic!("{version}: {e}"));
        assert_eq!(m, original, "{version}");
    }
    let e = read_msh_bytes(text.replacen("2.2 0 8", "4.0 0 8", 1).as_bytes(), "v.msh").unwrap_err();
    assert_eq!(e.kind, MeshErrorKind::UnsupportedVersion("4.0".into()));
    assert!(
        e.to_string()
            .contains("gmsh IN.msh -save -format msh41 -o OUT.msh"),
        "{e}"
    );
    let msh1 = "$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n$ELM\n1\n1 4 1 1 4 1 2 3 4\n$ENDELM\n";
    let e = read_mesh_bytes(msh1.as_bytes(), "old.msh").unwrap_err();
    assert_eq!(
        (&e.kind, &e.location),
        (&MeshErrorKind::Msh1, &Location::Line(1))
    );
    assert!(e.to_string().contains("-save -format msh41"), "{e}");
    if !gmsh_gate::have_gmsh("older_msh_versions_read_or_are_refused_with_the_resave") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (old, new) = (tmp.path().join("old.msh"), tmp.path().join("new.msh"));
    std::fs::write(&old, msh1).unwrap();
    let args = [
        old.as_os_str(),
        "-save".as_ref(),
        "-format".as_ref(),
        "msh41".as_ref(),
        "-o".as_ref(),
        new.as_os_str(),
    ];
    assert!(run_gmsh(&args), "gmsh could not re-save {}", old.display());
    let m = read_mesh(&new).unwrap();
    assert_eq!((m.nodes.len(), m.tets.len()), (4, 1));
    assert!((m.volume() - 1.0 / 6.0).abs() < 1e-15);
}

// Expectation: a straight second-order mesh whose coordinates were written with six decimals
// (Netgen's "Gmsh2 Format", in metres) is straight: its mid-edge nodes are within rounding
// (≤ 8.7e-7 m) of the midpoints, under the floor of 1e-5 of the diagonal; a mid-edge node
// moved ten times the floor off its midpoint is still refused as curved.
#[test]
fn a_straight_mesh_written_with_six_decimals_is_straight() {
    let mut m = TetMesh::structured_box([3, 3, 3], [0.2, 0.1, 0.05]).to_quadratic();
    for p in &mut m.nodes {
        for c in p.iter_mut() {
            // Moved off round numbers, then written with six decimals.
            *c = ((*c + 0.012_345_678_9) * 1e6).round() / 1e6;
        }
    }
    let worst = m
        .mid_edges
        .iter()
        .zip(&m.tets)
        .flat_map(|(e, t)| {
            modal_bake::mesh::TET10_EDGES
                .iter()
                .zip(e)
                .map(|(&[a, b], &v)| {
                    let (x, y, p) = (m.nodes[t[a]], m.nodes[t[b]], m.nodes[v]);
                    (0..3)
                        .map(|i| (p[i] - 0.5 * (x[i] + y[i])).powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
        })
        .fold(0.0, f64::max);
    assert!(
        worst > 1e-6 * 0.0167 && worst <= 8.7e-7,
        "rounding moved a midpoint {worst} m"
    );
    m.check_straight(DEFAULT_STRAIGHT_REL_TOL).unwrap();
    let floor = modal_bake::mesh::STRAIGHT_DIAGONAL_TOL * m.extent();
    let v = m.mid_edges[5][2];
    m.nodes[v][2] += 10.0 * floor;
    let e = m.check_straight(DEFAULT_STRAIGHT_REL_TOL).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::CurvedTet { .. }), "{e}");
}

// Expectation (real gmsh): gmsh's default second-order mesh (mid-edge nodes on the curved
// surface) is refused naming --straighten; straightened it is exactly the mesh gmsh makes with
// `Mesh.SecondOrderLinear = 1` (binary files: bit for bit), so `bake --straighten` gives the
// base of the straight mesh (same source hash) and `check --straighten` finds it up to date.
// A surface asset, meshed straight-sided already, refuses the option.
#[test]
fn a_curved_gmsh_mesh_bakes_straightened_as_gmsh_s_straight_one() {
    if !gmsh_gate::have_gmsh("a_curved_gmsh_mesh_bakes_straightened_as_gmsh_s_straight_one") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let sphere = |linear: u8| {
        let geo = format!(
            "SetFactory(\"OpenCASCADE\");\nSphere(1) = {{0, 0, 0, 0.05}};\n\
             Mesh.MeshSizeMax = 0.02;\nMesh.ElementOrder = 2;\n\
             Mesh.SecondOrderLinear = {linear};\nMesh.Binary = 1;\nMesh.MshFileVersion = 4.1;\n"
        );
        gmsh_volume_mesh(tmp.path(), &format!("s{linear}"), &geo)
    };
    let (curved, straight) = (sphere(0), sphere(1));
    let mut m = read_mesh(&curved).unwrap();
    let e = m.check_straight(DEFAULT_STRAIGHT_REL_TOL).unwrap_err();
    assert!(e.to_string().contains("--straighten"), "{e}");
    let (moved, relative) = m.straighten();
    assert!(moved > 1e-4 && relative > 0.01, "{moved} m, {relative}");
    let s = read_mesh(&straight).unwrap();
    assert_eq!(
        (&m.nodes, &m.tets, &m.mid_edges),
        (&s.nodes, &s.tets, &s.mid_edges)
    );
    let hash = |mesh: &Path, extra: &[&str], out: &str| {
        let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"bake", &mesh, &"-o"];
        let out = tmp.path().join(out);
        a.push(&out);
        a.extend(
            STEEL_4
                .iter()
                .chain(extra)
                .map(|s| s as &dyn AsRef<std::ffi::OsStr>),
        );
        a.push(&"--json");
        let o = run_bake(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["source_hash"].as_str().unwrap().to_string()
    };
    assert_eq!(
        hash(&curved, &["--straighten"], "c.modes"),
        hash(&straight, &[], "s.modes")
    );
    let base = tmp.path().join("c.modes");
    let check = |extra: &[&str]| {
        let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"check", &curved, &base];
        a.extend(
            STEEL_4
                .iter()
                .chain(extra)
                .map(|s| s as &dyn AsRef<std::ffi::OsStr>),
        );
        run_bake(&a).status.code()
    };
    assert_eq!(check(&["--straighten"]), Some(0));
    assert_eq!(
        check(&[]),
        Some(2),
        "without --straighten the curved mesh is refused"
    );
    let asset = data("assets/hp_body.obj");
    let o = run_bake(&[
        &"bake",
        &asset,
        &"-o",
        &tmp.path().join("a.modes"),
        &"--straighten",
    ]);
    let text = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && text.contains("--straighten applies to second-order volume meshes"),
        "{text}"
    );
}

// Expectation (real gmsh): a gmsh surface mesh (`-2`) given as a volume mesh is told it holds
// triangles only, with gmsh's command that writes the surface as an STL asset — and that
// command's STL reads as the same closed surface.
#[test]
fn a_gmsh_surface_mesh_is_told_how_to_become_an_asset() {
    if !gmsh_gate::have_gmsh("a_gmsh_surface_mesh_is_told_how_to_become_an_asset") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let geo = tmp.path().join("s.geo");
    std::fs::write(
        &geo,
        "SetFactory(\"OpenCASCADE\");\nSphere(1) = {0, 0, 0, 0.05};\nMesh.MeshSizeMax = 0.02;\n",
    )
    .unwrap();
    let msh = tmp.path().join("s.msh");
    let stl = tmp.path().join("s.stl");
    let gmsh = |args: &[&std::ffi::OsStr]| assert!(run_gmsh(args), "gmsh {args:?}");
    gmsh(&[
        geo.as_os_str(),
        "-2".as_ref(),
        "-o".as_ref(),
        msh.as_os_str(),
    ]);
    let e = read_mesh(&msh).unwrap_err();
    let MeshErrorKind::NoTets { found, .. } = &e.kind else {
        panic!("{e}")
    };
    let triangles: usize = found
        .split(' ')
        .next()
        .unwrap()
        .replace(',', "")
        .parse()
        .unwrap();
    assert!(
        e.to_string()
            .contains("`gmsh FILE.msh -0 -format stl -o FILE.stl`"),
        "{e}"
    );
    gmsh(&[
        msh.as_os_str(),
        "-0".as_ref(),
        "-format".as_ref(),
        "stl".as_ref(),
        "-o".as_ref(),
        stl.as_os_str(),
    ]);
    let mut surface = modal_bake::mesh::surface::read_surface(&stl).unwrap();
    assert_eq!(surface.triangles.len(), triangles);
    surface.check_closed("s.stl").unwrap();
}
