//! Command-line front end: one file per subcommand.

mod accuracy;
mod fit_attenuation;
mod fit_gain;
mod mesh_input;
mod progress;
mod scene_truth;
mod soft_body;
mod truth;
mod truth_base;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Evaluate dcr's bases against the full-order response: reference responses, the attenuation
/// fit and the accuracy report.
///
/// Units are SI throughout: metres, kilograms, seconds, pascals, newton-seconds.
#[derive(Parser)]
#[command(name = "dcr-lab", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Full-order reference response of a mesh to an impulse (Newmark or all modes).
    #[command(allow_negative_numbers = true)]
    Truth(truth::TruthArgs),
    /// Fit the spatial attenuation law (Eq. 14) to the full-order response at random surface pairs.
    #[command(allow_negative_numbers = true)]
    FitAttenuation(fit_attenuation::FitAttenuationArgs),
    /// Regenerate the accuracy report (OUT/accuracy.md and OUT/accuracy/*.svg).
    Accuracy(accuracy::AccuracyArgs),
    /// A scene's elastic objects as rapier FEM soft bodies, and side by side with dcr.
    SoftBody(soft_body::SoftBodyArgs),
    /// Coupled elastic–rigid reference of whole scenes; with --page, docs/outcomes.md.
    SceneTruth(scene_truth::SceneTruthArgs),
    /// The response gain at which a method's outcome matches a target (the coupled reference's).
    #[command(allow_negative_numbers = true)]
    FitGain(fit_gain::FitGainArgs),
}

/// Parses `--perturbation`: a placement distance in metres, in [0, 0.01) (the members of an
/// ensemble move the projectile by it; a centimetre would be a different scene).
pub(crate) fn parse_perturbation(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s} is not a number (a distance in metres, e.g. 1e-4)"))?;
    if (0.0..0.01).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} m is outside [0, 0.01) m (a placement distance, e.g. 1e-4)"
        ))
    }
}

/// Writes `s` to stdout. A closed pipe (`dcr-lab truth … | head`) is not an error; any other
/// failed write (a full disk) is.
pub fn emit(s: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(s.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::new(e).context("writing to stdout failed"))
        }
        _ => Ok(()),
    }
}

pub fn main() -> ExitCode {
    let cli = Cli::parse_from(modal_bake::args::join_negative_values(std::env::args_os()));
    if let Err(e) = modal_bake::signals::remove_temporaries_on_signals() {
        eprintln!("warning: cannot watch for signals ({e}); an interrupted write may leave a temporary file");
    }
    let result = match cli.command {
        Command::Truth(a) => truth::run(&a),
        Command::FitAttenuation(a) => fit_attenuation::run(&a).map(|()| ExitCode::SUCCESS),
        Command::Accuracy(a) => accuracy::run(&a).map(|()| ExitCode::SUCCESS),
        Command::SoftBody(a) => soft_body::run(&a).map(|()| ExitCode::SUCCESS),
        Command::SceneTruth(a) => scene_truth::run(&a),
        Command::FitGain(a) => fit_gain::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", modal_bake::args::error_line(&e));
            ExitCode::FAILURE
        }
    }
}
