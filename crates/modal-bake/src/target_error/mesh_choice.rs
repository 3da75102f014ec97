//! Choosing a surface asset's mesh for an accuracy target (`modal-bake bake ASSET
//! --target-error PCT` without a transfer table): mesh at a starting element size, bake the
//! lowest modes, mesh again at the size divided by [`REFINE`], and stop when no one of the
//! lowest modes moved by more than the target between the last two meshes. Every element
//! scales with the size (gmsh's curvature-driven sizes too, [`crate::mesh::sizing`]), so each
//! step refines the whole mesh. A step whose mesh
//! is the previous one (a mesher that keeps a finer size of its own) is not compared.
//!
//! Conforming finite elements converge from above at a rate h^p (p = 2 for 4-node, 4 for
//! 10-node tetrahedra, the square of the displacement's order), so with r = [`REFINE`] the
//! change c between the meshes of size h and h/r bounds the error of the finer one by
//! Richardson extrapolation: e(h/r) ≈ c · r^(−p) / (1 − r^(−p)) ([`MeshChoice::error_pct`]).
//! The loop stops before a step whose size estimate is over the budget (the caller's
//! `fits`), keeping the finest mesh that fitted and saying the target was not reached.

use super::super::bake::{bake_mesh, BakeError, BakeParams, BakeStage, ModeRequest};
use crate::mesh::TetMesh;

/// Size ratio between successive meshes (≈ 2.7× the tetrahedra per step).
pub const REFINE: f64 = 1.4;

/// Most meshes tried.
pub const MAX_STEPS: usize = 6;

/// One mesh of the refinement.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MeshStep {
    /// Element size asked of the mesher (m).
    pub size_m: f64,
    /// Tetrahedra.
    pub tets: usize,
    /// Free degrees of freedom.
    pub dofs: usize,
    /// The lowest elastic frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Largest relative change of those frequencies from the previous mesh (%); `None` for the
    /// first, and for a mesh identical to the previous one (the mesher did not refine).
    pub change_pct: Option<f64>,
}

/// The mesh chosen and the steps that led to it.
#[derive(Clone, Debug)]
pub struct MeshChoice {
    /// The finest mesh made (the one to bake).
    pub mesh: TetMesh,
    /// Every mesh tried, coarsest first.
    pub steps: Vec<MeshStep>,
    /// Whether the last change was at most the target.
    pub converged: bool,
    /// Element order of the meshes.
    pub order: u8,
}

impl MeshChoice {
    /// The Richardson estimate of the chosen mesh's frequency error (%): the last change ×
    /// r^(−p)/(1 − r^(−p)) (see the module doc); `None` after a single mesh.
    pub fn error_pct(&self) -> Option<f64> {
        let c = self.steps.last()?.change_pct?;
        let p = if self.order == 2 { 4 } else { 2 };
        let q = REFINE.powi(-p);
        Some(c * q / (1.0 - q))
    }
}

/// Refines the mesh of an asset until its lowest `modes` frequencies (with `params`'
/// material and fixed-node selectors) change by at most `target_pct` % between successive
/// meshes (see the module doc). `mesh_at(size)` meshes the asset at an element size (m);
/// `fits(size)` says whether a mesh of that size is within the budget. Starts at
/// `start_size`.
///
/// # Errors
/// A bad target; the first mesh over the budget; a meshing or bake failure.
#[allow(clippy::too_many_arguments)]
pub fn choose_mesh(
    mesh_at: &mut dyn FnMut(f64) -> Result<TetMesh, BakeError>,
    fits: &mut dyn FnMut(f64) -> bool,
    start_size: f64,
    order: u8,
    params: &BakeParams,
    target_pct: f64,
    modes: usize,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<MeshChoice, BakeError> {
    if !(target_pct.is_finite() && target_pct > 0.0) {
        return Err(BakeError::Params(format!(
            "{file}: the target error must be a percentage > 0, got {target_pct}"
        )));
    }
    if !fits(start_size) {
        return Err(BakeError::Params(format!(
            "{file}: the first mesh of the refinement (size {start_size:.4e} m) is already over the budget; give a larger --size or raise --max-memory / --max-time"
        )));
    }
    let probe = BakeParams {
        modes: ModeRequest::Count(modes),
        transfer: None,
        ..params.clone()
    };
    let mut steps: Vec<MeshStep> = Vec::new();
    let mut size = start_size;
    let mut best: Option<TetMesh> = None;
    let mut converged = false;
    for _ in 0..MAX_STEPS {
        let mesh = mesh_at(size)?;
        let tets = mesh.tets.len();
        let (base, report) = bake_mesh(mesh.clone(), &probe, file, progress)?;
        let freqs = base.frequencies_hz();
        // A mesher that did not refine (the same tetrahedra at a smaller size) proves nothing:
        // compare with the previous mesh only when this one is finer.
        let prev = steps.last();
        let same = prev.is_some_and(|p| p.tets == tets && p.dofs == report.free_dofs);
        let change = prev.filter(|_| !same).map(|prev| {
            prev.frequencies_hz
                .iter()
                .zip(&freqs)
                .map(|(a, b)| ((a - b) / b).abs() * 100.0)
                .fold(0.0f64, f64::max)
        });
        steps.push(MeshStep {
            size_m: size,
            tets,
            dofs: report.free_dofs,
            frequencies_hz: freqs,
            change_pct: change,
        });
        best = Some(mesh);
        if change.is_some_and(|c| c <= target_pct) {
            converged = true;
            break;
        }
        let next = size / REFINE;
        if !fits(next) {
            break;
        }
        size = next;
    }
    Ok(MeshChoice {
        mesh: best.expect("at least one mesh was made"),
        steps,
        converged,
        order,
    })
}
