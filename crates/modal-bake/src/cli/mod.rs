//! Command-line front end: one file per subcommand.

/// `println!` through [`write_stdout`]: a failed write is remembered and turned into an error
/// exit by `main` (a closed pipe, `modal-bake info x.modes | head`, ends output quietly).
macro_rules! outln {
    ($($t:tt)*) => {
        $crate::cli::write_stdout(format_args!("{}\n", format_args!($($t)*)))
    };
}

mod bake;
mod bake_options;
mod batch;
mod budget;
mod check;
mod export;
mod geodesic;
mod info;
mod info_mesh;
mod lab_alias;
mod mesh;
mod parse;
mod probe;
mod progress;
mod target;

use std::path::Path;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Bake linear-FEM modal bases (.modes) from tetrahedral meshes and inspect them.
///
/// Units are SI throughout: metres, kilograms, seconds, pascals, newton-seconds.
#[derive(Parser)]
#[command(
    name = "modal-bake",
    version,
    about,
    long_about = None,
    propagate_version = true,
    after_help = ENVIRONMENT
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The environment variables modal-bake reads, for `--help`.
const ENVIRONMENT: &str = "Environment:\n  \
     MODAL_BAKE_PYTHON           the Python that runs gmsh's module and pytetwild (default: python3 on PATH; python on Windows)\n  \
     PATH                        where `gmsh` and `python3` (Windows: `python`) are found\n  \
     MODAL_BAKE_PROGRESS_EVERY   seconds between progress lines in a log that is not a terminal (default 5; 0: every event)\n  \
     TMPDIR                      where the meshers' work folders are made (removed on exit; Windows: TMP, TEMP)\n  \
     JOB_COMPLETION_INDEX, SLURM_ARRAY_TASK_ID (and _MIN, _COUNT)\n  \
     \x20                           batch --shard env:NAME/N: the shard index a Kubernetes Job or Slurm array gives";

#[derive(Subcommand)]
enum Command {
    /// Bake MESH (gmsh MSH 2.2/4.1 ASCII or binary, meshio JSON, or a surface asset .obj /
    /// .stl / .ply / .glb / .gltf meshed with gmsh or fTetWild) into OUT.modes.
    #[command(allow_negative_numbers = true)]
    Bake(bake::BakeArgs),
    /// Bake the bases a manifest (JSON or TOML) lists, skipping those up to date; one shard
    /// of it (--shard I/N) on a farm, --jobs J at once. See docs/farm.md.
    #[command(allow_negative_numbers = true)]
    Batch(batch::BatchArgs),
    /// Tetrahedralize a surface asset (OBJ, STL, PLY, glTF) into a .msh mesh: inspected, then gmsh
    /// or fTetWild (--mesher auto).
    Mesh(mesh::MeshArgs),
    /// Print a readable summary of a .modes file, or of a volume mesh (.msh, .json) before
    /// baking it (or one JSON object with --json).
    Info(info::InfoArgs),
    /// Exit 0 if OUT.modes is up to date for MESH and the options, 1 if stale or missing,
    /// 2 on an error (unreadable mesh, bad options).
    #[command(allow_negative_numbers = true)]
    Check(check::CheckArgs),
    /// Distant response of one impulse at the contacts of a base (runtime conventions).
    #[command(allow_negative_numbers = true)]
    Probe(probe::ProbeArgs),
    /// Mode shapes as VTU (ParaView, meshio), GLB (Blender, three.js) and a PNG contact sheet.
    #[command(allow_negative_numbers = true)]
    Export(export::ExportArgs),
    /// Heat-method geodesic distances (m) from one surface vertex of a base.
    Geodesic(geodesic::GeodesicArgs),
    /// Moved to `dcr-lab truth` (full-order reference response; same options).
    #[command(disable_help_flag = true)]
    Truth(lab_alias::LabArgs),
    /// Moved to `dcr-lab fit-attenuation` (Eq. 14 fitted to the full-order response; same
    /// options).
    #[command(disable_help_flag = true)]
    FitAttenuation(lab_alias::LabArgs),
}

/// The first failure writing stdout, if any (checked once by `main`).
static STDOUT_ERROR: std::sync::OnceLock<std::io::Error> = std::sync::OnceLock::new();

/// Writes to stdout. The first failure is remembered and later writes are skipped; `main`
/// turns it into an error exit, except a closed pipe (`| head`), which ends output quietly.
pub fn write_stdout(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if STDOUT_ERROR.get().is_some() {
        return;
    }
    if let Err(e) = std::io::stdout().lock().write_fmt(args) {
        let _ = STDOUT_ERROR.set(e);
    }
}

/// Writes `s` to stdout ([`write_stdout`]).
pub fn emit(s: &str) {
    write_stdout(format_args!("{s}"));
}

/// Flushes stdout and returns the first write failure, a closed pipe excepted.
fn stdout_failure() -> Option<&'static std::io::Error> {
    use std::io::Write;
    if let Err(e) = std::io::stdout().lock().flush() {
        let _ = STDOUT_ERROR.set(e);
    }
    STDOUT_ERROR
        .get()
        .filter(|e| e.kind() != std::io::ErrorKind::BrokenPipe)
}

/// Refuses an output path before any long work: `out` must not be one of `inputs` (same
/// device and inode: a hard link or another spelling counts), must not exist as anything but a
/// regular file, and its nearest existing ancestor must be a folder.
///
/// # Errors
/// A one-line message naming `option` and the path.
pub fn check_output(out: &Path, option: &str, inputs: &[&Path]) -> anyhow::Result<()> {
    let mut plan = dcr_files::OutputPlan::new();
    for input in inputs {
        plan.input("the input", input);
    }
    plan.output(option, out)?;
    Ok(())
}

/// Creates the missing folders of `out`'s parent, saying so on stderr.
///
/// # Errors
/// When a folder cannot be created (message names it).
pub fn create_parent(out: &Path) -> anyhow::Result<()> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.exists() {
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("cannot create folder {}: {e}", dir.display()))?;
            eprintln!("note: created folder {}", dir.display());
        }
    }
    Ok(())
}

pub fn main() -> ExitCode {
    let cli = Cli::parse_from(modal_bake::args::join_negative_values(std::env::args_os()));
    if let Err(e) = modal_bake::signals::remove_temporaries_on_signals() {
        eprintln!("warning: cannot watch for signals ({e}); an interrupted write may leave a temporary file");
    }
    // `check` exits 2 on an error (0 and 1 say up to date / stale); the others exit 1.
    let error_code = if matches!(cli.command, Command::Check(_)) {
        2
    } else {
        1
    };
    let code = run_command(cli.command);
    match stdout_failure() {
        Some(e) => {
            eprintln!("error: cannot write to standard output: {e}");
            ExitCode::from(error_code)
        }
        None => code,
    }
}

/// An error and its causes on one line, each cause once: a cause whose text the line already
/// holds (a wrapper that prints its source, as `path: error` does) is not repeated.
pub fn one_line(e: &anyhow::Error) -> String {
    modal_bake::args::error_line(e)
}

/// `bake`: a plain bake, or with `--target-error` the cheapest base meeting the target.
fn run_bake(args: &bake::BakeArgs) -> anyhow::Result<()> {
    let asset = bake::check_args(args)?;
    match args.target_error {
        Some(target) => target::run(args, &asset, target),
        None => bake::run(args, &asset),
    }
}

fn run_command(command: Command) -> ExitCode {
    let result = match command {
        Command::Bake(a) => run_bake(&a).map(|()| ExitCode::SUCCESS),
        Command::Mesh(a) => mesh::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Info(a) => info::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Probe(a) => probe::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Export(a) => export::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Geodesic(a) => geodesic::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Truth(a) => lab_alias::run("truth", &a),
        Command::FitAttenuation(a) => lab_alias::run("fit-attenuation", &a),
        Command::Check(a) => return check::run(&a),
        Command::Batch(a) => batch::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Regression: an I/O error under a context printed its cause twice ("…: out/x.modes: No
    // such file or directory (os error 2): No such file or directory (os error 2)").
    #[test]
    fn one_line_prints_each_cause_once() {
        let io = std::io::Error::from(std::io::ErrorKind::NotFound);
        let err = dcr_runtime::format::FormatError::Io {
            path: "out/x.modes".into(),
            source: io,
        };
        let e = anyhow::Error::new(err).context("baking m.msh failed; nothing was written");
        let line = one_line(&e);
        assert_eq!(
            line,
            "baking m.msh failed; nothing was written: out/x.modes: entity not found"
        );
        assert_ne!(format!("{e:#}"), line, "anyhow's chain repeats the cause");
    }
}
