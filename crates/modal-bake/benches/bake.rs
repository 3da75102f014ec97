//! End-to-end bake benchmark (read + assemble + factor + 20 modes + write) on clamped
//! structured beams of ~3k, ~15k and ≥100k free dofs (slender and stout). Writes medians to
//! `target/bench/bake.json` and prints a table.
//!
//! Run: `cargo bench -p modal-bake --bench bake` (add `-- --quick` for one run per size, and
//! `-- --only 3k,15k` for some sizes only).

use std::path::Path;
use std::time::Instant;

use modal_bake::bake::{bake_file, BakeParams, BakeReport};
use modal_bake::mesh::TetMesh;

/// Writes `mesh` as meshio-style JSON with its groups as `cell_sets` over a vertex block.
fn write_json(mesh: &TetMesh, path: &Path) {
    let v = mesh.to_meshio_json("xmin", "clamp");
    std::fs::write(path, serde_json::to_vec(&v).unwrap()).unwrap();
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    // `--only NAMES`: comma-separated size names (e.g. `3k,15k`) to bake, the rest skipped.
    let only: Option<Vec<String>> = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .map(|list| list.split(',').map(str::to_string).collect());
    let dir = tempfile::tempdir().unwrap();
    // Clamped beams (cells are cubes). The factorization of a beam costs about
    // n·(cross-section dofs)², so the ≥100k row is reported twice: a slender, finely meshed
    // beam (3 m × 0.1 m × 0.1 m in 1 cm cells) and a stout one (4 m × 0.72 m × 0.72 m).
    let sizes: [(&str, [usize; 3], [f64; 3], usize); 4] = [
        ("3k", [24, 6, 6], [1.0, 0.25, 0.25], 9),
        ("15k", [45, 9, 9], [2.0, 0.4, 0.4], 7),
        ("100k", [300, 10, 10], [3.0, 0.1, 0.1], 3),
        ("100k-stout", [100, 18, 18], [4.0, 0.72, 0.72], 1),
    ];
    let params = BakeParams {
        fixed: vec!["clamp".into()],
        ..Default::default()
    };
    let mut rows = Vec::new();
    for (name, n, l, runs) in sizes {
        if only.as_ref().is_some_and(|o| !o.iter().any(|s| s == name)) {
            continue;
        }
        let mesh = TetMesh::structured_box(n, l);
        let src = dir.path().join(format!("{name}.json"));
        write_json(&mesh, &src);
        let out = dir.path().join(format!("{name}.modes"));
        let runs = if quick { 1 } else { runs };
        let mut total = Vec::new();
        let mut reports: Vec<BakeReport> = Vec::new();
        for _ in 0..runs {
            let t = Instant::now();
            let r = bake_file(&src, &params, &out, &mut |_| {}).expect("bake");
            total.push(t.elapsed().as_secs_f64());
            reports.push(r);
        }
        let med = |f: fn(&BakeReport) -> f64| median(reports.iter().map(f).collect());
        let free_dofs = reports[0].free_dofs;
        let row = serde_json::json!({
            "size": name,
            "free_dofs": free_dofs,
            "tets": reports[0].tets,
            "runs": runs,
            "total_s_median": median(total.clone()),
            "read_s_median": med(|r| r.read_s),
            "assemble_s_median": med(|r| r.assemble_s),
            "factor_s_median": med(|r| r.factor_s),
            "eigensolve_s_median": med(|r| r.eigensolve_s),
            "write_s_median": med(|r| r.write_s),
            "eigensolve_over_factor": med(|r| r.eigensolve_s / r.factor_s),
        });
        eprintln!(
            "{name:>5}: {free_dofs} free dofs, total {:.3} s (read {:.3}, assemble {:.3}, factor {:.3}, eigensolve {:.3} = {:.2}× factor, write {:.3}), median of {runs}",
            row["total_s_median"].as_f64().unwrap(),
            row["read_s_median"].as_f64().unwrap(),
            row["assemble_s_median"].as_f64().unwrap(),
            row["factor_s_median"].as_f64().unwrap(),
            row["eigensolve_s_median"].as_f64().unwrap(),
            row["eigensolve_over_factor"].as_f64().unwrap(),
            row["write_s_median"].as_f64().unwrap(),
        );
        rows.push(row);
    }
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/bench");
    std::fs::create_dir_all(&target).unwrap();
    let machine = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_default();
    let report = serde_json::json!({
        "machine": {"cpu": machine, "threads": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)},
        "rows": rows,
    });
    std::fs::write(
        target.join("bake.json"),
        serde_json::to_vec_pretty(&report).unwrap(),
    )
    .unwrap();
    eprintln!("wrote target/bench/bake.json");
}
