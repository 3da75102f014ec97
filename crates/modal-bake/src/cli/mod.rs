//! Command-line front end: one file per subcommand.

/// `println!` that ignores a closed stdout (`modal-bake info x.modes | head` must not panic).
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($t)*);
    }};
}

mod bake;
mod check;
mod geodesic;
mod info;
mod lab_alias;
mod parse;
mod probe;
mod target;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Bake linear-FEM modal bases (.modes) from tetrahedral meshes and inspect them.
///
/// Units are SI throughout: metres, kilograms, seconds, pascals, newton-seconds.
#[derive(Parser)]
#[command(name = "modal-bake", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Bake MESH (gmsh MSH 2.2/4.1 ASCII or binary, or meshio JSON) into OUT.modes.
    #[command(allow_negative_numbers = true)]
    Bake(bake::BakeArgs),
    /// Print a readable summary of a .modes file (or one JSON object with --json).
    Info(info::InfoArgs),
    /// Exit 0 if OUT.modes is up to date for MESH and the options, 1 if stale or missing,
    /// 2 on an error (unreadable mesh, bad options).
    #[command(allow_negative_numbers = true)]
    Check(check::CheckArgs),
    /// Distant response of one impulse at the contacts of a base (runtime conventions).
    #[command(allow_negative_numbers = true)]
    Probe(probe::ProbeArgs),
    /// Heat-method geodesic distances (m) from one surface vertex of a base.
    Geodesic(geodesic::GeodesicArgs),
    /// Alias of `dcr-lab truth` (full-order reference response): runs the `dcr-lab` binary.
    #[command(disable_help_flag = true)]
    Truth(lab_alias::LabArgs),
    /// Alias of `dcr-lab fit-attenuation` (Eq. 14 fitted to the full-order response): runs the
    /// `dcr-lab` binary.
    #[command(disable_help_flag = true)]
    FitAttenuation(lab_alias::LabArgs),
}

/// Writes `s` to stdout; a closed pipe (`modal-bake info x | head`) is not an error.
pub fn emit(s: &str) {
    use std::io::Write;
    let _ = std::io::stdout().lock().write_all(s.as_bytes());
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Bake(a) => bake::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Info(a) => info::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Probe(a) => probe::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Geodesic(a) => geodesic::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Truth(a) => lab_alias::run("truth", &a),
        Command::FitAttenuation(a) => lab_alias::run("fit-attenuation", &a),
        Command::Check(a) => return check::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
