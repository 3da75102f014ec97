//! What determines a bake's result: [`BakeParams`] (material, modes, fixed-node selectors,
//! damping, precision, the optional transfer table) and its content hash.

use sha2::{Digest, Sha256};

use super::BakeError;
use crate::fem::Material;
use dcr_runtime::format::{MaterialSi, ModesPrecision};

/// How many modes to keep.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeRequest {
    /// The lowest `n` elastic modes.
    Count(usize),
    /// Every elastic mode below this frequency (Hz).
    MaxFreqHz(f64),
}

/// Everything that determines a bake's result (SI units).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BakeParams {
    /// Isotropic material (E in Pa, ν, ρ in kg/m³). Default: the paper's table, 1.1 GPa, 0.3, 770.
    pub material: MaterialSi,
    /// Modes to keep. Default: the lowest 20.
    pub modes: ModeRequest,
    /// Names of physical groups whose nodes are fixed (empty: free-free).
    pub fixed: Vec<String>,
    /// Fix every node at or below a coordinate (`--fixed-below y=0.01`); combined with the
    /// other selectors by union.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_below: Vec<FixedBelow>,
    /// Fix every node inside an axis-aligned box `[x0, y0, z0, x1, y1, z1]` (m, object frame,
    /// bounds included; `--fixed-box`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_boxes: Vec<[f64; 6]>,
    /// Fix every node within a distance of given points and triangles (m, object frame;
    /// `--fixed-near FILE`, e.g. a vertex group's vertices and faces).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_near: Vec<super::FixedNear>,
    /// Default Rayleigh damping stored in the base (α0 in 1/s, α1 in s). Default (10, 1e-7).
    pub rayleigh: [f64; 2],
    /// Lumped (diagonal) mass instead of consistent mass.
    pub lumped: bool,
    /// Storage precision of the surface mode shapes.
    pub precision: ModesPrecision,
    /// The bake-time peak-transfer table ([`crate::transfer`]) to build over the base; `None`
    /// (the default) for none. Not serialized, so not part of [`BakeParams::hash`]: a bake
    /// records the table's parameters in `meta.bake_params.transfer` and staleness checks
    /// compare them on their own.
    #[serde(skip)]
    pub transfer: Option<crate::transfer::TransferParams>,
}

/// A half-space selector of fixed nodes: every node whose coordinate `axis` is ≤ `value`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FixedBelow {
    /// The axis: 0 = x, 1 = y, 2 = z (object frame).
    pub axis: usize,
    /// The threshold (m); nodes at or below it are fixed.
    pub value: f64,
}

impl std::fmt::Display for FixedBelow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let axis = ["x", "y", "z"].get(self.axis).copied().unwrap_or("?");
        write!(f, "{axis}={}", self.value)
    }
}

impl Default for BakeParams {
    fn default() -> Self {
        BakeParams {
            material: MaterialSi {
                youngs: 1.1e9,
                poisson: 0.3,
                density: 770.0,
            },
            modes: ModeRequest::Count(20),
            fixed: Vec::new(),
            fixed_below: Vec::new(),
            fixed_boxes: Vec::new(),
            fixed_near: Vec::new(),
            rayleigh: [10.0, 1e-7],
            lumped: false,
            precision: ModesPrecision::F64,
            transfer: None,
        }
    }
}

/// The schema number mixed into [`BakeParams::hash`]; changes only when the meaning of a
/// parameter changes (new parameters at their defaults leave the hash unchanged).
const PARAMS_HASH_VERSION: u32 = 1;

impl BakeParams {
    /// The number of elastic modes requested as a minimum count (1 for a frequency request).
    pub(super) fn min_modes(&self) -> usize {
        match self.modes {
            ModeRequest::Count(n) => n,
            ModeRequest::MaxFreqHz(_) => 1,
        }
    }

    /// Checks the parameters (material ranges, mode request, damping, fixed-node selectors)
    /// before any mesh work; returns the material.
    ///
    /// # Errors
    /// [`BakeError::Params`] or a material error naming the parameter.
    pub fn check(&self) -> Result<Material, BakeError> {
        let mat = Material::new(
            self.material.youngs,
            self.material.poisson,
            self.material.density,
        )?;
        match self.modes {
            ModeRequest::Count(0) => {
                return Err(BakeError::Params(
                    "parameter `modes`: the mode count must be at least 1".into(),
                ))
            }
            ModeRequest::Count(n) if n > 5000 => {
                return Err(BakeError::Params(format!(
                    "parameter `modes`: {n} modes is more than the supported 5000"
                )))
            }
            ModeRequest::MaxFreqHz(f) if !(f.is_finite() && f > 0.0) => {
                return Err(BakeError::Params(format!(
                    "parameter `modes`: the maximum frequency must be positive (Hz), got {f}"
                )))
            }
            _ => {}
        }
        if !self.rayleigh.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(BakeError::Params(format!(
                "parameter `rayleigh`: the coefficients must be finite and ≥ 0, got {:?}",
                self.rayleigh
            )));
        }
        self.fixed_selectors().check()?;
        Ok(mat)
    }

    /// The fixed-node selectors (`fixed`, `fixed_below`, `fixed_boxes`, `fixed_near`), borrowed.
    pub fn fixed_selectors(&self) -> super::FixedSelectors<'_> {
        super::FixedSelectors {
            groups: &self.fixed,
            below: &self.fixed_below,
            boxes: &self.fixed_boxes,
            near: &self.fixed_near,
        }
    }

    /// `sha256:<hex>` of everything in these parameters that changes the result, plus a
    /// schema number.
    pub fn hash(&self) -> String {
        let json = serde_json::to_vec(&(PARAMS_HASH_VERSION, self)).expect("params serialise");
        format!("sha256:{:x}", Sha256::digest(&json))
    }
}
