//! `modal-bake info MESH`: what a volume mesh holds and how to bake it — its size, extent,
//! connected pieces (for `--piece`), node groups (for `--fixed` and, 3-D physical groups of a
//! `.msh`, `--object`), whether its second-order elements are straight (else `--straighten`),
//! the bake's estimated time and memory at its defaults and the readers' notes. Coordinates as the file gives them (m unless `bake --units` says
//! otherwise).

use std::fmt::Write as _;
use std::path::Path;

use modal_bake::mesh::{four_digits, MeshErrorKind, TetMesh, DEFAULT_STRAIGHT_REL_TOL};

/// Whether `path` names a volume mesh by its extension (`.msh`, `.json`).
pub fn is_volume_mesh(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("msh") || e.eq_ignore_ascii_case("json"))
}

/// The first curved element of `mesh` (element id, mid-edge offset (m), edge length (m)), or
/// `None` when every element is straight-sided (or the mesh is linear).
fn curved(mesh: &TetMesh) -> Option<(u64, f64, f64)> {
    match mesh.check_straight(DEFAULT_STRAIGHT_REL_TOL) {
        Err(e) => match e.kind() {
            MeshErrorKind::CurvedTet {
                element,
                offset,
                edge_length,
            } => Some((*element, *offset, *edge_length)),
            _ => None,
        },
        Ok(()) => None,
    }
}

/// The axis-aligned bounding box of the mesh's nodes (m), `[min, max]`.
fn bounding_box(mesh: &TetMesh) -> [[f64; 3]; 2] {
    let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
    for p in &mesh.nodes {
        for k in 0..3 {
            b[0][k] = b[0][k].min(p[k]);
            b[1][k] = b[1][k].max(p[k]);
        }
    }
    b
}

/// Prints the summary of the volume mesh at `file` (or one JSON object with `json`).
///
/// # Errors
/// The mesh cannot be read (the reader's error names the file and where).
pub fn run(file: &Path, json: bool) -> anyhow::Result<()> {
    let mesh = modal_bake::mesh::read_mesh(file)?;
    let pieces = mesh.pieces();
    let curved = curved(&mesh);
    let bbox = bounding_box(&mesh);
    let order = if mesh.is_quadratic() { 2 } else { 1 };
    let name = file.display().to_string();
    // The bake at its defaults (20 modes, free-free) against the default budget.
    let estimate =
        modal_bake::bake::SizeEstimate::of_bake(&mesh, &modal_bake::bake::BakeParams::default());
    let fits = estimate.fits(&modal_bake::bake::Budget::default());
    let text = if json {
        let v = serde_json::json!({
            "file": name,
            "kind": "volume mesh",
            "nodes": mesh.nodes.len(),
            "tets": mesh.tets.len(),
            "order": order,
            "dofs": mesh.dofs(),
            "bbox_m": bbox,
            "diagonal_m": mesh.extent(),
            "volume_m3": mesh.volume(),
            "pieces": pieces.iter().map(|p| serde_json::json!({
                "number": p.number,
                "tets": p.tets,
                "volume_m3": p.volume,
                "bbox_m": p.bbox,
            })).collect::<Vec<_>>(),
            "groups": mesh.groups.iter().map(|(g, n)| (g.clone(), n.len())).collect::<std::collections::BTreeMap<_, _>>(),
            "curved": curved.map(|(element, offset, edge)| serde_json::json!({
                "element": element,
                "offset_m": offset,
                "edge_length_m": edge,
            })),
            "notes": mesh.notes,
            "bake_estimate": {
                "seconds": estimate.bake_s,
                "peak_bytes": estimate.bake_bytes,
                "within_default_budget": fits,
            },
        });
        format!("{}\n", serde_json::to_string_pretty(&v)?)
    } else {
        let mut s = String::new();
        let g = modal_bake::bake::group_digits;
        let p = |x: [f64; 3]| format!("({})", x.map(four_digits).join(", "));
        writeln!(s, "{name}  (volume mesh)")?;
        writeln!(
            s,
            "  mesh: {} nodes, {} {}-node tetrahedra (order {order}), {} dofs free-free",
            g(mesh.nodes.len()),
            g(mesh.tets.len()),
            if order == 2 { 10 } else { 4 },
            g(mesh.dofs())
        )?;
        writeln!(
            s,
            "  extent: from {} to {} m, diagonal {} m; volume {} m³",
            p(bbox[0]),
            p(bbox[1]),
            four_digits(mesh.extent()),
            four_digits(mesh.volume())
        )?;
        if pieces.len() == 1 {
            writeln!(s, "  pieces: 1 (connected)")?;
        } else {
            writeln!(
                s,
                "  pieces: {} (a bake needs one: --piece N bakes piece N alone), largest first:",
                pieces.len()
            )?;
            for piece in pieces.iter().take(20) {
                writeln!(s, "    {piece}")?;
            }
            if pieces.len() > 20 {
                writeln!(s, "    and {} smaller", pieces.len() - 20)?;
            }
        }
        if mesh.groups.is_empty() {
            writeln!(
                s,
                "  groups: none (fix nodes with --fixed-below, --fixed-box or --fixed-near)"
            )?;
        } else {
            let list: Vec<String> = mesh
                .groups
                .iter()
                .map(|(name, nodes)| {
                    let noun = if nodes.len() == 1 { "node" } else { "nodes" };
                    format!("{name} ({} {noun})", g(nodes.len()))
                })
                .collect();
            writeln!(
                s,
                "  groups (--fixed NAME; a 3-D physical group of a .msh is also --object NAME): {}",
                list.join(", ")
            )?;
        }
        match (order, curved) {
            (1, _) => {}
            (_, None) => writeln!(s, "  elements: straight-sided")?,
            (_, Some((element, offset, edge))) => writeln!(
                s,
                "  elements: curved (element {element}: a mid-edge node {offset:.3e} m off its edge's midpoint, edge {edge:.3e} m): bake with --straighten"
            )?,
        }
        writeln!(
            s,
            "  bake (20 modes, free-free): about {} and {}{}",
            modal_bake::bake::format_seconds(estimate.bake_s),
            modal_bake::bake::format_bytes(estimate.bake_bytes),
            if fits {
                ""
            } else {
                ": over the default budget of 2 GB and 5 min, so `bake` refuses it without --max-memory / --max-time or --force"
            }
        )?;
        for note in &mesh.notes {
            writeln!(s, "  note: {note}")?;
        }
        s
    };
    super::emit(&text);
    Ok(())
}
