//! The shared, immutable modal model: a validated `.modes` base plus what every query needs
//! (area-weighted vertex normals, per-vertex normal mode rows nᵀU, ω_j, and a BVH over the
//! surface for point → surface mapping, paper §4.2). Second-order bases interpolate the mode
//! rows with the quadratic shape functions of their 6-node surface triangles
//! ([`quadratic_triangle_weights`]); mapping, normals and geodesics use the linear triangles
//! of the corners, which are the exact geometry of straight-sided elements.

mod load_error;
mod modal_model;

pub use crate::surface_point::{
    area_weighted_normals, quadratic_triangle_weights, surface_point_on, SurfacePoint,
};
pub use load_error::LoadError;
pub use modal_model::ModalModel;

#[cfg(test)]
mod tests;
