//! A rapier FEM soft body from a tetrahedral mesh: the baker's mesh, material, fixed nodes and
//! Rayleigh damping carried over to `rapier3d_f64::dynamics::SoftBodyBuilder`.

use anyhow::{bail, Context, Result};
use dcr_runtime::math::{cross, dot, sub};
use modal_bake::mesh::TetMesh;
use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::prelude::*;

/// What a tetrahedral elastic object becomes in rapier's FEM solver.
///
/// Defaults: rapier's contact skin cut to 0.1 mm (see [`TetSoftBodyDesc::particle_radius`]),
/// no sleeping (a stiff body at rest must keep answering contacts), friction 0.6 and
/// restitution 0.15 (the scene defaults).
#[derive(Clone, Debug)]
pub struct TetSoftBodyDesc {
    /// Young's modulus (Pa).
    pub youngs: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Density (kg/m³); each tetrahedron gives a quarter of its mass ρV to each corner
    /// (lumped mass, the same total as the baker's consistent mass).
    pub density: f64,
    /// Rayleigh damping `C = α0 M + α1 K` (α0 in 1/s, α1 in s), as the base is baked with.
    /// α0 becomes the particles' linear damping (rapier applies `v ← v / (1 + h α0)` each step,
    /// an implicit `−α0 M v`); α1 becomes the elastic damping ratio ζ whose per-cell
    /// coefficient `β = 2ζ / ω̄_cell` equals α1 at the median cell (rapier's FEM damps each cell
    /// with `β K_cell`, β from ζ and the cell's mean strain-mode frequency ω̄).
    pub rayleigh: [f64; 2],
    /// Names of the mesh's node groups whose nodes are pinned (the baker's `fixed`).
    pub fixed: Vec<String>,
    /// Pin every node whose coordinate `axis` is ≤ `value` (m, mesh frame; the baker's
    /// `fixed_below`). Default none.
    pub fixed_below: Vec<modal_bake::bake::FixedBelow>,
    /// Pin every node inside a box `[x0, y0, z0, x1, y1, z1]` (m, mesh frame, bounds included;
    /// the baker's `fixed_boxes`). Default none.
    pub fixed_boxes: Vec<[f64; 6]>,
    /// Pose of the mesh frame in the world.
    pub pose: Pose,
    /// The contact skin of the body's surface collider (m). rapier's default (1 cm) would hold
    /// bodies resting on the mesh's surface 1 cm above it; 0.1 mm keeps the scene's contact
    /// geometry within a tenth of a millimetre of the rigid proxies'.
    pub particle_radius: f64,
    /// Friction coefficient of the surface collider.
    pub friction: f64,
    /// Restitution of the surface collider.
    pub restitution: f64,
}

impl Default for TetSoftBodyDesc {
    fn default() -> Self {
        TetSoftBodyDesc {
            youngs: 1.0e9,
            poisson: 0.3,
            density: 1000.0,
            rayleigh: [10.0, 1e-7],
            fixed: Vec::new(),
            fixed_below: Vec::new(),
            fixed_boxes: Vec::new(),
            pose: Pose::IDENTITY,
            particle_radius: 1.0e-4,
            friction: 0.6,
            restitution: 0.15,
        }
    }
}

/// The soft body built from a mesh, with what it needs to read it back.
#[derive(Clone, Debug)]
pub struct TetSoftBody {
    /// The builder, ready for `PhysicsWorld::insert_soft_body`.
    pub builder: SoftBodyBuilder,
    /// Mesh node index of each particle (corner nodes only: a second-order mesh's mid-edge
    /// nodes are not particles).
    pub particle_node: Vec<usize>,
    /// The pinned particles (sorted).
    pub pinned: Vec<u32>,
    /// Total mass (kg), Σ ρV over the tetrahedra.
    pub mass: f64,
    /// The elastic damping ratio ζ given to rapier (see [`TetSoftBodyDesc::rayleigh`]).
    pub damping_ratio: f64,
    /// The per-cell stiffness-damping coefficient β = 2ζ/ω̄ rapier derives from it (s):
    /// smallest, median and largest over the cells.
    pub beta_range: [f64; 3],
}

/// The inverse of the 3×3 matrix with columns `c` (None when singular), as rows.
fn inverse_cols(c: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let [a, b, d] = c;
    // Rows of the inverse are the cross products of the other two columns over the determinant.
    let r0 = cross(b, d);
    let det = dot(a, r0);
    if det.abs() < f64::MIN_POSITIVE {
        return None;
    }
    let r1 = cross(d, a);
    let r2 = cross(a, b);
    Some([r0, r1, r2].map(|r| r.map(|x| x / det)))
}

/// The mean natural frequency ω̄ (rad/s) of a cell's strain modes as rapier's FEM solver
/// computes it for its damping coefficient: strain row r has stiffness `k_r V` (`2μ + λ` on the
/// normal rows, `4μ` on the shear rows) over the effective inverse mass `Σ_p w_p |g_r[p]|²`,
/// `g_r[p]` the gradient of strain row r with respect to particle p's velocity (`w_p` its inverse
/// mass, 0 when pinned). `None` for a degenerate or fully pinned cell.
fn cell_mean_omega(x: [[f64; 3]; 4], w: [f64; 4], mu: f64, lambda: f64) -> Option<f64> {
    let cols = [sub(x[1], x[0]), sub(x[2], x[0]), sub(x[3], x[0])];
    let volume = (cols[0][0] * (cols[1][1] * cols[2][2] - cols[1][2] * cols[2][1])
        - cols[0][1] * (cols[1][0] * cols[2][2] - cols[1][2] * cols[2][0])
        + cols[0][2] * (cols[1][0] * cols[2][1] - cols[1][1] * cols[2][0]))
        .abs()
        / 6.0;
    let inv = inverse_cols(cols)?;
    // Shape-function gradients: corner a+1 gets row a of the inverse, corner 0 minus their sum.
    let mut c = [[0.0; 3]; 4];
    for a in 0..3 {
        c[a + 1] = inv[a];
        for k in 0..3 {
            c[0][k] -= inv[a][k];
        }
    }
    const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
    let (mut sum, mut count) = (0.0, 0);
    for (r, &(a, b)) in PAIRS.iter().enumerate() {
        let block: f64 = (0..4)
            .map(|p| {
                let g2 = if a == b {
                    c[p][a] * c[p][a]
                } else {
                    0.25 * (c[p][b] * c[p][b] + c[p][a] * c[p][a])
                };
                w[p] * g2
            })
            .sum();
        let k = if r < 3 { 2.0 * mu + lambda } else { 4.0 * mu } * volume;
        let omega = (k * block).sqrt();
        if omega > 0.0 {
            sum += omega;
            count += 1;
        }
    }
    if count > 0 {
        Some(sum / count as f64)
    } else {
        None
    }
}

/// Builds the rapier FEM soft body of `mesh` (object frame) placed at `desc.pose`:
/// corner nodes as particles with lumped masses, the tetrahedra as corotational cells
/// (`SoftBodyCellModel::Corotational`, linear elasticity in each cell's rotation-free frame,
/// which is linear elasticity at the small strains of these scenes) solved by
/// `SoftBodySolver::Fem`, the nodes of `desc.fixed` pinned, the cells' boundary as its
/// collision surface.
///
/// # Errors
/// An unknown fixed group (the message lists the mesh's groups), a selector that fixes no
/// node or fixed nodes none of which is a tetrahedron's corner, non-positive material
/// constants, or a mesh without tetrahedra.
///
/// ```
/// use dcr_lab::soft_body::{tet_soft_body, TetSoftBodyDesc};
/// use modal_bake::mesh::TetMesh;
/// let mesh = TetMesh::structured_box([4, 1, 1], [1.0, 0.25, 0.25]);
/// let desc = TetSoftBodyDesc { fixed: vec!["xmin".into()], density: 500.0, ..Default::default() };
/// let body = tet_soft_body(&mesh, &desc).unwrap();
/// assert_eq!(body.particle_node.len(), mesh.nodes.len());
/// assert_eq!(body.pinned.len(), 4); // the 2 × 2 nodes at x = 0
/// assert!((body.mass - 500.0 * 0.0625).abs() < 1e-9);
/// let mut world = rapier3d_f64::prelude::PhysicsWorld::new();
/// world.insert_soft_body(body.builder);
/// world.step();
/// ```
pub fn tet_soft_body(mesh: &TetMesh, desc: &TetSoftBodyDesc) -> Result<TetSoftBody> {
    if mesh.tets.is_empty() {
        bail!("the mesh has no tetrahedra");
    }
    if !(desc.youngs > 0.0 && desc.density > 0.0 && (0.0..0.5).contains(&desc.poisson)) {
        bail!(
            "material: need E > 0, ρ > 0 and 0 ≤ ν < 0.5 (got E = {}, ν = {}, ρ = {})",
            desc.youngs,
            desc.poisson,
            desc.density
        );
    }
    // Corner nodes only, in mesh order.
    let mut particle_of = vec![u32::MAX; mesh.nodes.len()];
    let mut particle_node = Vec::new();
    for t in &mesh.tets {
        for &n in t {
            if particle_of[n] == u32::MAX {
                particle_of[n] = 0;
            }
        }
    }
    for (n, p) in particle_of.iter_mut().enumerate() {
        if *p != u32::MAX {
            *p = particle_node.len() as u32;
            particle_node.push(n);
        }
    }
    let cells: Vec<[u32; 4]> = mesh
        .tets
        .iter()
        .map(|t| t.map(|n| particle_of[n]))
        .collect();
    let mut masses = vec![0.0; particle_node.len()];
    let mut mass = 0.0;
    for t in &mesh.tets {
        let [a, b, c, d] = t.map(|n| mesh.nodes[n]);
        let m = desc.density * modal_bake::mesh::signed_volume(a, b, c, d).abs();
        mass += m;
        for &n in t {
            masses[particle_of[n] as usize] += m / 4.0;
        }
    }
    let selectors = modal_bake::bake::FixedSelectors {
        groups: &desc.fixed,
        below: &desc.fixed_below,
        boxes: &desc.fixed_boxes,
        near: &[],
    };
    let fixed = selectors
        .resolve(mesh, "the mesh")
        .map_err(|e| anyhow::anyhow!("fixed nodes: {e}"))?;
    let mut pinned: Vec<u32> = fixed
        .nodes
        .iter()
        .map(|&n| particle_of[n])
        .filter(|&p| p != u32::MAX)
        .collect();
    if !selectors.is_empty() && pinned.is_empty() {
        bail!(
            "fixed nodes ({}): none is a corner node of a tetrahedron",
            fixed
                .by
                .iter()
                .map(|(w, _)| w.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    pinned.sort_unstable();
    pinned.dedup();

    // ζ from α1 at the median cell (see `TetSoftBodyDesc::rayleigh`).
    let mu = desc.youngs / (2.0 * (1.0 + desc.poisson));
    let lambda = desc.youngs * desc.poisson / ((1.0 + desc.poisson) * (1.0 - 2.0 * desc.poisson));
    let mut is_pinned = vec![false; particle_node.len()];
    for &p in &pinned {
        is_pinned[p as usize] = true;
    }
    let mut omegas: Vec<f64> = cells
        .iter()
        .filter_map(|c| {
            let x = c.map(|p| mesh.nodes[particle_node[p as usize]]);
            let w = c.map(|p| {
                if is_pinned[p as usize] {
                    0.0
                } else {
                    1.0 / masses[p as usize]
                }
            });
            cell_mean_omega(x, w, mu, lambda)
        })
        .collect();
    if omegas.is_empty() {
        bail!("every tetrahedron is degenerate or fully pinned");
    }
    omegas.sort_by(f64::total_cmp);
    let median = omegas[omegas.len() / 2];
    let damping_ratio = desc.rayleigh[1].max(0.0) * median / 2.0;
    let beta = |omega: f64| 2.0 * damping_ratio / omega;
    let beta_range = [
        beta(omegas[omegas.len() - 1]),
        beta(median),
        beta(omegas[0]),
    ];

    let positions: Vec<Vector> = particle_node
        .iter()
        .map(|&n| {
            let p = mesh.nodes[n];
            desc.pose.transform_point(Vector::new(p[0], p[1], p[2]))
        })
        .collect();
    let builder = SoftBodyBuilder::new(positions)
        .cells(cells)
        .masses(masses)
        .pinned_particles(pinned.iter().copied())
        .cell_model(SoftBodyCellModel::Corotational)
        .solver(SoftBodySolver::Fem)
        .material(SoftBodyMaterial {
            young_modulus: desc.youngs,
            poisson_ratio: desc.poisson,
            elastic_damping_ratio: damping_ratio,
            ..SoftBodyMaterial::default()
        })
        .linear_damping(desc.rayleigh[0].max(0.0))
        .particle_radius(desc.particle_radius)
        .surface_collider(
            ColliderBuilder::ball(desc.particle_radius)
                .density(0.0)
                .friction(desc.friction)
                .restitution(desc.restitution),
        )
        .can_sleep(false);
    Ok(TetSoftBody {
        builder,
        particle_node,
        pinned,
        mass,
        damping_ratio,
        beta_range,
    })
}

/// Reads `path` with the baker's mesh reader and builds its soft body (see [`tet_soft_body()`]).
///
/// # Errors
/// The mesh cannot be read, or [`tet_soft_body()`] refuses it (the message names the file).
pub fn tet_soft_body_from_file(
    path: &std::path::Path,
    desc: &TetSoftBodyDesc,
) -> Result<TetSoftBody> {
    let mesh = modal_bake::mesh::read_mesh(path)
        .with_context(|| format!("reading mesh {}", path.display()))?;
    tet_soft_body(&mesh, desc).with_context(|| format!("soft body of {}", path.display()))
}
