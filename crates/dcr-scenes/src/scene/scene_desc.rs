//! The scene file format (`scenes/*.json`), as plain serde types. See docs/scenes.md.
//!
//! Frames: world is y-up, metres, seconds, kilograms. A pose is a translation plus a rotation
//! given as a scaled axis in degrees (`rotation_deg`: axis × angle, like rapier's `AngVector`).

use serde::{Deserialize, Serialize};

/// A whole scene: simulation settings, elastic objects (with modal bases), rigid props,
/// joints, drivers and the outcome figures to measure.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// Scene name (`dinner`, `roof`, ...).
    pub name: String,
    /// One line on what happens.
    #[serde(default)]
    pub description: String,
    /// Rigid-body time step h (s). Default 0.01.
    #[serde(default = "default_h")]
    pub h: f64,
    /// Gravity (m/s², world frame). Default (0, −9.81, 0).
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Coefficient of restitution of every collider. Default 0.15 (paper §5).
    #[serde(default = "default_restitution")]
    pub restitution: f64,
    /// Default run length (s) for `dcr-scenes run`.
    #[serde(default = "default_seconds")]
    pub seconds: f64,
    /// Short run length (s) the tests use; long enough for the described effect.
    #[serde(default)]
    pub test_seconds: Option<f64>,
    /// Elastic objects: rigid bodies with a precomputed modal base.
    pub elastic: Vec<ElasticDesc>,
    /// Rigid props.
    #[serde(default)]
    pub props: Vec<PropDesc>,
    /// Joints between bodies (by name).
    #[serde(default)]
    pub joints: Vec<JointDesc>,
    /// Scripted impulses (a shaking machine, a hopping low-rider).
    #[serde(default)]
    pub drivers: Vec<DriverDesc>,
    /// Outcome figures reported on vs off; the first is the scene's main outcome (the one
    /// docs/outcomes.md judges the methods on).
    #[serde(default)]
    pub outcomes: Vec<OutcomeDesc>,
}

fn default_h() -> f64 {
    0.01
}
fn default_gravity() -> [f64; 3] {
    [0.0, -9.81, 0.0]
}
fn default_restitution() -> f64 {
    0.15
}
fn default_seconds() -> f64 {
    3.0
}
fn default_friction() -> f64 {
    0.6
}

/// A pose: translation (m) and rotation as a scaled axis in degrees.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseDesc {
    /// Translation (m, world frame or parent frame).
    #[serde(default)]
    pub translation: [f64; 3],
    /// Rotation: axis × angle in degrees (e.g. `[0, 0, 30]` is 30° about z).
    #[serde(default)]
    pub rotation_deg: [f64; 3],
}

/// Isotropic material (paper Table 2).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    /// Young's modulus (Pa).
    pub youngs: f64,
    /// Poisson ratio.
    pub poisson: f64,
    /// Density (kg/m³).
    pub density: f64,
}

/// How an elastic object's body moves in rapier.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum BodyKind {
    /// Fixed (collision detection + response only).
    Static,
    /// Dynamic with this mass (kg).
    Dynamic {
        /// Mass (kg).
        mass: f64,
    },
}

/// How the response of an elastic object is computed.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MethodDesc {
    /// Modal IIR response (paper §4.2–4.3).
    Modal,
    /// Spatial attenuation, simplified law s = C r^−β (paper §4.4–4.5).
    Attenuation {
        /// C.
        c: f64,
        /// β.
        beta: f64,
        /// `heat` (geodesics by the heat method, one solve per new resting contact),
        /// `heat_table` (the same distances precomputed for all surface vertex pairs at set-up,
        /// read bilinearly) or `euclidean`.
        #[serde(default = "default_distance")]
        distance: String,
        /// Amplitude: `per_vertex`, `mean`, or the name of a physical group of the mesh whose
        /// surface vertices are averaged (e.g. `top`).
        #[serde(default = "default_amplitude")]
        amplitude: String,
    },
    /// The base's bake-time peak-transfer table (`dcr_runtime::Method::Transfer`): peaks
    /// summed over many modes (every mode where the dense eigensolve fits), looked up between
    /// the table's region points. Contacts and impacts outside the region are served by the
    /// 20-mode modal base the table is stored in (`ServedBy::Modal` in the events).
    Transfer(TransferDesc),
}

/// What an elastic object's peak-transfer table covers (`modal_bake::transfer::TransferParams`).
/// The table is baked for the scene's step `h` and the object's Rayleigh damping, into its own
/// base file (`out/bases/NAME.transfer.modes`) beside the plain modal base.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferDesc {
    /// Up direction (mesh frame, any length): the region keeps surface vertices whose outward
    /// normal is within 60° of it. `None` (default): no normal filter.
    #[serde(default)]
    pub up: Option<[f64; 3]>,
    /// Region boxes `[xmin, ymin, zmin, xmax, ymax, zmax]` (m, mesh frame): the region keeps
    /// surface vertices inside any of them. Empty (default): the whole surface.
    #[serde(default)]
    pub boxes: Vec<[f64; 6]>,
    /// Modes summed by the table. `None` (default): every mode when the mesh has at most
    /// 6000 free dofs (dense eigensolve), else the lowest 640 (Lanczos).
    #[serde(default)]
    pub modes: Option<usize>,
    /// Interpolation order over each region triangle. Default `auto` (cubic up to 5792
    /// points, else quadratic).
    #[serde(default)]
    pub order: TableOrderDesc,
    /// The step the table is baked for (s). Optional: a table is valid for one h only, and it
    /// is always baked for the scene's `h`; stating it pins the table to that step, and a run
    /// whose scene steps another h is refused (error naming the object) instead of rebaking.
    #[serde(default)]
    pub h: Option<f64>,
}

/// Interpolation order of a transfer table over each region triangle
/// (`modal_bake::transfer::TableOrder`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TableOrderDesc {
    /// Cubic when the cubic table has at most 5792 points, else quadratic.
    #[default]
    Auto,
    /// Vertices only.
    Linear,
    /// Vertices and edge midpoints (P2).
    Quadratic,
    /// Vertices, two points per edge and face centroids (P3).
    Cubic,
}

fn default_distance() -> String {
    "heat".into()
}
fn default_amplitude() -> String {
    "per_vertex".into()
}

/// An elastic object: a tet mesh with a modal base, posed in the world.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticDesc {
    /// Name (also the Table 1 "model" column and the base's file stem).
    pub name: String,
    /// Tet mesh path relative to the repository root (`data/scenes/table.msh`).
    pub mesh: String,
    /// Material (paper Table 2).
    pub material: MaterialDesc,
    /// Physical groups of the mesh whose nodes are fixed. The fixed set is the union of
    /// `fixed`, `fixed_below` and `fixed_boxes`; all empty: free-free. Default empty.
    #[serde(default)]
    pub fixed: Vec<String>,
    /// Half-spaces of fixed nodes, in the mesh frame: `{"axis": "y", "value": 0.01}` fixes
    /// every node with y ≤ 0.01 m — an asset without physical groups (an OBJ meshed by
    /// `modal-bake mesh`) standing on its feet. The bake's `--fixed-below`. Default empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_below: Vec<FixedBelowDesc>,
    /// Boxes of fixed nodes `[x0, y0, z0, x1, y1, z1]` (m, mesh frame, bounds included). The
    /// bake's `--fixed-box`. Default empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_boxes: Vec<[f64; 6]>,
    /// Number of modes. Default 20.
    #[serde(default = "default_modes")]
    pub modes: usize,
    /// Rayleigh damping (α0 1/s, α1 s) baked into the base. Default (10, 1e-7).
    #[serde(default = "default_rayleigh")]
    pub rayleigh: [f64; 2],
    /// Static or dynamic.
    pub body: BodyKind,
    /// Pose of the mesh frame in the world.
    #[serde(default)]
    pub pose: PoseDesc,
    /// Collision proxy: `None` uses the mesh's boundary as a trimesh (static bodies only);
    /// otherwise these primitive colliders (in the mesh frame).
    #[serde(default)]
    pub colliders: Option<Vec<ColliderDesc>>,
    /// Friction coefficient. Default 0.6.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Response method used when the run does not override it. Default modal.
    #[serde(default = "default_method")]
    pub method: MethodDesc,
    /// Attenuation settings used when a run asks for `--method attenuation` on a scene whose
    /// default is modal.
    #[serde(default)]
    pub attenuation: Option<MethodDesc>,
    /// Transfer-table settings used when a run asks for `--method transfer` on a scene whose
    /// default is another method (a run refuses `--method transfer` for an object without
    /// them, or without `method: {"transfer": ...}`).
    #[serde(default)]
    pub transfer: Option<TransferDesc>,
    /// Impacts below this normal impulse (N·s) are ignored (paper §4.5). Default 0.5.
    #[serde(default = "default_threshold")]
    pub impact_threshold: f64,
    /// Scale on the response impulses (1 = the paper's Eq. 18); a run's `--gain` overrides it
    /// for every object. Default 1.
    #[serde(default = "default_gain")]
    pub gain: f64,
}

impl ElasticDesc {
    /// `fixed_below` as the baker's selectors (axis 0 = x, 1 = y, 2 = z).
    pub fn fixed_below(&self) -> Vec<modal_bake::bake::FixedBelow> {
        self.fixed_below
            .iter()
            .map(|b| modal_bake::bake::FixedBelow {
                axis: b.axis as usize,
                value: b.value,
            })
            .collect()
    }

    /// Whether nothing is fixed (a free-free object).
    pub fn free_free(&self) -> bool {
        self.fixed.is_empty() && self.fixed_below.is_empty() && self.fixed_boxes.is_empty()
    }
}

/// A half-space of fixed nodes: every node whose coordinate `axis` is ≤ `value` (mesh frame).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixedBelowDesc {
    /// The coordinate compared: `"x"`, `"y"` or `"z"`.
    pub axis: AxisDesc,
    /// The threshold (m); nodes at or below it are fixed.
    pub value: f64,
}

/// A coordinate axis of the mesh frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisDesc {
    /// x.
    X = 0,
    /// y.
    Y = 1,
    /// z.
    Z = 2,
}

fn default_modes() -> usize {
    20
}
fn default_rayleigh() -> [f64; 2] {
    [10.0, 1e-7]
}
fn default_method() -> MethodDesc {
    MethodDesc::Modal
}
fn default_threshold() -> f64 {
    0.5
}
fn default_gain() -> f64 {
    1.0
}

/// A collision shape (sizes in m).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeDesc {
    /// Box with these half extents.
    Cuboid {
        /// Half extents (m).
        half_extents: [f64; 3],
    },
    /// Sphere.
    Ball {
        /// Radius (m).
        radius: f64,
    },
    /// Cylinder along y.
    Cylinder {
        /// Half height (m).
        half_height: f64,
        /// Radius (m).
        radius: f64,
    },
    /// Cone along y (apex up).
    Cone {
        /// Half height (m).
        half_height: f64,
        /// Base radius (m).
        radius: f64,
    },
    /// Capsule along y.
    Capsule {
        /// Half height of the segment (m).
        half_height: f64,
        /// Radius (m).
        radius: f64,
    },
    /// Convex hull of these points (m, collider frame).
    ConvexHull {
        /// Points.
        points: Vec<[f64; 3]>,
    },
}

/// One collider of a body: a shape at an offset in the body frame.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColliderDesc {
    /// Shape.
    pub shape: ShapeDesc,
    /// Pose in the body frame.
    #[serde(default)]
    pub offset: PoseDesc,
}

/// A rigid prop. `copies` places the same prop at several poses (names get `_0`, `_1`, ...).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropDesc {
    /// Name (copies: name_i).
    pub name: String,
    /// Colliders (body frame); the body's mass is spread over them by volume.
    pub colliders: Vec<ColliderDesc>,
    /// Total mass (kg).
    pub mass: f64,
    /// Pose (world frame). With `copies`, the pose of each copy is `pose` followed by the
    /// copy's translation.
    #[serde(default)]
    pub pose: PoseDesc,
    /// Extra translations (m, world) of copies; empty means one body.
    #[serde(default)]
    pub copies: Vec<[f64; 3]>,
    /// Friction coefficient. Default 0.6.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Initial linear velocity (m/s, world).
    #[serde(default)]
    pub linvel: [f64; 3],
    /// Initial angular velocity (rad/s, world).
    #[serde(default)]
    pub angvel: [f64; 3],
    /// Linear damping. Default 0.
    #[serde(default)]
    pub linear_damping: f64,
    /// Angular damping. Default 0.
    #[serde(default)]
    pub angular_damping: f64,
    /// Continuous collision detection (fast droppers). Default false.
    #[serde(default)]
    pub ccd: bool,
    /// A fixed body (plain static scenery without a base, e.g. a road); not recorded.
    #[serde(default)]
    pub fixed: bool,
    /// Name of an elastic object whose frame `pose` and `copies` are given in (props resting
    /// on a tilted roof). Velocities stay in the world frame.
    #[serde(default)]
    pub relative_to: Option<String>,
}

/// A compliant revolute joint (the plant's leaves): body2 hinges on body1 about `axis`,
/// pulled back to its initial angle by a motor spring (stiffness N·m/rad, damping N·m·s/rad).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDesc {
    /// Parent body name.
    pub body1: String,
    /// Child body name (a glob `leaf*` joins every match to body1, each at `anchor_offset`
    /// from its own centre).
    pub body2: String,
    /// Hinge point relative to the child's initial centre (m, world frame).
    pub anchor_offset: [f64; 3],
    /// Hinge axis (world frame; both bodies start unrotated).
    pub axis: [f64; 3],
    /// Spring stiffness (N·m/rad).
    pub stiffness: f64,
    /// Spring damping (N·m·s/rad).
    pub damping: f64,
}

/// A scripted impulse source.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriverDesc {
    /// Body name.
    pub body: String,
    /// First application (s).
    #[serde(default)]
    pub start: f64,
    /// No application after this (s).
    #[serde(default = "default_stop")]
    pub stop: f64,
    /// Period between applications (s).
    pub period: f64,
    /// Impulse (N·s, world frame) at t = start.
    pub impulse: [f64; 3],
    /// If set, the impulse rotates about this world axis at `hz` turns per second (an
    /// unbalanced drum).
    #[serde(default)]
    pub rotate_axis: Option<[f64; 3]>,
    /// Rotation rate (Hz).
    #[serde(default)]
    pub hz: f64,
    /// Point of application in the body frame (m). Default the centre of mass.
    #[serde(default)]
    pub point: Option<[f64; 3]>,
}

fn default_stop() -> f64 {
    f64::INFINITY
}

/// An outcome figure, measured over the run on the bodies whose name matches `bodies`
/// (exact, or a prefix glob `plate*`).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutcomeDesc {
    /// Figure name (`plates_max_lift`, ...).
    pub name: String,
    /// `max_lift` (mm: largest rise of the centre of mass above its start),
    /// `max_slide` (mm: largest horizontal displacement, final),
    /// `max_tilt` (deg: largest rotation from the start pose),
    /// `count_fallen` (bodies whose centre dropped more than `threshold` m),
    /// `max_sway` (deg: largest rotation relative to `relative_to` from the start),
    /// `sway_range` (deg: range over time of the rotation relative to `relative_to`),
    /// `count_moved` (bodies displaced more than `threshold` m).
    pub kind: String,
    /// Bodies (name or prefix glob).
    pub bodies: String,
    /// Threshold for the count kinds (m). Default 0.1.
    #[serde(default = "default_outcome_threshold")]
    pub threshold: f64,
    /// For `max_sway`: the body the rotation is measured relative to.
    #[serde(default)]
    pub relative_to: Option<String>,
    /// Only count what happens from this time on (s). Default 0.
    #[serde(default)]
    pub after: f64,
}

fn default_outcome_threshold() -> f64 {
    0.1
}

impl SceneDesc {
    /// Largest scene file read (bytes).
    pub const MAX_FILE_BYTES: u64 = 64 << 20;

    /// Reads, parses and validates ([`SceneDesc::validate`]) a scene file. Only a regular file
    /// (or a link to one) of at most [`SceneDesc::MAX_FILE_BYTES`] is opened.
    ///
    /// # Errors
    /// A message naming the file and, for a field out of range, the field and its range.
    pub fn read(path: &std::path::Path) -> anyhow::Result<SceneDesc> {
        use std::io::Read;
        let (file, len) = dcr_runtime::format::open_regular_file(path)
            .map_err(|e| anyhow::anyhow!("scene {}: {e}", path.display()))?;
        if len > Self::MAX_FILE_BYTES {
            anyhow::bail!(
                "scene {}: {len} bytes; a scene file holds at most {} bytes",
                path.display(),
                Self::MAX_FILE_BYTES
            );
        }
        let mut text = String::new();
        file.take(Self::MAX_FILE_BYTES)
            .read_to_string(&mut text)
            .map_err(|e| anyhow::anyhow!("scene {}: {e}", path.display()))?;
        let desc: SceneDesc = serde_json::from_str(&text)
            .map_err(|e| anyhow::anyhow!("scene {}: {e}", path.display()))?;
        desc.validate()
            .map_err(|e| anyhow::anyhow!("scene {}: {e}", path.display()))?;
        Ok(desc)
    }
}

/// Does `name` match `pattern` (exact, or prefix glob ending in `*`)?
///
/// ```
/// use dcr_scenes::scene::name_matches;
/// assert!(name_matches("plate*", "plate_3"));
/// assert!(name_matches("pot", "pot") && !name_matches("pot", "pot_0"));
/// ```
pub fn name_matches(pattern: &str, name: &str) -> bool {
    match pattern.strip_suffix('*') {
        Some(prefix) => name.starts_with(prefix),
        None => name == pattern,
    }
}
