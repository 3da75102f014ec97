//! `modal-bake truth` and `modal-bake fit-attenuation`: aliases of the same subcommands of the
//! `dcr-lab` binary, kept so that existing scripts work.
//!
//! The evaluation tools live in the `dcr-lab` crate, which depends on this one (it drives the
//! baker's full-order kernel, [`modal_bake::full_order`]); so this binary cannot call them as a
//! library and runs the `dcr-lab` executable instead, with the arguments unchanged. It looks
//! for it in `$DCR_LAB` (a path), then next to this executable (where `cargo build` puts every
//! binary of the workspace), then on `PATH`.

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::{Command, ExitCode};

use anyhow::Context;
use clap::Args;

/// Everything after the subcommand, passed through to `dcr-lab` unchanged (`--help` included).
#[derive(Args, Clone, Debug)]
pub struct LabArgs {
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
    pub args: Vec<OsString>,
}

/// The `dcr-lab` executable: `$DCR_LAB`, else beside the current executable, else `dcr-lab`
/// (resolved through `PATH` when run).
fn lab_executable() -> PathBuf {
    if let Some(p) = std::env::var_os("DCR_LAB").filter(|p| !p.is_empty()) {
        return PathBuf::from(p);
    }
    let name = format!("dcr-lab{}", std::env::consts::EXE_SUFFIX);
    std::env::current_exe()
        .ok()
        .map(|exe| exe.with_file_name(&name))
        .filter(|p| p.is_file())
        .unwrap_or_else(|| PathBuf::from(name))
}

/// Runs `dcr-lab SUBCOMMAND ARGS…` after a one-line note on stderr; returns its exit code.
pub fn run(subcommand: &str, args: &LabArgs) -> anyhow::Result<ExitCode> {
    let lab = lab_executable();
    eprintln!(
        "note: `modal-bake {subcommand}` is now `dcr-lab {subcommand}` (running {})",
        lab.display()
    );
    let status = Command::new(&lab)
        .arg(subcommand)
        .args(&args.args)
        .status()
        .with_context(|| {
            format!(
                "could not run {} (build it with `cargo build --release -p dcr-lab`, or set DCR_LAB to its path)",
                lab.display()
            )
        })?;
    Ok(match status.code() {
        Some(c) => ExitCode::from(u8::try_from(c).unwrap_or(1)),
        None => ExitCode::FAILURE,
    })
}
