//! Timing of the bake's first two stages on the bake bench's stout 100k beam (100 × 18 × 18
//! cells, 4 m × 0.72 m × 0.72 m, ~108k free dofs): reading its meshio JSON and assembling
//! K and M restricted to the free dofs.
//!
//! `cargo run --release -p modal-bake --example read_assemble_timing -- [--reps R] [--only read|assemble] [--write PATH]`
//! Prints per-rep seconds and the min/median, and a SHA-256 of the assembled matrices (pattern
//! and value bits) so that a faster assembly can be checked to be bit-identical. Speed is
//! measured here, never asserted in tests.

use std::time::Instant;

use faer::sparse::SparseColMat;
use modal_bake::fem::{assemble_clamped, Material};
use modal_bake::mesh::{read_mesh, TetMesh};
use sha2::{Digest, Sha256};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .map(|i| args[i + 1].clone())
    };
    let reps: usize = arg("--reps").map_or(5, |r| r.parse().expect("--reps R"));
    let only = arg("--only");
    let mesh = TetMesh::structured_box([100, 18, 18], [4.0, 0.72, 0.72]);
    // As benches/bake.rs writes it: the clamp as cell_sets over a vertex block.
    let clamp = &mesh.groups["xmin"];
    let v = mesh.to_meshio_json("xmin", "clamp");
    let dir = tempfile::tempdir().unwrap();
    // `--write PATH` keeps the JSON (e.g. to bake it with two builds of the CLI and compare).
    let path = arg("--write").map_or_else(|| dir.path().join("stout.json"), Into::into);
    std::fs::write(&path, serde_json::to_vec(&v).unwrap()).unwrap();
    let mat = Material::new(2.0e9, 0.3, 1200.0).unwrap();
    let (mut tr, mut ta) = (Vec::new(), Vec::new());
    for _ in 0..reps {
        if only.as_deref() != Some("assemble") {
            let t = Instant::now();
            let m = read_mesh(&path).unwrap();
            tr.push(t.elapsed().as_secs_f64());
            assert_eq!(m.tets.len(), mesh.tets.len());
        }
        if only.as_deref() != Some("read") {
            let t = Instant::now();
            let (map, k, m) = assemble_clamped(&mesh, &mat, false, clamp).unwrap();
            ta.push(t.elapsed().as_secs_f64());
            assert!(map.n_free() > 100_000);
            if ta.len() == 1 {
                println!("K, M sha256 {}", checksum(&[&k, &m]));
            }
        }
    }
    for (name, mut v) in [("read", tr), ("assemble", ta)] {
        if v.is_empty() {
            continue;
        }
        println!("{name}: {v:.4?}");
        v.sort_by(f64::total_cmp);
        println!("{name}: min {:.4} s, median {:.4} s", v[0], v[v.len() / 2]);
    }
}

/// SHA-256 of the patterns and value bits of `mats`.
fn checksum(mats: &[&SparseColMat<usize, f64>]) -> String {
    let mut h = Sha256::new();
    for a in mats {
        for &p in a.symbolic().col_ptr().iter().chain(a.symbolic().row_idx()) {
            h.update((p as u64).to_le_bytes());
        }
        for v in a.val() {
            h.update(v.to_bits().to_le_bytes());
        }
    }
    format!("{:x}", h.finalize())
}
