//! `modal-bake check`: exit 0 up to date, 1 stale or missing, 2 error.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use modal_bake::bake;

use super::bake::BakeOptions;

#[derive(Args)]
pub struct CheckArgs {
    /// The source mesh.
    pub mesh: PathBuf,
    /// The base that should hold its modes.
    pub out: PathBuf,
    #[command(flatten)]
    pub options: BakeOptions,
}

pub fn run(args: &CheckArgs) -> ExitCode {
    match bake::is_up_to_date(&args.mesh, &args.options.params(), &args.out) {
        Ok(true) => {
            outln!("{}: up to date", args.out.display());
            ExitCode::SUCCESS
        }
        Ok(false) => {
            outln!("{}: stale or missing", args.out.display());
            ExitCode::from(1)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
