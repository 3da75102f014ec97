//! `dcr-lab truth --base BASE.modes`: the reference of a base's own object — its material,
//! damping and fixed nodes, its mesh read as it was baked (`selection`), checked to be the
//! mesh it was baked from — and the base's own response at the same points (the runtime's
//! default method: its transfer table where it serves, else its modes), with its error.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Context;
use clap::ValueEnum;
use dcr_runtime::format::ModesFile;
use dcr_runtime::response::{Impact, RestingContact};
use dcr_runtime::{DistantResponse, ModalModel, ResponseParams};
use modal_bake::bake::{BakeParams, BaseStatus};
use modal_bake::full_order::SystemParams;
use modal_bake::mesh::{TetMesh, Units};

use super::mesh_input::MeshInput;

/// A base whose object a reference is computed for.
pub struct BaseUnderTest {
    path: PathBuf,
    base: ModesFile,
    bake: BakeParams,
}

/// The base's response at one contact.
#[derive(serde::Serialize)]
pub struct BasePeak {
    /// Peak normal displacement (m) over the window h.
    pub peak_displacement_m: f64,
    /// What served it: `modal`, `transfer_table`, `unmapped`.
    pub served_by: &'static str,
    /// (base − truth) / truth × 100 (%); `None` where the reference is 0 (a fixed point).
    pub error_pct: Option<f64>,
}

impl BaseUnderTest {
    /// Reads the base at `path` and its record of how it was baked.
    ///
    /// # Errors
    /// An unreadable base, or one whose record is not a `modal-bake bake`'s.
    pub fn load(path: &Path) -> anyhow::Result<BaseUnderTest> {
        let base = ModesFile::read(path).map_err(|e| anyhow::anyhow!("{e}"))?;
        let bake: BakeParams = serde_json::from_value(base.meta.bake_params.clone())
            .map_err(|e| {
                anyhow::anyhow!(
                    "{}: its record (meta.bake_params) is not a modal-bake bake's ({e}); give the material and fixed-node options instead of --base",
                    path.display()
                )
            })?;
        Ok(BaseUnderTest {
            path: path.to_path_buf(),
            base,
            bake,
        })
    }

    /// The object the base describes: material, fixed-node selectors, damping, lumping.
    pub fn system(&self) -> SystemParams {
        SystemParams::of_bake(&self.bake)
    }

    /// How its mesh file is read: the recorded `--units`, `--object`, `--piece`.
    pub fn input(&self) -> MeshInput {
        let sel = self.base.meta.bake_params.get("selection");
        let get = |k: &str| sel.and_then(|s| s.get(k));
        MeshInput {
            units: get("units")
                .and_then(|u| u.as_str())
                .and_then(|u| Units::from_str(u, true).ok())
                .unwrap_or_default(),
            object: get("object").and_then(|o| o.as_str()).map(str::to_string),
            piece: get("piece").and_then(serde_json::Value::as_u64),
        }
    }

    /// Checks that `mesh` (read from `file`) is the mesh the base was baked from.
    ///
    /// # Errors
    /// Another mesh (with what differs), or a mesh the bake would refuse.
    pub fn check_mesh(&self, mesh: &TetMesh, file: &str) -> anyhow::Result<()> {
        let params = BakeParams {
            transfer: None,
            ..self.bake.clone()
        };
        let not_it = || {
            format!(
                "{file} is not the mesh {} was baked from",
                self.path.display()
            )
        };
        let status = modal_bake::bake::mesh_base_status(mesh.clone(), file, &params, &self.path)
            .with_context(not_it)?;
        match status {
            BaseStatus::GeometryChanged(d) => anyhow::bail!("{}: {d}", not_it()),
            _ => Ok(()),
        }
    }

    /// The base's response over the window `h` (s) to `impulse` (N·s) at `impact` along
    /// `direction` (the truth's), at `contacts` (m, object frame), against the truth's peaks.
    ///
    /// # Errors
    /// Parameters the runtime refuses, a point off the surface.
    pub fn peaks(
        &self,
        h: f64,
        impact: [f64; 3],
        direction: [f64; 3],
        impulse: f64,
        contacts: &[[f64; 3]],
        truth: &[f64],
    ) -> anyhow::Result<Vec<BasePeak>> {
        let model =
            Arc::new(ModalModel::from_base(self.base.clone()).map_err(|e| anyhow::anyhow!("{e}"))?);
        let params = ResponseParams {
            h,
            impact_threshold: 0.0,
            ..ResponseParams::default()
        };
        let mut resp = DistantResponse::new(model, params)
            .with_context(|| format!("{}: invalid parameters", self.path.display()))?;
        let resting: Vec<RestingContact> = contacts
            .iter()
            .enumerate()
            .map(|(i, &point)| RestingContact {
                id: i as u64,
                point,
            })
            .collect();
        let out = resp.step(
            &[Impact {
                point: impact,
                direction,
                impulse,
            }],
            &resting,
        );
        Ok(out
            .iter()
            .zip(truth)
            .map(|(o, &t)| BasePeak {
                peak_displacement_m: o.peak_displacement,
                served_by: o.served_by.name(),
                error_pct: (t != 0.0).then(|| 100.0 * (o.peak_displacement - t) / t),
            })
            .collect())
    }

    /// The base's mode count.
    pub fn modes(&self) -> usize {
        self.base.num_modes()
    }

    /// The base's file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
