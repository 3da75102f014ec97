//! The response engine the adapter talks to: `dcr_runtime`'s public surface.
//!
//! TEMPORARY: while `dcr_runtime::DistantResponse` is being written, this re-exports a minimal
//! stand-in built from the runtime's existing pieces (`ModalModel`, `ModalBank`), with the
//! same contract. Replace the body of this file with `pub use dcr_runtime::{...}` when the
//! runtime's response lands.

pub use super::engine_standin::*;
