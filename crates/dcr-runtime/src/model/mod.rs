//! The shared, immutable modal model: a validated `.modes` base plus what every query needs
//! (area-weighted vertex normals, per-vertex normal mode rows nᵀU, ω_j, and a BVH over the
//! surface for point → surface mapping, paper §4.2).

mod load_error;
mod modal_model;
mod surface_point;

pub use load_error::LoadError;
pub use modal_model::ModalModel;
pub use surface_point::SurfacePoint;

#[cfg(test)]
mod tests;
