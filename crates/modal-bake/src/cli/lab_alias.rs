//! `modal-bake truth` and `modal-bake fit-attenuation`: the evaluation tools moved to the
//! `dcr-lab` binary (`dcr-lab truth`, `dcr-lab fit-attenuation`, same options). These
//! subcommands only say so, in one line, and exit with a failure.
//!
//! Why no forwarding: `dcr-lab` depends on this crate (it drives the baker's full-order kernel,
//! [`modal_bake::full_order`]), so this binary cannot call it as a library, and running another
//! executable found by path or `PATH` would make the result depend on which `dcr-lab` is found.

use std::ffi::OsString;
use std::process::ExitCode;

use clap::Args;

/// Everything after the subcommand (accepted so that the message is the same for any
/// arguments, `--help` included).
#[derive(Args, Clone, Debug)]
pub struct LabArgs {
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
    pub args: Vec<OsString>,
}

/// The error naming the `dcr-lab` subcommand to run instead.
pub fn run(subcommand: &str, _args: &LabArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "`modal-bake {subcommand}` moved to `dcr-lab {subcommand}` (same options): run `dcr-lab {subcommand} …` (build it with `cargo build --release -p dcr-lab`)"
    )
}
