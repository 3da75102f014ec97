//! Size before work: the tetrahedra, degrees of freedom, wall time and peak memory a mesh
//! and a bake will take, estimated from the surface asset (before gmsh runs) or from the
//! tetrahedral mesh (before assembly), and compared with a [`Budget`].
//!
//! The model (n_tri the asset's triangles, V its volume, A its area, h the element size):
//! - boundary triangles of the tetrahedral mesh F = A / (√3/4 h²) (equilateral triangles of
//!   edge h); with `keep_surface` F = n_tri, and h is the smaller of the size and the asset's
//!   mean edge a = √(4A / (√3 n_tri)) (gmsh grows the volume size from the boundary's).
//! - tetrahedra T = c_V V/h³ + c_F F: the volume term dominates compact objects, the boundary
//!   term thin ones (a 2 mm wall meshed at 6 mm is all boundary layer).
//! - nodes N = a_o T + b_o F per element order o (order 2 adds a mid-edge node per edge);
//!   degrees of freedom n = 3N (exact when the tetrahedral mesh is known).
//! - gmsh: CPU time t₀ + k_tri n_tri (classifying and rebuilding the surface; 0 with
//!   `keep_surface`) + k_tet T, peak memory B₀ + β_tri n_tri + β_tet T.
//! - bake: CPU time k_o (n/10⁴)^p · (1 + m/26)/2 (the factorization and block Lanczos of
//!   m = 20 + 6 modes as calibrated; the Lanczos half assumed linear in m), peak memory
//!   B_o + b_o n^(4/3) + 24 n · max(0, m − 26) bytes (the sparse factor's fill grows as
//!   n^(4/3) for 3-D meshes under nested dissection; each further mode adds Lanczos vectors).
//!   At order 2, b₂ runs linearly from 170 bytes for a thin-walled mesh (r = T/F ≤ 1.6
//!   tetrahedra per boundary triangle: all boundary layer, whose separators are those of a
//!   surface) to 300 bytes for a compact one (r ≥ 6).
//!
//! Calibration: the coefficients are least-squares fits (relative residuals; log space for the
//! power law) to nine `modal-bake mesh` + `bake` runs under `/usr/bin/time` — gmsh's tutorial
//! STL (1,580 triangles, a thin-walled part) at three sizes and a 0.1 m box at four, both
//! orders, 20 modes — plus the tutorial STL refined to 50,864 triangles for k_tri and β_tri
//! (`scripts/calibrate_estimate.sh`, figures in docs/benchmarks.md § Size estimates); b₂'s
//! two ends from the box's order-2 bakes (r 6–8: 295–328 bytes) and four order-2 bakes of the
//! tutorial part with thickness-aware sizing, 0.9–3.0·10⁵ dofs (r 1.5–1.7: 156–185 bytes;
//! docs/benchmarks.md § Size estimates). Times
//! are CPU seconds (user + system), which is the wall time of an otherwise idle machine; the
//! machine was loaded when they were measured, so its wall times were longer. How close the
//! estimates came over those runs is in the same section. The estimate aims at the order of
//! magnitude a budget needs; it is not a benchmark.

/// Estimated size and cost of meshing and baking one object.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct SizeEstimate {
    /// Tetrahedra.
    pub tets: f64,
    /// Element order (1 or 2).
    pub order: u8,
    /// Nodes (corner nodes, plus mid-edge nodes at order 2).
    pub nodes: f64,
    /// Degrees of freedom (3 per node).
    pub dofs: f64,
    /// Boundary triangles of the tetrahedral mesh (0 when unknown: taken as compact).
    pub boundary: f64,
    /// Modes requested (elastic, plus six rigid ones free-free).
    pub modes: usize,
    /// Wall time of gmsh (s); 0 for a mesh already tetrahedral.
    pub mesh_s: f64,
    /// Peak memory of gmsh (bytes); 0 for a mesh already tetrahedral.
    pub mesh_bytes: f64,
    /// Wall time of the bake (assembly, factorization, eigensolve) (s).
    pub bake_s: f64,
    /// Peak memory of the bake (bytes).
    pub bake_bytes: f64,
    /// Wall time of solving a transfer table's modes (s): the dense all-mode eigensolve or a
    /// Lanczos bake with the table's modes; 0 without a table, or when the base's own modes
    /// suffice. The table's own build is estimated once its modes are known
    /// ([`TablePlan`](crate::transfer::TablePlan)): its sampling depends on its highest mode.
    pub table_modes_s: f64,
    /// Peak memory of solving a transfer table's modes (bytes); 0 as `table_modes_s`.
    pub table_modes_bytes: f64,
    /// The counts (tetrahedra, nodes, dofs) are a tetrahedral mesh's own, not estimated from a
    /// surface ([`SizeEstimate::of_mesh`]); the times and memory are estimates either way.
    pub counted: bool,
}

/// The work a bake may take before it is refused (unless forced).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Budget {
    /// Largest peak memory (bytes). Default 2 GB (2e9).
    pub max_bytes: f64,
    /// Longest wall time of meshing plus baking (s). Default 300 (5 minutes).
    pub max_seconds: f64,
}

impl Budget {
    /// A budget of `max_gb` GB (1e9 bytes) and `max_seconds` s; `names`: how the two limits are
    /// given (command-line options), for the error.
    ///
    /// # Errors
    /// A limit that is not a positive finite number, naming it.
    pub fn from_gb(max_gb: f64, max_seconds: f64, names: [&str; 2]) -> Result<Budget, String> {
        for (name, v) in names.into_iter().zip([max_gb, max_seconds]) {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} {v} must be a positive number"));
            }
        }
        Ok(Budget {
            max_bytes: max_gb * 1e9,
            max_seconds,
        })
    }
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            max_bytes: 2e9,
            max_seconds: 300.0,
        }
    }
}

/// How many times the model's tetrahedra fTetWild makes at the same `--size`: the geometric
/// mean over the three real assets it meshes at the defaults (Suzanne, the teapot, the dragon:
/// 3.1, 1.9 and 2.9 times; docs/artist-guide.md § 7).
pub const FTETWILD_ELEMENTS: f64 = 2.5;

/// fTetWild's wall time per tetrahedron it makes (s): `modal-bake mesh` on six real assets at
/// load ≈ 1 took 0.58–1.25 ms per output tetrahedron (the teapot, the dragon, Suzanne and three
/// XR controllers, docs/benchmarks.md § Meshing real assets and § glTF assets as shipped);
/// gmsh's per-tetrahedron time is 30 times less.
pub const FTETWILD_S_PER_TET: f64 = 1.0e-3;

/// The fewest tetrahedra a mesher has made against this estimate's count, as a fraction of it
/// (gmsh, fTetWild): gmsh's meshes of the real and generated assets of docs/artist-guide.md § 7
/// came within 1/1.3 of the estimate from below but for a slender rod (1/2.49, its curvature
/// overrated); fTetWild's seven real assets within 1/1.6 (Suzanne, the teapot, the dragon and
/// four XR controllers: 0.65–1.56 times the estimate). A surface whose estimate is over the
/// budget but would fit at this fraction is meshed first and its bake decided on the mesh's
/// exact counts: the cost of being wrong is the meshing, itself held to the budget.
pub const FEWEST_ELEMENTS: [f64; 2] = [1.0 / 2.5, 1.0 / 1.6];

/// Tetrahedra per V/h³ (c_V) and per boundary triangle (c_F).
const TETS_PER_VOLUME: f64 = 3.6;
const TETS_PER_BOUNDARY_TRI: f64 = 1.7;
/// Nodes per tetrahedron and per boundary triangle, order 1 and 2 (a_o, b_o).
const NODES: [(f64, f64); 2] = [(0.147, 0.39), (1.256, 1.57)];
/// gmsh start-up (s), seconds per surface triangle rebuilt and per tetrahedron.
const MESH_T0: f64 = 0.8;
const MESH_S_PER_TRI: f64 = 7e-5;
const MESH_S_PER_TET: f64 = 3.6e-5;
/// gmsh peak memory: base, per asset triangle and per tetrahedron (bytes).
const MESH_B0: f64 = 74e6;
const MESH_B_PER_TRI: f64 = 1.1e3;
const MESH_B_PER_TET: f64 = 425.0;
/// Bake CPU time: seconds at 10⁴ free dofs per order, and the exponent.
const BAKE_T: [f64; 2] = [0.30, 0.27];
const BAKE_T_EXP: f64 = 1.64;
/// Bake memory per order: base (bytes) and factor bytes per n^(4/3) (order 2: of a compact
/// mesh, [`R_SOLID`] or more tetrahedra per boundary triangle).
const BAKE_B0: [f64; 2] = [17e6, 85e6];
const BAKE_B_FILL: [f64; 2] = [330.0, 300.0];
/// Order 2: factor bytes per n^(4/3) of a thin-walled mesh, [`R_THIN`] or fewer tetrahedra
/// per boundary triangle (its separators are those of a surface: less fill).
const BAKE_B_FILL_THIN: f64 = 170.0;
const R_THIN: f64 = 1.6;
const R_SOLID: f64 = 6.0;
/// Modes (20 elastic + 6 rigid) the bake coefficients were measured at.
const CALIBRATED_MODES: f64 = 26.0;
/// The dense all-mode eigensolve of n free dofs (a transfer table's modes on a small mesh):
/// CPU seconds per n³ and peak bytes per n² (dense K and M, the Cholesky factor, the reduced
/// matrix, its eigenvectors and the workspace; the dinner table's 2,988 free dofs peaked at
/// 628 MB, the npm bunny's 4,785 took 36 s of CPU).
const DENSE_S_PER_N3: f64 = 3.3e-10;
const DENSE_B_PER_N2: f64 = 70.0;

/// A surface asset's measures that the estimate needs (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceMeasures {
    /// Enclosed volume V (m³).
    pub volume_m3: f64,
    /// Surface area A (m²).
    pub area_m2: f64,
    /// Triangles of the asset.
    pub triangles: usize,
    /// Bounding-box diagonal (m).
    pub extent_m: f64,
}

impl SurfaceMeasures {
    /// The measures of a triangle surface (m): |signed volume| by the divergence theorem, area,
    /// triangle count and bounding-box diagonal.
    pub fn of(vertices: &[[f64; 3]], triangles: &[[usize; 3]]) -> SurfaceMeasures {
        let (mut vol, mut area) = (0.0, 0.0);
        for t in triangles {
            let [a, b, c] = t.map(|i| vertices[i]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            area += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent = if vertices.is_empty() {
            0.0
        } else {
            (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
        };
        SurfaceMeasures {
            volume_m3: vol.abs(),
            area_m2: area,
            triangles: triangles.len(),
            extent_m: extent,
        }
    }

    /// Mean edge length of the asset's triangles (m), taking them as equilateral:
    /// a = √(4A / (√3 n)).
    pub fn mean_edge(&self) -> f64 {
        (4.0 * self.area_m2 / (3f64.sqrt() * self.triangles.max(1) as f64)).sqrt()
    }
}

impl SizeEstimate {
    /// The estimate for meshing a surface with element size `size` (m) at `order`, keeping its
    /// triangles as the boundary when `keep_surface`, then baking `modes` modes (count the six
    /// rigid-body modes of a free-free object in it).
    ///
    /// ```
    /// use modal_bake::bake::{SizeEstimate, SurfaceMeasures};
    /// // A 0.1 m cube at 1 cm: 3.6 × 1000 + 1.7 × 1386 ≈ 6000 tetrahedra (gmsh: 5198).
    /// let cube = SurfaceMeasures { volume_m3: 1e-3, area_m2: 0.06, triangles: 12, extent_m: 0.173 };
    /// let e = SizeEstimate::of_surface(&cube, 0.01, false, 2, 26);
    /// assert!(e.tets > 5e3 && e.tets < 2e4);
    /// assert!(e.dofs > 3.0 * e.tets);
    /// ```
    pub fn of_surface(
        s: &SurfaceMeasures,
        size: f64,
        keep_surface: bool,
        order: u8,
        modes: usize,
    ) -> SizeEstimate {
        let (h, boundary) = if keep_surface {
            (size.min(s.mean_edge()), s.triangles as f64)
        } else {
            (size, s.area_m2 / (3f64.sqrt() / 4.0 * size * size))
        };
        let tets =
            (TETS_PER_VOLUME * s.volume_m3 / h.powi(3) + TETS_PER_BOUNDARY_TRI * boundary).max(1.0);
        let (a, b) = NODES[usize::from(order == 2)];
        let nodes = a * tets + b * boundary;
        let rebuilt = if keep_surface {
            0.0
        } else {
            s.triangles as f64
        };
        let mut e = SizeEstimate {
            tets,
            order,
            nodes,
            dofs: 3.0 * nodes,
            boundary,
            modes,
            mesh_s: MESH_T0 + MESH_S_PER_TRI * rebuilt + MESH_S_PER_TET * tets,
            mesh_bytes: MESH_B0 + MESH_B_PER_TRI * s.triangles as f64 + MESH_B_PER_TET * tets,
            ..Default::default()
        };
        e.bake();
        e
    }

    /// The same estimate for fTetWild, which fills a surface with about
    /// [`FTETWILD_ELEMENTS`] times what gmsh makes at the same `--size` (its edge length is an
    /// ideal, refined near the envelope), in about [`FTETWILD_S_PER_TET`] per tetrahedron.
    pub fn for_ftetwild(self) -> SizeEstimate {
        let k = FTETWILD_ELEMENTS;
        let mut e = self.with_elements(k);
        e.mesh_s = MESH_T0 + FTETWILD_S_PER_TET * e.tets;
        e.mesh_bytes += MESH_B_PER_TET * (k - 1.0) * self.tets;
        e
    }

    /// The same estimate with `k` times the tetrahedra, nodes and degrees of freedom (the
    /// bake's time and memory follow; meshing's are kept). A transfer table's mode set is
    /// not rescaled: apply [`SizeEstimate::with_table_modes`] after.
    pub fn with_elements(mut self, k: f64) -> SizeEstimate {
        let k = if k.is_finite() && k > 0.0 { k } else { 1.0 };
        self.tets *= k;
        self.nodes *= k;
        self.dofs *= k;
        self.boundary *= k;
        self.bake();
        self
    }

    /// The estimate for baking `modes` modes of a tetrahedral mesh with `nodes` nodes (mid-edge
    /// nodes included at order 2), `tets` tetrahedra and `boundary` boundary triangles (0 when
    /// unknown).
    pub fn of_mesh(
        nodes: usize,
        tets: usize,
        boundary: usize,
        order: u8,
        modes: usize,
    ) -> SizeEstimate {
        let mut e = SizeEstimate {
            tets: tets as f64,
            order,
            nodes: nodes as f64,
            dofs: 3.0 * nodes as f64,
            boundary: boundary as f64,
            modes,
            counted: true,
            ..Default::default()
        };
        e.bake();
        e
    }

    /// With a transfer table's mode set, for a mesh of `free_dofs` free degrees of freedom:
    /// `modes` resolved as the bake resolves them (`Auto`: every mode up to
    /// [`DENSE_MAX_DOFS`](crate::transfer::DENSE_MAX_DOFS) free dofs, else
    /// [`AUTO_LANCZOS_MODES`](crate::transfer::AUTO_LANCZOS_MODES)); nothing when the base's
    /// own `self.modes` suffice, the dense eigensolve up to `DENSE_MAX_DOFS` free dofs, else a
    /// Lanczos bake of that many modes.
    pub fn with_table_modes(
        mut self,
        modes: crate::transfer::TransferModes,
        free_dofs: usize,
    ) -> SizeEstimate {
        use crate::transfer::{TransferModes, DENSE_MAX_DOFS};
        self.table_modes_s = 0.0;
        self.table_modes_bytes = 0.0;
        match modes.resolve(free_dofs) {
            TransferModes::Count(k) if k <= self.modes => {}
            TransferModes::Count(k) if free_dofs > DENSE_MAX_DOFS => {
                let mut lanczos = SizeEstimate { modes: k, ..self };
                lanczos.bake();
                self.table_modes_s = lanczos.bake_s;
                self.table_modes_bytes = lanczos.bake_bytes;
            }
            _ => {
                let n = free_dofs as f64;
                self.table_modes_s = DENSE_S_PER_N3 * n.powi(3);
                self.table_modes_bytes = DENSE_B_PER_N2 * n * n;
            }
        }
        self
    }

    /// The estimate for baking the tetrahedral `mesh` with `params`: its modes (a count, plus
    /// six — the rigid-body modes of a free-free object; 20 for a frequency limit, as the CLI
    /// counts) and, when `params.transfer` asks for a table, the table's mode set
    /// ([`SizeEstimate::with_table_modes`], over the dofs its fixed-node selectors leave free;
    /// all of them when the selectors do not resolve — the bake then says why).
    pub fn of_bake(mesh: &crate::mesh::TetMesh, params: &super::BakeParams) -> SizeEstimate {
        let order = if mesh.is_quadratic() { 2 } else { 1 };
        let boundary = crate::mesh::extract_surface(mesh).1.len();
        let modes = match params.modes {
            super::ModeRequest::Count(n) => n,
            super::ModeRequest::MaxFreqHz(_) => 20,
        } + 6;
        let e = SizeEstimate::of_mesh(mesh.nodes.len(), mesh.tets.len(), boundary, order, modes);
        match &params.transfer {
            Some(t) => {
                let fixed = params
                    .fixed_selectors()
                    .resolve(mesh, "")
                    .map_or(0, |f| f.nodes.len());
                e.with_table_modes(t.modes, 3 * mesh.nodes.len().saturating_sub(fixed))
            }
            None => e,
        }
    }

    /// The factor's bytes per n^(4/3) (b_o in the module doc): at order 2 from 170 (thin-walled,
    /// T/F ≤ 1.6) to 300 (compact, T/F ≥ 6, or the boundary unknown).
    fn fill_per_n43(&self) -> f64 {
        if self.order != 2 {
            return BAKE_B_FILL[0];
        }
        if !(self.boundary > 0.0) {
            return BAKE_B_FILL[1];
        }
        let r = self.tets / self.boundary;
        let w = ((r - R_THIN) / (R_SOLID - R_THIN)).clamp(0.0, 1.0);
        BAKE_B_FILL_THIN + (BAKE_B_FILL[1] - BAKE_B_FILL_THIN) * w
    }

    /// Fills in the bake's time and memory from the dofs, order and modes.
    fn bake(&mut self) {
        let o = usize::from(self.order == 2);
        let n = self.dofs;
        let m = self.modes as f64;
        self.bake_s = BAKE_T[o] * (n / 1e4).powf(BAKE_T_EXP) * (1.0 + m / CALIBRATED_MODES) / 2.0;
        self.bake_bytes = BAKE_B0[o]
            + self.fill_per_n43() * n.powf(4.0 / 3.0)
            + 24.0 * n * (m - CALIBRATED_MODES).max(0.0);
    }

    /// Total wall time (s): meshing, baking and a transfer table's modes.
    pub fn total_s(&self) -> f64 {
        self.mesh_s + self.bake_s + self.table_modes_s
    }

    /// Peak memory (bytes): the largest of meshing's, baking's and a transfer table's modes'.
    pub fn peak_bytes(&self) -> f64 {
        self.mesh_bytes
            .max(self.bake_bytes)
            .max(self.table_modes_bytes)
    }

    /// Whether the estimate (meshing and baking) is within `budget`.
    pub fn fits(&self, budget: &Budget) -> bool {
        self.peak_bytes() <= budget.max_bytes && self.total_s() <= budget.max_seconds
    }

    /// One line: `~12,300 tetrahedra (order 2), ~3,100 nodes, ~9,300 dofs; baking about 14 s and
    /// 0.5 GB` (counts without `~` when [`SizeEstimate::counted`]).
    pub fn describe(&self) -> String {
        let count = |x: f64| {
            if self.counted {
                group_digits(x as usize)
            } else {
                format!("~{}", format_count(x))
            }
        };
        let mut s = format!(
            "{} tetrahedra (order {}), {} nodes, {} dofs; ",
            count(self.tets),
            self.order,
            count(self.nodes),
            count(self.dofs)
        );
        if self.mesh_s > 0.0 {
            s.push_str(&format!(
                "meshing about {} and {}, ",
                format_seconds(self.mesh_s),
                format_bytes(self.mesh_bytes)
            ));
        }
        s.push_str(&format!(
            "baking about {} and {}",
            format_seconds(self.bake_s),
            format_bytes(self.bake_bytes)
        ));
        if self.table_modes_s > 0.0 {
            s.push_str(&format!(
                ", the transfer table's modes about {} and {}",
                format_seconds(self.table_modes_s),
                format_bytes(self.table_modes_bytes)
            ));
        }
        s
    }
}

/// `12,300` (three significant digits, thousands separated).
pub fn format_count(x: f64) -> String {
    if !(x.is_finite()) {
        return format!("{x}");
    }
    let x = x.max(0.0);
    let mag = if x >= 1.0 { x.log10().floor() } else { 0.0 };
    let unit = 10f64.powf((mag - 2.0).max(0.0));
    group_digits(((x / unit).round() * unit) as usize)
}

/// `5742` → `5,742` (exact, digits grouped by thousands).
pub fn group_digits(n: usize) -> String {
    let d = n.to_string();
    let mut out = String::with_capacity(d.len() + d.len() / 3);
    for (i, c) in d.chars().enumerate() {
        if i > 0 && (d.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `0.05 s`, `1.5 s`, `14 s`, `3.2 min`, `2.1 h`: two significant digits under 10 s, so a
/// sub-second budget does not print as `0 s`.
pub fn format_seconds(s: f64) -> String {
    if s > 0.0 && s < 10.0 {
        format!("{s:.*} s", significant_decimals(s))
    } else if s < 90.0 {
        format!("{s:.0} s")
    } else if s < 5400.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// `512 B`, `40 kB`, `120 MB`, `2.4 GB`.
pub fn format_bytes(b: f64) -> String {
    if b < 1e3 {
        format!("{b:.0} B")
    } else if b < 1e6 {
        format!("{:.0} kB", b / 1e3)
    } else if b < 1e9 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.1} GB", b / 1e9)
    }
}

/// Decimals that print `x` (> 0, < 10) with two significant digits, at most six.
fn significant_decimals(x: f64) -> usize {
    (1.0 - x.log10().floor()).clamp(0.0, 6.0) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    // fTetWild's estimate: 2.5 times the elements and dofs, its meshing time per output
    // tetrahedron; `with_elements` scales the counts and the bake, not meshing.
    #[test]
    fn ftetwild_and_fewer_elements_scale_the_counts_and_the_bake() {
        let m = SurfaceMeasures {
            volume_m3: 1e-3,
            area_m2: 6e-2,
            triangles: 12,
            extent_m: 0.173,
        };
        let g = SizeEstimate::of_surface(&m, 0.006, false, 2, 26);
        let f = g.for_ftetwild();
        assert!((f.tets / g.tets - FTETWILD_ELEMENTS).abs() < 1e-12);
        assert!((f.dofs / g.dofs - FTETWILD_ELEMENTS).abs() < 1e-12);
        assert!((f.mesh_s - (MESH_T0 + FTETWILD_S_PER_TET * f.tets)).abs() < 1e-9);
        assert!(f.bake_s > g.bake_s && f.bake_bytes > g.bake_bytes);
        let low = g.with_elements(FEWEST_ELEMENTS[0]);
        assert_eq!((low.mesh_s, low.mesh_bytes), (g.mesh_s, g.mesh_bytes));
        assert!((low.dofs / g.dofs - FEWEST_ELEMENTS[0]).abs() < 1e-12);
        assert!(low.bake_bytes < g.bake_bytes && low.bake_s < g.bake_s);
    }

    // Limits below a unit print with their digits, not as zero.
    #[test]
    fn small_seconds_and_bytes_keep_their_digits() {
        let secs = [
            (0.05, "0.050 s"),
            (0.5, "0.50 s"),
            (1.5, "1.5 s"),
            (14.0, "14 s"),
        ];
        for (s, text) in secs {
            assert_eq!(format_seconds(s), text);
        }
        assert_eq!(format_seconds(0.0), "0 s");
        assert_eq!(format_seconds(300.0), "5.0 min");
        assert_eq!(format_seconds(7200.0), "2.0 h");
        assert_eq!(format_bytes(512.0), "512 B");
        assert_eq!(format_bytes(4.0e4), "40 kB");
        assert_eq!(format_bytes(1.2e8), "120 MB");
        assert_eq!(format_bytes(2.4e9), "2.4 GB");
    }

    // A budget's limits are positive and finite; the refusal names the limit as it was given.
    #[test]
    fn a_budget_refuses_non_positive_limits_by_name() {
        let names = ["--max-memory", "--max-time"];
        let b = Budget::from_gb(2.0, 300.0, names).unwrap();
        assert_eq!(b, Budget::default());
        for (gb, s, bad) in [
            (0.0, 300.0, "--max-memory 0"),
            (f64::NAN, 300.0, "--max-memory NaN"),
            (2.0, -1.0, "--max-time -1"),
            (2.0, f64::INFINITY, "--max-time inf"),
        ] {
            let e = Budget::from_gb(gb, s, names).unwrap_err();
            assert!(e.starts_with(bad), "{e}");
        }
    }

    // Halving the size multiplies the tetrahedra by 8 and raises every cost; order 2 has more
    // dofs than order 1 on the same tetrahedra; keeping a fine surface refines the estimate.
    #[test]
    fn estimate_grows_with_refinement_and_order() {
        let s = SurfaceMeasures {
            volume_m3: 1e-3,
            area_m2: 0.06,
            triangles: 12,
            extent_m: 0.173,
        };
        let a = SizeEstimate::of_surface(&s, 0.02, false, 1, 20);
        let b = SizeEstimate::of_surface(&s, 0.01, false, 1, 20);
        // Between 4× (all boundary) and 8× (all volume).
        assert!(b.tets / a.tets > 4.0 && b.tets / a.tets < 8.0);
        assert!(b.dofs > a.dofs && b.bake_s > a.bake_s && b.bake_bytes > a.bake_bytes);
        let b2 = SizeEstimate::of_surface(&s, 0.01, false, 2, 20);
        assert!(b2.dofs > 5.0 * b.dofs && b2.bake_s > b.bake_s);
        let fine = SurfaceMeasures {
            triangles: 400_000,
            ..s
        };
        let kept = SizeEstimate::of_surface(&fine, 0.01, true, 2, 20);
        assert!(kept.tets > 100.0 * b2.tets, "{kept:?}");
        assert!(!kept.fits(&Budget::default()));
        assert!(b.fits(&Budget::default()));
    }

    // The measures of a unit cube's surface: volume 1, area 6, mean edge of 12 equal-area
    // right triangles.
    #[test]
    fn measures_of_a_cube() {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let m = SurfaceMeasures::of(&v, &t);
        assert!((m.volume_m3 - 1.0).abs() < 1e-12);
        assert!((m.area_m2 - 6.0).abs() < 1e-12);
        assert!((m.extent_m - 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(format_count(12345.0), "12,300");
        assert_eq!(format_count(999.4), "999");
    }
}
