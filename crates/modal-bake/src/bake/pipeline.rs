//! The bake pipeline: mesh → oriented, validated mesh → K, M → boundary conditions → lowest
//! elastic modes (shift-invert block Lanczos, K u = λ M u) → surface rows → [`ModesFile`],
//! plus the optional peak-transfer table.

use std::path::Path;
use std::time::Instant;

use super::prepare::{prepare, Prepared};
use super::surface::Surface;
use super::{BakeError, BakeParams, BakeReport, BakeStage, ModeRequest, TransferReport};
use crate::eigen::{self, EigenParams};
use crate::fem;
use crate::mesh::TetMesh;
use dcr_runtime::format::{FormatError, ModesFile, ModesMeta, QuadraticSurface};

/// Version of what `modal-bake` writes for given inputs, stored in every base
/// (`meta.bake_params.output_version`). Bumped by any change of the tool that changes a base's
/// content for the same mesh and options (assembly, eigensolver, surface extraction, hashing),
/// and only then — not by the crate version — so `check` calls bases of an older output stale
/// and an upgrade that changes nothing keeps them fresh.
pub const OUTPUT_VERSION: u32 = 1;

/// `modal-bake <version>`, stored in every base.
pub const TOOL_VERSION: &str = concat!("modal-bake ", env!("CARGO_PKG_VERSION"));

/// A near-zero eigenvalue is a rigid-body mode when |λ| ≤ this × the first elastic λ.
pub const RIGID_REL_TOL: f64 = 1e-6;

/// Largest relative residual ‖Ku − λMu‖/‖Ku‖ accepted for a mode that is written, unless the
/// residual is at its double-precision floor (see `bake_mesh`).
pub const MAX_RESIDUAL: f64 = 1e-8;

/// Bakes the modal base of an in-memory mesh, with the peak-transfer table when
/// [`BakeParams::transfer`] asks for one. `file` names the source in messages.
///
/// The table ([`crate::transfer`]) covers the selected region and is built from the base's own
/// modes when it keeps enough, else from the dense all-mode eigensolve (≤
/// [`crate::transfer::DENSE_MAX_DOFS`] free dofs) or a Lanczos bake with that many modes. Its
/// parameters are recorded in `meta.bake_params.transfer`; `params_hash` does not depend on
/// them (the table is checked by its own entries: h, Rayleigh, modes).
///
/// # Errors
/// A [`BakeError`] naming the file and what failed; [`BakeError::Transfer`] when the table
/// cannot be built.
pub fn bake_mesh(
    mesh: TetMesh,
    params: &BakeParams,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<(ModesFile, BakeReport), BakeError> {
    match &params.transfer {
        None => bake_modes(mesh, params, file, progress),
        Some(tp) => bake_with_table(mesh, params, tp, file, progress),
    }
}

/// The modal base of an in-memory mesh, without a transfer table (whatever
/// [`BakeParams::transfer`] says).
///
/// Steps: orient tetrahedra (inverted ones are flipped and counted, degenerate ones are an
/// error), refuse disconnected meshes, fix the named groups, assemble K and M, solve
/// K u = λ M u for the lowest modes by shift-invert block Lanczos, exclude the six rigid-body
/// modes of a free-free object, check every residual ≤ [`MAX_RESIDUAL`], keep the surface rows.
///
/// # Errors
/// A [`BakeError`] naming the file and what failed.
fn bake_modes(
    mesh: TetMesh,
    params: &BakeParams,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<(ModesFile, BakeReport), BakeError> {
    let mat = params.check()?;
    let mut report = BakeReport {
        notes: mesh.notes.clone(),
        ..Default::default()
    };
    let prepared = prepare(mesh, params, file)?;
    let mesh = &prepared.mesh;
    report.order = if mesh.is_quadratic() { 2 } else { 1 };
    report.material = Some(params.material);
    report.fixed_by = prepared.fixed_by.clone();
    report.nodes = mesh.nodes.len();
    report.tets = mesh.tets.len();
    report.extent_m = mesh.extent();
    report.reoriented_tets = prepared.reoriented;
    report.fixed_nodes = prepared.fixed.len();
    report.source_hash = prepared.hash.clone();
    let solved = solve(&prepared, &mat, params, file, progress, &mut report)?;
    let free_free = prepared.fixed.is_empty();
    let elastic = elastic_modes(&solved.res, params, free_free, file, &mut report)?;
    let base = base_of(prepared, solved, &elastic, params, &mut report);
    Ok((base, report))
}

/// Rigid-body modes a mesh has: 6 free-free, 0 with fixed nodes.
fn rigid_count(free_free: bool) -> usize {
    if free_free {
        6
    } else {
        0
    }
}

/// What the eigensolve step yields: the free-dof map, the modes and the surface.
struct Solved {
    map: fem::DofMap,
    res: eigen::EigenResult,
    surface: Surface,
}

/// Assembles K and M on the free dofs and solves for the lowest modes (plus the six rigid-body
/// modes of a free-free object), extracting the surface on a second thread meanwhile.
fn solve(
    prepared: &Prepared,
    mat: &fem::Material,
    params: &BakeParams,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
    report: &mut BakeReport,
) -> Result<Solved, BakeError> {
    let Prepared {
        mesh,
        fixed,
        mid_table,
        ..
    } = prepared;
    progress(BakeStage::Assemble);
    let t = Instant::now();
    let (map, kf, mf) = fem::assemble_clamped(mesh, mat, params.lumped, fixed)
        .map_err(|e| BakeError::Params(format!("{file}: {e}")))?;
    report.assemble_s = t.elapsed().as_secs_f64();
    report.free_dofs = map.n_free();
    report.mass_kg = mat.density * mesh.volume();

    let free_free = fixed.is_empty();
    let rigid = rigid_count(free_free);
    let wanted = params.min_modes() + rigid;
    if wanted > map.n_free() {
        return Err(BakeError::Params(format!(
            "{file}: parameter `modes` asks for {}: at most {} modes for this mesh (3 × {} nodes − {} fixed dofs{} = {})",
            params.min_modes(),
            map.n_free().saturating_sub(rigid),
            mesh.nodes.len(),
            3 * mesh.nodes.len() - map.n_free(),
            if rigid > 0 { " − 6 rigid" } else { "" },
            map.n_free().saturating_sub(rigid)
        )));
    }
    let eparams = EigenParams {
        nev: wanted,
        max_freq_hz: match params.modes {
            ModeRequest::MaxFreqHz(f) => Some(f),
            ModeRequest::Count(_) => None,
        },
        shift: if free_free {
            eigen::default_shift(mesh, mat)
        } else {
            0.0
        },
        // The MAX_RESIDUAL a written mode must meet: the solver confirms every pair on the
        // same explicit residual, so a stricter tolerance only buys iterations (1e-10 is below
        // the rounding floor of the higher modes of fine meshes).
        tol: MAX_RESIDUAL,
        ..Default::default()
    };
    // The surface and its heat-geodesic ordering depend on the mesh only: they are computed
    // on a second thread during the factorization and eigensolve (the bake bench's 3k / 15k
    // beams: ≈ 5 / 17 ms, otherwise after it).
    progress(BakeStage::Factor);
    let (res, surface) = std::thread::scope(|scope| {
        let surface = scope.spawn(|| Surface::of(mesh, mid_table));
        let res = eigen::solve_lowest(&kf, &mf, &eparams, &mut |p| {
            progress(BakeStage::Eigensolve(p))
        });
        (
            res,
            surface.join().expect("the surface thread does not panic"),
        )
    });
    let res = res.map_err(|error| BakeError::Eigen {
        file: file.to_string(),
        error: explain_factorization(error, mat),
    })?;
    report.factor_s = res.info.factor_seconds;
    report.eigensolve_s = res.info.solve_seconds;
    Ok(Solved { map, res, surface })
}

/// A factorization failure with the material's part in it: a Poisson ratio near 0.5 (nearly
/// incompressible: the volumetric stiffness is 2ν/(1 − 2ν) times the shear stiffness) or near
/// −1 (the bulk modulus vanishes) makes K too ill-conditioned to factor in double precision,
/// though ν is inside (−1, 0.5).
fn explain_factorization(error: eigen::EigenError, mat: &fem::Material) -> eigen::EigenError {
    let nu = mat.poisson;
    match error {
        eigen::EigenError::Factorization(msg) if !(-0.9..=0.45).contains(&nu) => {
            eigen::EigenError::Factorization(format!(
                "{msg}; the Poisson ratio --poisson {nu} is so close to {} that the stiffness \
                 matrix cannot be factored in double precision (volumetric / shear stiffness \
                 2ν/(1 − 2ν) = {:.3e}); use a ratio in −0.9 … 0.45 (rubber-like materials bake \
                 well at 0.45)",
                if nu > 0.0 { "0.5" } else { "−1" },
                2.0 * nu / (1.0 - 2.0 * nu)
            ))
        }
        other => other,
    }
}

/// The indices of the elastic modes to keep: after exactly six rigid-body modes of a
/// free-free object, the requested count or those below the requested frequency, each with a
/// residual ≤ [`MAX_RESIDUAL`] (or at its double-precision floor) and λ > 0.
fn elastic_modes(
    res: &eigen::EigenResult,
    params: &BakeParams,
    free_free: bool,
    file: &str,
    report: &mut BakeReport,
) -> Result<Vec<usize>, BakeError> {
    // Rigid-body modes: exactly six near-zero eigenvalues for a free-free object.
    let rigid = rigid_count(free_free);
    let mut first = 0;
    if free_free {
        let lam7 = res
            .eigenvalues
            .get(rigid)
            .copied()
            .unwrap_or(f64::INFINITY)
            .abs();
        let tol = RIGID_REL_TOL * lam7;
        let near_zero = res.eigenvalues.iter().filter(|l| l.abs() <= tol).count();
        if near_zero != rigid {
            return Err(BakeError::RigidModes {
                file: file.to_string(),
                found: near_zero,
                tol,
            });
        }
        report.rigid_eigenvalues = res.eigenvalues[..rigid].to_vec();
        first = rigid;
    }
    report.rigid_modes_excluded = first;
    let elastic: Vec<usize> = (first..res.eigenvalues.len())
        .filter(|&j| match params.modes {
            ModeRequest::Count(n) => j < first + n,
            ModeRequest::MaxFreqHz(f) => {
                res.eigenvalues[j].max(0.0).sqrt() / (2.0 * std::f64::consts::PI) < f
            }
        })
        .collect();
    if elastic.is_empty() {
        return Err(BakeError::Params(format!(
            "{file}: no elastic mode below the requested frequency (lowest is {:.4} Hz)",
            res.eigenvalues
                .get(first)
                .map_or(0.0, |l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        )));
    }
    for (i, &j) in elastic.iter().enumerate() {
        // A mode passes at MAX_RESIDUAL, or within the eigensolver's factor of its double-
        // precision floor ε(‖|K||u|‖ + λ‖|M||u|‖)/‖Ku‖ ≈ ε·λ_max/λ, which exceeds 1e-8 for the
        // low modes of slender, finely meshed objects (measured: 1.5e-7 on a 300×10×10 beam):
        // no double-precision vector can do better there.
        let floor_ok = res.residuals[j] <= eigen::FLOOR_FACTOR * res.residual_floors[j];
        if !(res.residuals[j] <= MAX_RESIDUAL || floor_ok) || !(res.eigenvalues[j] > 0.0) {
            return Err(BakeError::NotConverged {
                file: file.to_string(),
                mode: i,
                residual: res.residuals[j],
            });
        }
    }
    Ok(elastic)
}

/// The base: the surface rows of the `elastic` modes, the surface, material and metadata.
fn base_of(
    prepared: Prepared,
    solved: Solved,
    elastic: &[usize],
    params: &BakeParams,
    report: &mut BakeReport,
) -> ModesFile {
    let Prepared {
        mesh,
        fixed,
        reoriented,
        hash,
        ..
    } = prepared;
    let Solved { map, res, surface } = solved;
    // Surface rows of U.
    let full = map.expand(res.vectors.as_ref());
    let Surface {
        nodes: surf,
        positions,
        triangles,
        order,
        edges,
        edge_nodes,
    } = surface;
    let nm = elastic.len();
    let rows_of = |nodes: &[usize]| {
        let mut modes = Vec::with_capacity(nodes.len() * 3 * nm);
        for &v in nodes {
            for axis in 0..3 {
                for &j in elastic {
                    modes.push(if v < mesh.nodes.len() {
                        full[(3 * v + axis, j)]
                    } else {
                        f64::NAN // refused by the base's validation
                    });
                }
            }
        }
        modes
    };
    let modes = rows_of(&surf);
    let quadratic = mesh.is_quadratic().then(|| QuadraticSurface {
        edge_to_volume: edge_nodes.iter().map(|&v| v as u32).collect(),
        modes: rows_of(&edge_nodes),
        edges,
    });
    let eigenvalues: Vec<f64> = elastic.iter().map(|&j| res.eigenvalues[j]).collect();
    let residuals: Vec<f64> = elastic.iter().map(|&j| res.residuals[j]).collect();
    let base = ModesFile {
        eigenvalues,
        surface_vertices: positions,
        surface_triangles: triangles,
        surface_to_volume: surf.iter().map(|&v| v as u32).collect(),
        modes,
        material: params.material,
        rayleigh: params.rayleigh,
        fixed_nodes: fixed.iter().map(|&v| v as u32).collect(),
        residuals,
        meta: ModesMeta {
            format_version: 1,
            tool_version: TOOL_VERSION.to_string(),
            source_hash: hash,
            params_hash: params.hash(),
            bake_params: {
                let mut v = serde_json::to_value(params).expect("params serialise");
                if let Some(obj) = v.as_object_mut() {
                    obj.insert("output_version".into(), OUTPUT_VERSION.into());
                }
                v
            },
            volume_nodes: mesh.nodes.len(),
            volume_tets: mesh.tets.len(),
            rigid_modes_excluded: report.rigid_modes_excluded,
            mass_kg: report.mass_kg,
            reoriented_tets: reoriented,
            accuracy: None,
        },
        precision: params.precision,
        transfer: None,
        surface_order: order,
        quadratic,
    };
    let mut base = base;
    base.meta.format_version = base.required_format_version();
    report.surface_edge_nodes = base.quadratic.as_ref().map_or(0, |q| q.edges.len());
    report.modes = nm;
    report.frequencies_hz = base.frequencies_hz();
    report.residuals = base.residuals.clone();
    report.residual_floors = elastic.iter().map(|&j| res.residual_floors[j]).collect();
    report.surface_vertices = base.surface_vertices.len();
    report.surface_triangles = base.surface_triangles.len();
    base
}

/// The base of `mesh` with the peak-transfer table `tp` (see [`bake_mesh`]).
fn bake_with_table(
    mesh: TetMesh,
    params: &BakeParams,
    tp: &crate::transfer::TransferParams,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<(ModesFile, BakeReport), BakeError> {
    use crate::transfer::{self as tr, TransferModes};
    let terr = |error| BakeError::Transfer {
        file: file.to_string(),
        error: Box::new(error),
    };
    tp.check().map_err(terr)?;
    if mesh.is_quadratic() {
        return Err(terr(tr::TransferError::Params(
            "parameter `transfer`: a peak-transfer table is not supported for second-order (10-node) meshes: the table interpolates P1 midpoint rows; bake the linear mesh for a table".into(),
        )));
    }
    let (mut base, mut report) = bake_modes(mesh.clone(), params, file, progress)?;
    // The region and its points depend on the surface only: an empty or oversized region is
    // refused before the table's modes are solved (the plan over the base's own modes).
    tr::plan_transfer_table(
        &base,
        &tr::TransferParams {
            modes: TransferModes::Count(base.num_modes()),
            budget: None,
            ..tp.clone()
        },
    )
    .map_err(terr)?;
    let t = Instant::now();
    let tp = &tr::TransferParams {
        modes: tp.modes.resolve(report.free_dofs),
        ..tp.clone()
    };
    let enough = matches!(tp.modes, TransferModes::Count(n) if n <= base.num_modes());
    let (set, mode_source) = if enough {
        (None, "base")
    } else if report.free_dofs <= tr::DENSE_MAX_DOFS {
        progress(BakeStage::TransferModes);
        let set = super::mode_set_dense(&base, &mesh, params, tp.modes, file).map_err(terr)?;
        (Some(set), "dense")
    } else {
        let TransferModes::Count(n) = tp.modes else {
            return Err(terr(tr::TransferError::Params(format!(
                "parameter `transfer.modes` = all needs the dense eigensolve, but the mesh has {} free dofs (limit {}); give a count",
                report.free_dofs,
                tr::DENSE_MAX_DOFS
            ))));
        };
        progress(BakeStage::TransferModes);
        let set = super::mode_set_lanczos(&mesh, params, n, file)?;
        (Some(set), "lanczos")
    };
    let modes_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut plan = None;
    let table = tr::build_transfer_table(
        set.as_ref().unwrap_or(&base),
        tp,
        params.rayleigh,
        &mut |p| {
            plan = Some(p.plan);
            progress(BakeStage::Transfer(p))
        },
    )
    .map_err(terr)?;
    report.transfer = Some(
        TransferReport::of(&table, mode_source, modes_s, t.elapsed().as_secs_f64()).with_plan(plan),
    );
    if let Some(obj) = base.meta.bake_params.as_object_mut() {
        obj.insert("transfer".into(), transfer_meta(tp, params));
    }
    base.transfer = Some(table);
    Ok((base, report))
}

/// The record of a transfer table's parameters in `meta.bake_params.transfer` (what
/// [`base_status`] compares). A base fixed by half-spaces, boxes or `near` sets records
/// `"modes_fixed_by": "every selector"`: its table's extra modes are solved with those nodes
/// fixed, where tables baked before that was so were solved with the physical groups alone —
/// such bases lack the key and are stale.
pub(crate) fn transfer_meta(
    tp: &crate::transfer::TransferParams,
    params: &BakeParams,
) -> serde_json::Value {
    use crate::transfer::TransferModes;
    let mut meta = serde_json::json!({
        "h": tp.h,
        "modes": match tp.modes {
            TransferModes::All => serde_json::json!("all"),
            TransferModes::Auto => serde_json::json!("auto"),
            TransferModes::Count(n) => serde_json::json!(n),
        },
        "regions": tp.boxes,
        "up": tp.up,
        "up_min_cos": tp.up_min_cos,
        "oversample": tp.oversample,
        "order": match tp.order {
            crate::transfer::TableOrder::Auto => serde_json::json!("auto"),
            crate::transfer::TableOrder::Linear => serde_json::json!(1),
            crate::transfer::TableOrder::Quadratic => serde_json::json!(2),
            crate::transfer::TableOrder::Cubic => serde_json::json!(3),
        },
    });
    let selectors = params.fixed_selectors();
    if !(selectors.below.is_empty() && selectors.boxes.is_empty() && selectors.near.is_empty()) {
        meta["modes_fixed_by"] = "every selector".into();
    }
    meta
}

/// Reads `mesh_path`, bakes it ([`bake_mesh`], with the transfer table when `params` asks for
/// one) and writes `out` atomically (nothing is left on failure), creating `out`'s folder if it
/// is missing ([`BakeReport::created_folder`]).
///
/// # Errors
/// A [`BakeError`] naming the file and what failed.
pub fn bake_file(
    mesh_path: &Path,
    params: &BakeParams,
    out: &Path,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<BakeReport, BakeError> {
    progress(BakeStage::Read);
    let t = Instant::now();
    let mesh = crate::mesh::read_mesh(mesh_path)?;
    let read_s = t.elapsed().as_secs_f64();
    let (base, mut report) = bake_mesh(mesh, params, &mesh_path.display().to_string(), progress)?;
    report.read_s = read_s;
    progress(BakeStage::Write);
    let t = Instant::now();
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.exists() {
            std::fs::create_dir_all(dir).map_err(|source| FormatError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
            report.created_folder = Some(dir.display().to_string());
        }
    }
    base.write_atomic(out)?;
    report.write_s = t.elapsed().as_secs_f64();
    Ok(report)
}
