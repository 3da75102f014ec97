//! Timing of the dense eigen path against shift-invert Lanczos on clamped structured beams,
//! for choosing the size below which small problems are solved densely.
//!
//! `cargo run --release -p modal-bake --example dense_timing -- [--reps R]`: for beams of about
//! 750, 1500, 2600, 2900 and 5000 free dofs, prints one CSV row per run: dofs, path (`dense`:
//! every mode below an unreachable frequency cap; `lanczos20`: the 20 lowest; `lanczos_tenth`:
//! the n/10 lowest, the largest count Lanczos still takes), wall seconds and modes. Speed is
//! measured here, never asserted in tests.

use std::time::Instant;

use modal_bake::eigen::{solve_lowest, EigenParams};
use modal_bake::fem::{assemble_clamped, Material};
use modal_bake::mesh::TetMesh;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let reps = args
        .iter()
        .position(|a| a == "--reps")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(3usize);
    let mat = Material::new(2e11, 0.3, 7800.0).expect("valid material");
    println!("dofs,path,seconds,modes");
    for n in [[10, 4, 4], [14, 5, 5], [18, 6, 6], [20, 6, 6], [26, 7, 7]] {
        let l = [1.0, 0.1 * n[1] as f64 / 4.0, 0.1 * n[2] as f64 / 4.0];
        let mesh = TetMesh::structured_box(n, l);
        let (_, k, m) =
            assemble_clamped(&mesh, &mat, false, &mesh.groups["xmin"]).expect("a clamped beam");
        let dofs = k.nrows();
        let runs = [
            ("dense", 1, Some(1e300)),
            ("lanczos20", 20, None),
            ("lanczos_tenth", dofs / 10, None),
        ];
        for (path, nev, max_freq_hz) in runs {
            if path == "dense" && dofs > 3000 {
                continue;
            }
            for _ in 0..reps {
                let params = EigenParams {
                    nev,
                    max_freq_hz,
                    max_modes: dofs,
                    tol: 1e-8,
                    ..Default::default()
                };
                let t = Instant::now();
                let res = solve_lowest(&k, &m, &params, &mut |_| {}).expect("converges");
                println!(
                    "{dofs},{path},{:.3},{}",
                    t.elapsed().as_secs_f64(),
                    res.eigenvalues.len()
                );
            }
        }
    }
}
