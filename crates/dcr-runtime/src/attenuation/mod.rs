//! Spatial attenuation (paper §4.4, Eq. 14–16, 19): a local amplitude q̂ per surface vertex (the
//! peak normal displacement of a vertex under a unit normal impulse at itself, §4.3 procedure),
//! scaled by s(r) of the impact → contact distance r, measured on the surface with the heat
//! method (Crane, Weischedel & Wardetzky 2013) or straight-line.

mod attenuation_params;
mod distance_cache;
mod geodesic_table;
mod heat_geodesic;
mod sparse_llt;

pub use attenuation_params::{AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind};
pub(crate) use distance_cache::DistanceCache;
pub use geodesic_table::GeodesicTable;
#[cfg(feature = "bench-internals")]
#[doc(hidden)]
pub use heat_geodesic::LltProbe;
pub use heat_geodesic::{GeodesicError, HeatGeodesic, HeatWorkspace};

#[cfg(test)]
mod tests;
