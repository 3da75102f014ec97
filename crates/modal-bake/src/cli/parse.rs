//! Small value parsers shared by the subcommands (the general ones are defined once in
//! [`modal_bake::args`]).

pub use modal_bake::args::{aabb, vec3};
