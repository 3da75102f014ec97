//! What a person looks at after a run: the run as an animated glTF ([`write_scene_glb`]: every
//! body from its collider shapes, elastic objects from their surface mesh, a keyframe per
//! step, response events in `extras`; several runs side by side) and the outcome figures over
//! time as SVG ([`write_outcomes_svg`]). The browser viewer in `viewer/` plays the glTF.

mod outcomes_svg;
mod scene_gltf;
mod shape_mesh;

pub use outcomes_svg::{outcome_series, write_outcomes_svg, SVG_CURVE_POINTS};
pub use scene_gltf::{side_label, write_scene_glb, SceneGlbInfo, Side};
pub use shape_mesh::{shape_triangles, ShapeMesh};
