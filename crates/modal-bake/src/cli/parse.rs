//! Small value parsers shared by the subcommands (defined once in [`modal_bake::args`]).

pub use modal_bake::args::{aabb, vec3};
