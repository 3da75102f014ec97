//! Timing of the bake's numerical core on clamped structured beams: assembly of K and M, the
//! factorization of K − σM and the shift-invert block Lanczos eigensolve.
//!
//! `cargo run --release -p modal-bake --example eigen_timing -- [sizes...] [--nev N] [--reps R]`
//! with sizes among `3k 15k 100k beam100k bench3k bench15k stout` (default: the first three), optional `--block B`,
//! `--ncv D` (Krylov dimension), `--tol T` (default: the bake's 1e-8) and `--threads T` (`EigenParams::threads`). Prints one CSV row
//! per run and a median summary per size. Speed is measured here, never asserted in tests.
//! `solve_cpu_s` is the calling thread's CPU time in `solve_lowest` (factorization +
//! eigensolve): below 20 000 dofs the whole solve runs on that thread, so on a loaded machine
//! it is the steadier figure to compare.

use std::time::Instant;

use modal_bake::eigen::{solve_lowest, EigenParams};
use modal_bake::fem::{assemble_mass, assemble_stiffness, reduce_fixed, Material};
use modal_bake::mesh::TetMesh;

/// CPU time (s) this thread has run, from `/proc/thread-self/schedstat` (ns; Linux only,
/// 0 elsewhere). Below 20 000 dofs the whole eigensolve runs on the calling thread, so this
/// measures it without the time spent waiting for a core on a loaded machine.
fn thread_cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .map_or(0.0, |ns| ns as f64 * 1e-9)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut sizes = Vec::new();
    let mut nev = 20usize;
    let mut reps = 0usize;
    let mut block = EigenParams::default().block;
    let mut ncv: Option<usize> = None;
    let mut threads = 0usize;
    // The bake's tolerance (modal_bake::bake::MAX_RESIDUAL).
    let mut tol = modal_bake::bake::MAX_RESIDUAL;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--nev" => {
                nev = args[i + 1].parse().expect("--nev N");
                i += 1;
            }
            "--reps" => {
                reps = args[i + 1].parse().expect("--reps R");
                i += 1;
            }
            "--threads" => {
                threads = args[i + 1].parse().expect("--threads T");
                i += 1;
            }
            "--ncv" => {
                ncv = Some(args[i + 1].parse().expect("--ncv D"));
                i += 1;
            }
            "--tol" => {
                tol = args[i + 1].parse().expect("--tol T");
                i += 1;
            }
            "--block" => {
                block = args[i + 1].parse().expect("--block B");
                i += 1;
            }
            s => sizes.push(s.to_string()),
        }
        i += 1;
    }
    if sizes.is_empty() {
        sizes = vec!["3k".into(), "15k".into(), "100k".into()];
    }
    let mat = Material::new(2.0e9, 0.3, 1200.0).unwrap();
    println!(
        "size,free_dofs,assembly_s,factor_s,eigensolve_s,total_s,solve_cpu_s,block_solves,restarts,checks,purified,factor_nnz,f1_hz"
    );
    for size in &sizes {
        // Beams with a 0.1 m square section, clamped at x = 0: L = 1 m, or 3 m for the
        // slender `beam100k` (300 × 10 × 10 cubic cells, ~109k free dofs).
        let (cells, len) = match size.as_str() {
            "3k" => ([40, 4, 4], 1.0),
            "15k" => ([60, 8, 8], 1.0),
            "100k" => ([120, 16, 16], 1.0),
            "beam100k" => ([300, 10, 10], 3.0),
            // The bake bench's 3k and 15k beams (benches/bake.rs).
            "bench3k" => ([24, 6, 6], 1.0),
            "bench15k" => ([45, 9, 9], 2.0),
            // The bake bench's 100k-stout beam (4 m × 0.72 m × 0.72 m).
            "stout" => ([100, 18, 18], 4.0),
            other => {
                panic!("unknown size {other} (3k, 15k, 100k, beam100k, bench3k, bench15k, stout)")
            }
        };
        let reps = if reps > 0 {
            reps
        } else if size.contains("100k") {
            3
        } else {
            5
        };
        let side = match size.as_str() {
            "bench3k" => 0.25,
            "bench15k" => 0.4,
            "stout" => 0.72,
            _ => 0.1,
        };
        let mesh = TetMesh::structured_box(cells, [len, side, side]);
        let (mut ta, mut tf, mut te, mut tt, mut tc) = (vec![], vec![], vec![], vec![], vec![]);
        for _ in 0..reps {
            let t0 = Instant::now();
            let k = assemble_stiffness(&mesh, &mat);
            let m = assemble_mass(&mesh, &mat, false);
            let (_, k, m) = reduce_fixed(&k, &m, &mesh.groups["xmin"]).unwrap();
            let assembly = t0.elapsed().as_secs_f64();
            let p = EigenParams {
                nev,
                block,
                krylov_dim: ncv,
                threads,
                tol,
                ..Default::default()
            };
            let cpu0 = thread_cpu_s();
            let res = solve_lowest(&k, &m, &p, &mut |_| {}).expect("eigensolve");
            let cpu = thread_cpu_s() - cpu0;
            let total = t0.elapsed().as_secs_f64();
            println!(
                "{size},{},{assembly:.4},{:.4},{:.4},{total:.4},{cpu:.4},{},{},{},{},{},{:.4}",
                k.nrows(),
                res.info.factor_seconds,
                res.info.solve_seconds,
                res.info.block_solves,
                res.info.restarts,
                res.info.residual_checks,
                res.info.purified,
                res.info.factor_nnz,
                res.frequencies_hz()[0]
            );
            ta.push(assembly);
            tf.push(res.info.factor_seconds);
            te.push(res.info.solve_seconds);
            tt.push(total);
            tc.push(cpu);
        }
        println!(
            "# {size} median of {reps}: assembly {:.3} s, factor {:.3} s, eigensolve {:.3} s, total {:.3} s, factor + eigensolve thread CPU {:.4} s (min {:.4})",
            median(ta),
            median(tf),
            median(te),
            median(tt),
            median(tc.clone()),
            tc.iter().cloned().fold(f64::INFINITY, f64::min)
        );
    }
}
