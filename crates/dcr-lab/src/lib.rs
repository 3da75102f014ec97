//! `dcr-lab`: evaluation beside the pipeline — how far a baked base or transfer table is from
//! the full-order response it approximates, and what the attenuation law (Eq. 14) fits.
//!
//! Built on the baker's full-order kernel ([`modal_bake::full_order`]: Newmark and the sum over
//! every mode), not a copy of it:
//! - [`truth`]: the reference response of a mesh to an impulse at surface points, in
//!   `modal-bake probe`'s shape (`dcr-lab truth`);
//! - [`attenuation_fit`]: Eq. 14 and the §4.5 law fitted to the full-order response at random
//!   surface pairs (`dcr-lab fit-attenuation`);
//! - [`accuracy`]: the report `docs/accuracy.md` and its plots (`dcr-lab accuracy --out docs`);
//! - [`scene_truth`]: the coupled elastic–rigid reference of whole scenes and the outcomes page
//!   `docs/outcomes.md` (`dcr-lab scene-truth`);
//! - [`soft_body`]: the elastic objects as rapier FEM soft bodies instead, side by side with dcr
//!   (`dcr-lab soft-body run|compare`).

pub mod accuracy;
pub mod attenuation_fit;
pub mod scene_truth;
pub mod soft_body;
pub mod truth;
