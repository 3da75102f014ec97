//! `dcr-capi`: the C ABI of the dcr runtime (paper §4.2–4.5), for C and C++ engines.
//!
//! Built as `libdcr_capi.a` (static) and `libdcr_capi.so` (shared) with the header
//! `include/dcr.h`, which cbindgen generates from this crate's `extern "C"` items and their doc
//! comments (the tests regenerate it and fail when the committed file differs). The conventions
//! follow the Rapier C API:
//!
//! - every name is prefixed `dcr_` (functions), `Dcr` (types) or `DCR_` (constants);
//! - objects are opaque handles created and freed explicitly: [`DcrModel`] (an immutable base,
//!   `dcr_model_load` / `dcr_model_load_bytes` / `dcr_model_free`), [`DcrResponse`] (one
//!   object's per-step query, `dcr_response_create` / `dcr_response_free`), [`DcrWorld`] (the
//!   engine-level world API, `dcr_world_create` / `dcr_world_free`);
//! - every fallible call returns a [`DcrStatus`]; on failure a thread-local message (the Rust
//!   error's text, naming the file and the entry, value or argument at fault) is available
//!   through `dcr_last_error_message` or `dcr_last_error`. The only calls without a status are
//!   those that cannot fail: the `*_free` functions (which, like `free`, accept NULL),
//!   `dcr_last_error`, `dcr_status_name` and `dcr_version_string`;
//! - no panic crosses the boundary: every entry point runs under `catch_unwind`, and a panic
//!   becomes [`DcrStatus::Panic`] (the objects the call mutated must then be freed, not used);
//! - NULL pointers, misaligned pointers, unknown enumeration codes, `bool` fields that hold
//!   neither 0 nor 1 (read as raw bytes before any Rust reference exists) and set-up structs
//!   whose `struct_size` is not this library's `sizeof` are errors, never crashes;
//! - output arrays are caller-owned with an explicit capacity; when it is too small the call
//!   does nothing else, returns [`DcrStatus::BufferTooSmall`] and reports the required count.
//!   The world's impulse events are the exception: a borrowed array, valid until the next
//!   `dcr_world_step` or `dcr_world_free` on that world (Box2D's contact events).
//!
//! Units are SI (m, kg, s, N·s); the frame of every point and vector is stated on its field:
//! the per-object query works in the base's object frame, the world API in the world frame.
//!
//! Threading: a [`DcrModel`] is immutable and may be shared by any number of threads, responses
//! and worlds at once (`ModalModel` is `Send + Sync`; handles keep it alive by reference count,
//! so `dcr_model_free` may come before the responses built on it are freed). A [`DcrResponse`]
//! or [`DcrWorld`] is used by one thread at a time (it may move between threads between calls).
//!
//! The per-step calls (`dcr_response_step`, `dcr_world_step`) do not allocate after warm-up:
//! they convert the caller's arrays into scratch buffers kept in the handle.
//!
//! This crate is the workspace's only exemption from `unsafe_code = "deny"`: every `unsafe`
//! block dereferences a pointer the C caller passed, after the checks in `ptr.rs`, and carries
//! a `// SAFETY:` comment.
//!
//! The call order, from Rust through the rlib (C programs: `examples/probe.c`,
//! `examples/world.c`):
//!
//! ```
//! # #![allow(unsafe_code)]
//! use dcr_capi::*;
//! # let dir = tempfile::tempdir()?;
//! # let path = dir.path().join("plate.modes");
//! # dcr_runtime::testing::plate_base().write_atomic(&path)?; // a 1 m × 0.6 m plate, z = 0
//! let bytes = std::fs::read(&path)?; // a baked .modes base
//! let mut model = std::ptr::null_mut();
//! let mut response = std::ptr::null_mut();
//! let mut params = DcrResponseParams::defaults(); // = dcr_response_params_default(&params)
//! params.method = DCR_METHOD_MODAL;
//! // A 2 N·s hit pushing into the plate (−z) at its middle; a box resting near a corner.
//! let hit = DcrImpact { point: [0.5, 0.3, 0.0], direction: [0.0, 0.0, -1.0], impulse: 2.0 };
//! let resting = [DcrRestingContact { id: 7, point: [0.9, 0.5, 0.001] }];
//! let mut out = [DcrContactResponse::default(); 1];
//! let mut count = 0;
//! // SAFETY: valid pointers and counts; handles freed once.
//! unsafe {
//!     assert_eq!(dcr_model_load_bytes(bytes.as_ptr(), bytes.len(), &mut model), DcrStatus::Ok);
//!     assert_eq!(dcr_response_create(model, &params, &mut response), DcrStatus::Ok);
//!     let st = dcr_response_step(response, &hit, 1, resting.as_ptr(), 1, out.as_mut_ptr(), 1,
//!         &mut count);
//!     assert_eq!(st, DcrStatus::Ok);
//!     dcr_response_free(response);
//!     dcr_model_free(model);
//! }
//! assert!(count == 1 && out[0].mapped && out[0].delta_v > 0.0); // m/s along +normal
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![allow(unsafe_code)]

mod guard;
mod helpers;
mod model;
mod ptr;
mod response;
mod response_params;
mod status;
mod version;
mod world;
mod world_params;

pub use guard::guard;
pub use helpers::*;
pub use model::*;
pub use response::*;
pub use response_params::*;
pub use status::*;
pub use version::*;
pub use world::*;
pub use world_params::*;
