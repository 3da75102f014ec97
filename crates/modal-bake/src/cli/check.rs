//! `modal-bake check`: exit 0 up to date, 1 stale or missing, 2 error.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use modal_bake::bake;

use super::bake::{BakeOptions, TransferOptions};
use super::mesh::AssetOptions;

#[derive(Args)]
pub struct CheckArgs {
    /// The source mesh.
    pub mesh: PathBuf,
    /// The base that should hold its modes.
    pub out: PathBuf,
    #[command(flatten)]
    pub options: BakeOptions,
    /// The transfer-table options the base was baked with (a base with another table, or a
    /// table when none is asked for, is stale).
    #[command(flatten)]
    pub transfer: TransferOptions,
    /// How a surface asset was meshed (it is meshed again with gmsh and compared).
    #[command(flatten)]
    pub asset: AssetOptions,
}

pub fn run(args: &CheckArgs) -> ExitCode {
    let transfer = args.transfer.params();
    let (mesh, _) = match super::bake::load_mesh(&args.mesh, &args.asset) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e:#}");
            return ExitCode::from(2);
        }
    };
    match bake::is_mesh_up_to_date(
        mesh,
        &args.mesh.display().to_string(),
        &args.options.params(),
        transfer.as_ref(),
        &args.out,
    ) {
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
