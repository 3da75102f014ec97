//! Modal bases for a scene's elastic objects: baked on demand into `out/bases/`, rebaked
//! when the mesh or the bake parameters change (content hashes, `modal_bake::bake::is_up_to_date`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use modal_bake::bake::{BakeParams, MaterialSi, ModeRequest};

use crate::scene::ElasticDesc;

/// The bake parameters of an elastic object (material, modes, fixed groups, Rayleigh).
pub fn bake_params(e: &ElasticDesc) -> BakeParams {
    BakeParams {
        material: MaterialSi {
            youngs: e.material.youngs,
            poisson: e.material.poisson,
            density: e.material.density,
        },
        modes: ModeRequest::Count(e.modes),
        fixed: e.fixed.clone(),
        rayleigh: e.rayleigh,
        ..BakeParams::default()
    }
}

/// Where an elastic object's base lives.
pub fn base_path(bases_dir: &Path, e: &ElasticDesc) -> PathBuf {
    bases_dir.join(format!("{}.modes", e.name))
}

/// Bakes `e`'s base into `bases_dir` unless an up-to-date one is there. Returns the path and
/// whether it baked. Progress on stderr.
///
/// # Errors
/// Mesh or bake failures, with the mesh path.
pub fn ensure_base(root: &Path, bases_dir: &Path, e: &ElasticDesc) -> Result<(PathBuf, bool)> {
    std::fs::create_dir_all(bases_dir)
        .with_context(|| format!("creating {}", bases_dir.display()))?;
    let mesh = root.join(&e.mesh);
    let params = bake_params(e);
    let out = base_path(bases_dir, e);
    let fresh = modal_bake::bake::is_up_to_date(&mesh, &params, &out)
        .with_context(|| format!("checking base of {}", mesh.display()))?;
    if fresh {
        return Ok((out, false));
    }
    eprintln!(
        "[dcr-scenes] baking {} ({} modes, fixed {:?}) -> {}",
        e.name,
        e.modes,
        e.fixed,
        out.display()
    );
    let t = std::time::Instant::now();
    let report = modal_bake::bake::bake_file(&mesh, &params, &out, &mut |_| {})
        .with_context(|| format!("baking {}", mesh.display()))?;
    eprintln!(
        "[dcr-scenes] baked {} in {:.1} s ({} nodes, {} tets)",
        e.name,
        t.elapsed().as_secs_f64(),
        report.nodes,
        report.tets
    );
    Ok((out, true))
}
