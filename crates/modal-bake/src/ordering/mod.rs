//! Fill-reducing orderings computed at bake time: METIS nested dissection (`metis.rs`, the
//! crate's one C dependency) and the heat-geodesic surface order stored in a base
//! (`surface_order.rs`). The volume stiffness ordering (AMD or nested dissection, whichever
//! fills less) lives with the eigensolver in `eigen/ordering.rs` and calls [`nested_dissection`].
//! [`c_rand`]: the C library's `rand` as glibc computes it, which the `modal-bake` program
//! gives METIS on every platform.

pub mod c_rand;
mod metis;
mod surface_order;

pub use metis::nested_dissection;
pub use surface_order::plan_surface_order;
