//! The heat method's sparse Cholesky: the runtime's hand-written left-looking LLᵀ
//! (`attenuation/sparse_llt.rs`) against faer's sparse Cholesky on the same geodesic systems.
//!
//! For each base (paths as arguments; default every `.modes` in `data/bases/` and `out/bases/`,
//! the scene bases `dcr-scenes table1` bakes), both operators (M + tL) and (L + εM) under the
//! base's stored elimination order (AMD without one) are factored
//! - `own`: the runtime's set-up (pattern, one sweep for both factors, solve layout),
//! - `faer_simplicial`: faer's simplicial numeric factor on the same symbolic analysis,
//! - `faer_auto`: faer's own choice under the same order (supernodal past its flop-ratio
//!   threshold; numeric factor only, the symbolic analysis is not timed),
//!
//! and one heat solve and one Poisson solve are timed with each (serial). The rounds are
//! interleaved; medians of 15 rounds are printed and written to `out/bench/sparse_llt.json`.
//!
//! `cargo bench -p dcr-runtime --features bench-internals --bench sparse_llt [-- BASE.modes …]`
//! (in a workspace build `cargo bench --workspace --bench sparse_llt`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use dcr_runtime::attenuation::LltProbe;
use dcr_runtime::format::ModesFile;

const ROUNDS: usize = 15;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(f: &mut dyn FnMut()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

fn default_bases(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in ["data/bases", "out/bases"] {
        if let Ok(rd) = std::fs::read_dir(root.join(dir)) {
            let mut v: Vec<PathBuf> = rd
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == "modes"))
                .collect();
            v.sort();
            out.extend(v);
        }
    }
    out
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let args: Vec<PathBuf> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .collect();
    let bases = if args.is_empty() {
        default_bases(&root)
    } else {
        args
    };
    let mut rows = Vec::new();
    for path in &bases {
        let base = match ModesFile::read(path) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("skipping {}: {e}", path.display());
                continue;
            }
        };
        let v = &base.surface_vertices;
        let t = &base.surface_triangles;
        let mut probe = match LltProbe::new(v, t, base.surface_order.as_deref()) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("skipping {}: {e}", path.display());
                continue;
            }
        };
        let (n, nnz, supernodal, nnz_auto) = probe.info();
        let mut rhs = vec![0.0; n];
        let mut x = Vec::new();
        let src = |rhs: &mut [f64]| {
            rhs.iter_mut().for_each(|r| *r = 0.0);
            rhs[n / 3] = 1.0;
        };
        // [own, faer simplicial, faer auto] × [factor both, heat solve, poisson solve]
        let mut t: [[Vec<f64>; 3]; 3] = Default::default();
        for round in 0..=ROUNDS {
            let f = [
                time(&mut || probe.factor_own()),
                time(&mut || probe.factor_faer(false)),
                time(&mut || probe.factor_faer(true)),
            ];
            let mut s = [[0.0; 2]; 3];
            for which in 0..2 {
                src(&mut rhs);
                s[0][which] = time(&mut || probe.solve_own(which, &mut rhs, &mut x));
                let own = rhs.clone();
                for (k, sn) in [(1, false), (2, true)] {
                    src(&mut rhs);
                    s[k][which] = time(&mut || probe.solve_faer(sn, which, &mut rhs));
                    let scale = own.iter().fold(0.0f64, |m, y| m.max(y.abs()));
                    let diff = own
                        .iter()
                        .zip(&rhs)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    // The Poisson operator is regularised by ε = 1e-8/t only (closed
                    // surfaces): its solves agree to its conditioning, not to rounding.
                    let tol = [1e-10, 1e-5][which];
                    assert!(
                        diff <= tol * scale,
                        "{}: solves differ ({which}: {diff:e} of {scale:e})",
                        path.display()
                    );
                }
            }
            if round == 0 {
                continue; // warm-up
            }
            for k in 0..3 {
                t[k][0].push(f[k]);
                t[k][1].push(s[k][0]);
                t[k][2].push(s[k][1]);
            }
        }
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let ms = |k: usize, j: usize| median(t[k][j].clone()) * 1e3;
        println!(
            "{name}: {n} vertices, factor entries {nnz} (faer auto: {} {nnz_auto}); \
             factor both own {:.3} / faer simplicial {:.3} / faer auto {:.3} ms; \
             heat solve {:.4} / {:.4} / {:.4} ms; poisson solve {:.4} / {:.4} / {:.4} ms",
            if supernodal {
                "supernodal"
            } else {
                "simplicial"
            },
            ms(0, 0),
            ms(1, 0),
            ms(2, 0),
            ms(0, 1),
            ms(1, 1),
            ms(2, 1),
            ms(0, 2),
            ms(1, 2),
            ms(2, 2),
        );
        rows.push(format!(
            "    {{\"base\": \"{name}\", \"vertices\": {n}, \"factor_entries\": {nnz}, \
             \"faer_auto_supernodal\": {supernodal}, \"faer_auto_entries\": {nnz_auto}, \
             \"factor_ms\": {{\"own\": {:.4}, \"faer_simplicial\": {:.4}, \"faer_auto\": {:.4}}}, \
             \"heat_solve_ms\": {{\"own\": {:.5}, \"faer_simplicial\": {:.5}, \"faer_auto\": {:.5}}}, \
             \"poisson_solve_ms\": {{\"own\": {:.5}, \"faer_simplicial\": {:.5}, \"faer_auto\": {:.5}}}}}",
            ms(0, 0),
            ms(1, 0),
            ms(2, 0),
            ms(0, 1),
            ms(1, 1),
            ms(2, 1),
            ms(0, 2),
            ms(1, 2),
            ms(2, 2),
        ));
    }
    let out = root.join("out/bench");
    std::fs::create_dir_all(&out).expect("create out/bench");
    let json = format!(
        "{{\"rounds\": {ROUNDS}, \"statistic\": \"median\", \"bases\": [\n{}\n]}}\n",
        rows.join(",\n")
    );
    std::fs::write(out.join("sparse_llt.json"), json).expect("write out/bench/sparse_llt.json");
}
