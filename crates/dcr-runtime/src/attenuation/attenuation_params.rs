//! Parameters of the spatial attenuation method (Eq. 14 and the §4.5 simplification).

/// Attenuation factor s(r) of the local amplitude at distance r (m) from the impact.
///
/// Distances are clamped from below at r0 (no amplification closer than r0): r ≤ r0 gives the
/// value at r0, i.e. s = 1 for [`AttenuationLaw::Full`] and s = C for
/// [`AttenuationLaw::Simplified`] (whose r0 is 1 m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AttenuationLaw {
    /// Eq. 14: s = exp(−α (r − r0)) (r/r0)^−β.
    Full {
        /// Material absorption α (1/m), ≥ 0.
        alpha: f64,
        /// Geometric spreading exponent β (≈ 0 rods, 0.5 shells, 1 volumes), ≥ 0.
        beta: f64,
        /// Minimum distance r0 (m), > 0.
        r0: f64,
    },
    /// §4.5: s = C r^−β with r0 = 1 m (r in m).
    Simplified {
        /// Constant C ≥ 0.
        c: f64,
        /// Exponent β ≥ 0.
        beta: f64,
    },
}

impl AttenuationLaw {
    /// s(r) for a distance `r` (m), clamped as documented on the type.
    pub fn factor(&self, r: f64) -> f64 {
        match *self {
            AttenuationLaw::Full { alpha, beta, r0 } => {
                let r = r.max(r0);
                (-alpha * (r - r0)).exp() * (r / r0).powf(-beta)
            }
            AttenuationLaw::Simplified { c, beta } => c * r.max(1.0).powf(-beta),
        }
    }
}

/// How the impact → resting-contact distance r is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DistanceKind {
    /// Heat-method geodesic distance on the surface (m), a field per resting contact, cached.
    /// A step whose uncached contacts outnumber twice its impacts caches the fields of only as
    /// many contacts as there are impacts and serves the rest from one field per impact (the
    /// distance is symmetric up to the method's discretisation error): at most 2 × impacts
    /// heat solves per step.
    Heat,
    /// Heat-method geodesic distances between every pair of surface vertices, computed once
    /// per model at set-up (ns heat solves on the rayon pool, ns² × 4 bytes shared by every
    /// instance of the model; [`crate::attenuation::GeodesicTable`]) and read bilinearly
    /// between the contact's and the impact's triangles: no solve per step, whatever the
    /// contacts do. For surfaces of up to [`crate::attenuation::GeodesicTable::MAX_VERTICES`]
    /// vertices; differs from [`DistanceKind::Heat`] inside triangles by the interpolation
    /// error.
    HeatTable,
    /// Straight-line distance between the mapped surface points.
    Euclidean,
}

/// Where the local amplitude q̂ comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum AmplitudeKind {
    /// q̂ of each vertex, interpolated at the impact with its barycentric weights (Eq. 15).
    PerVertex,
    /// The mean of q̂ over all surface vertices.
    Mean,
    /// The mean of q̂ over a subset of surface vertices (indices into the base's surface), e.g.
    /// the top of a slab (the paper's low-rider).
    MeanOver(Vec<u32>),
}

/// Parameters of [`crate::Method::Attenuation`].
#[derive(Clone, Debug, PartialEq)]
pub struct AttenuationParams {
    /// s(r) law.
    pub law: AttenuationLaw,
    /// Distance measure.
    pub distance: DistanceKind,
    /// Local amplitude source.
    pub amplitude: AmplitudeKind,
    /// Most heat-method distance fields kept (one per resting contact, least recently used
    /// evicted; memory ns × 8 bytes each). 0: nothing kept; each step solves one field per
    /// impact (or per contact, if there are fewer contacts).
    pub cache_capacity: usize,
    /// Solve each new heat-method distance field on two threads where that pays (see
    /// [`crate::attenuation::HeatWorkspace::set_parallel`]): bit-identical results, faster on
    /// large surfaces when a second core is free (timings in `docs/benchmarks.md`). Off by default.
    pub parallel_heat: bool,
}

impl Default for AttenuationParams {
    /// Simplified law C = 1, β = 1 (volumes), heat distances, per-vertex amplitude, 64 fields,
    /// serial solves.
    fn default() -> Self {
        AttenuationParams {
            law: AttenuationLaw::Simplified { c: 1.0, beta: 1.0 },
            distance: DistanceKind::Heat,
            amplitude: AmplitudeKind::PerVertex,
            cache_capacity: 64,
            parallel_heat: false,
        }
    }
}
