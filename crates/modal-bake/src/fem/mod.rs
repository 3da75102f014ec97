//! FEM assembly: P1 (4-node) and P2 (10-node, straight-sided) tetrahedra, isotropic linear
//! elasticity, SI units
//! (paper §4.1, Eq. 5: the K and M of M ü + D u̇ + K u = f).
//!
//! - [`assemble_stiffness`]: K (N/m), [`assemble_mass`]: M (kg), consistent or lumped.
//!   Dofs are node-major (`3·node + axis`), matrices are stored with both triangles, rows
//!   sorted. Summation order is fixed, so the matrices are bit-identical for any thread count.
//! - [`DofMap`] / [`reduce_fixed`]: clamp nodes (restrict K, M to the free dofs, expand modes
//!   back with zeros); [`assemble_clamped`] assembles the restricted K and M directly (what
//!   the bake uses: bit-identical, without the full matrices).
//! - [`rigid_body_modes`]: the 6-dimensional null space of the free-free K.
//!
//! - [`MaterialPreset`]: named typical materials (`--material steel`).
//!
//! Unsupported: anisotropic or heterogeneous materials, curved (non-affine) 10-node
//! tetrahedra (refused by [`crate::mesh::TetMesh::check_straight`] before assembly).

mod assembly;
mod dof_map;
mod material;
mod material_preset;

pub use assembly::{assemble_clamped, assemble_mass, assemble_stiffness, rigid_body_modes};
pub use dof_map::{reduce_fixed, DofMap, DofMapError};
pub use material::{Material, MaterialError};
pub use material_preset::MaterialPreset;
