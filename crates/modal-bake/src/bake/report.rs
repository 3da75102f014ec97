//! What a bake reports besides the base ([`BakeReport`], [`TransferReport`]) and its progress
//! stages ([`BakeStage`]).

use crate::eigen::EigenProgress;

/// What a bake reports besides the base: timings (s) and facts about the mesh and the modes.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct BakeReport {
    /// Seconds spent reading the mesh.
    pub read_s: f64,
    /// Seconds assembling K and M.
    pub assemble_s: f64,
    /// Seconds in the numeric (and symbolic) factorization of K − σM.
    pub factor_s: f64,
    /// Seconds in the eigensolver after factorization.
    pub eigensolve_s: f64,
    /// Seconds writing the file.
    pub write_s: f64,
    /// Volume nodes and tetrahedra.
    pub nodes: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Free degrees of freedom solved for.
    pub free_dofs: usize,
    /// Inverted tetrahedra reoriented.
    pub reoriented_tets: usize,
    /// Fixed nodes (the union of every selector's).
    pub fixed_nodes: usize,
    /// What each fixed-node selector picked: (`group NAME` / `below y=0.01` / `box ...`,
    /// nodes), in the order groups, half-spaces, boxes; selectors may overlap.
    pub fixed_by: Vec<(String, usize)>,
    /// Element order: 1 (4-node tetrahedra) or 2 (10-node).
    pub order: u8,
    /// The material baked (E in Pa, ν, ρ in kg/m³).
    pub material: Option<dcr_runtime::format::MaterialSi>,
    /// Where the material came from, as the caller describes it (`steel`, `steel with
    /// --youngs`, `default (no --material given)`); empty when not said.
    pub material_name: String,
    /// Second-order bases: surface mid-edge nodes whose mode rows are stored (0 for P1).
    pub surface_edge_nodes: usize,
    /// Rigid-body modes detected and excluded (6 when free-free).
    pub rigid_modes_excluded: usize,
    /// Their eigenvalues (rad²/s²), as computed (≈ 0).
    pub rigid_eigenvalues: Vec<f64>,
    /// Elastic modes written.
    pub modes: usize,
    /// Their frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Their relative residuals.
    pub residuals: Vec<f64>,
    /// Their double-precision residual floors (see [`MAX_RESIDUAL`](super::MAX_RESIDUAL)).
    pub residual_floors: Vec<f64>,
    /// Surface vertices and triangles.
    pub surface_vertices: usize,
    /// Surface triangles.
    pub surface_triangles: usize,
    /// Object mass (kg).
    pub mass_kg: f64,
    /// Notes from reading (skipped element types, ...).
    pub notes: Vec<String>,
    /// Geometry hash stored in the base.
    pub source_hash: String,
    /// The peak-transfer table's figures (`None` without a table).
    pub transfer: Option<TransferReport>,
    /// Bounding-box diagonal of the mesh (m).
    pub extent_m: f64,
    /// The output's folder, when the bake had to create it ([`bake_file`](super::bake_file)).
    pub created_folder: Option<String>,
}

/// What a bake reports about the peak-transfer table it built ([`BakeParams::transfer`](super::BakeParams::transfer)).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct TransferReport {
    /// Seconds computing the table's modes (0 when the base's own modes sufficed).
    pub modes_s: f64,
    /// Seconds building the table.
    pub build_s: f64,
    /// Region vertices.
    pub vertices: usize,
    /// Region edges whose points are tabulated.
    pub edges: usize,
    /// Interpolation order (1, 2, 3).
    pub order: u8,
    /// Points (vertices, edge and face points).
    pub points: usize,
    /// Modes summed.
    pub modes: usize,
    /// Samples per step.
    pub samples: usize,
    /// Where its modes came from (`base`, `dense`, `lanczos`).
    pub mode_source: String,
    /// Points computed from their own normal rows (vertices' normals differ).
    pub bent: usize,
    /// The build's estimated wall time (s) and peak memory (bytes) before it started
    /// ([`TablePlan`](crate::transfer::TablePlan)); 0 when not planned.
    pub estimated_s: f64,
    /// See `estimated_s`.
    pub estimated_bytes: f64,
}

impl TransferReport {
    /// The figures of `table`, with the mode source and timings (s) given.
    pub fn of(
        table: &dcr_runtime::format::TransferTable,
        mode_source: &str,
        modes_s: f64,
        build_s: f64,
    ) -> Self {
        TransferReport {
            modes_s,
            build_s,
            vertices: table.len(),
            edges: table.edges.len(),
            order: table.order,
            points: table.num_points(),
            modes: table.modes as usize,
            samples: table.samples as usize,
            mode_source: mode_source.to_string(),
            ..TransferReport::default()
        }
    }

    /// With the build's plan: its bent points and estimate.
    pub fn with_plan(self, plan: Option<crate::transfer::TablePlan>) -> Self {
        match plan {
            None => self,
            Some(p) => TransferReport {
                bent: p.bent,
                estimated_s: p.seconds(),
                estimated_bytes: p.bytes(),
                ..self
            },
        }
    }
}

/// Progress of a bake, for a CLI bar.
#[derive(Clone, Copy, Debug)]
pub enum BakeStage {
    /// Reading the mesh.
    Read,
    /// Assembling K and M.
    Assemble,
    /// Factoring K − σM (before the first Lanczos step).
    Factor,
    /// Iterating; carries the eigensolver's progress.
    Eigensolve(EigenProgress),
    /// Solving for the transfer table's modes (dense or Lanczos).
    TransferModes,
    /// Building the transfer table; carries rows done / total.
    Transfer(crate::transfer::TransferProgress),
    /// Computing the converged full-order truth a choice by accuracy scores candidates
    /// against (`--target-error`); carries the refinement's level and samples.
    Truth(crate::full_order::RefineProgress),
    /// Writing the file.
    Write,
}

impl BakeStage {
    /// The stage in words, for progress lines and logs ("assembling K and M", …; the
    /// eigensolve's and the table's counts are in their progress values, not here).
    pub fn label(&self) -> &'static str {
        match self {
            BakeStage::Read => "reading mesh",
            BakeStage::Assemble => "assembling K and M",
            BakeStage::Factor => "factoring K − σM",
            BakeStage::Eigensolve(_) => "solving for the modes",
            BakeStage::TransferModes => "solving for the transfer table's modes",
            BakeStage::Transfer(_) => "building the transfer table",
            BakeStage::Truth(_) => "computing the full-order truth",
            BakeStage::Write => "writing",
        }
    }
}
