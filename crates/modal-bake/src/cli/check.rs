//! `modal-bake check`: exit 0 up to date, 1 stale or missing, 2 error.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use modal_bake::bake::{self, BaseStatus};
use modal_bake::mesh::surface::is_surface_asset;

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
    /// How a surface asset was meshed (it is meshed again the same way and compared).
    #[command(flatten)]
    pub asset: AssetOptions,
    /// Print one JSON object: {"base", "mesh", "up_to_date", "reason" (up_to_date, missing,
    /// unreadable, tool_changed, geometry_changed, parameters_changed, transfer_table_changed),
    /// "detail" (what differs, by the options that change it; null when up to date or
    /// missing), "meshed_again" (false when a surface asset's base records the same bytes or
    /// surface, options, meshers and build, so the asset was not meshed again)} (or {"error"}
    /// with exit 2).
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &CheckArgs) -> ExitCode {
    let params = bake::BakeParams {
        transfer: args.transfer.params(),
        ..args.options.params()
    };
    let file = args.mesh.display().to_string();
    let asset = super::bake::asset_for(&args.asset, args.transfer.transfer_h.is_some(), &args.mesh);
    // The options are checked as `bake` checks them, naming the option.
    // An unchanged asset is not meshed again (minutes on a large one) when its base records
    // the same bytes or surface, options, meshers and build.
    let mut remeshed = true;
    let status = args
        .options
        .model
        .check_ranges()
        .and_then(|()| {
            super::bake::unchanged_asset_up_to_date(&args.mesh, &asset, &params, &args.out)
        })
        .and_then(|unchanged| {
            if unchanged {
                remeshed = false;
                return Ok(BaseStatus::UpToDate);
            }
            let loaded = super::bake::load_mesh(&args.mesh, &asset)?;
            Ok(bake::mesh_base_status(
                loaded.mesh,
                &file,
                &params,
                &args.out,
            )?)
        });
    match status {
        Ok(status) => {
            let fresh = status == BaseStatus::UpToDate;
            let detail = super::bake::stale_detail(&status, &args.out, &asset);
            if args.json {
                outln!(
                    "{}",
                    serde_json::json!({
                        "base": args.out.display().to_string(),
                        "mesh": args.mesh.display().to_string(),
                        "up_to_date": fresh,
                        "reason": status.reason(),
                        "detail": detail,
                        "meshed_again": is_surface_asset(&args.mesh) && remeshed,
                    })
                );
            } else if fresh && !remeshed {
                outln!(
                    "{}: up to date (the asset's surface, options, meshers and build are the base's: not meshed again)",
                    args.out.display()
                );
            } else if fresh {
                outln!("{}: up to date", args.out.display());
            } else {
                outln!(
                    "{}: stale ({}){}",
                    args.out.display(),
                    status.reason().replace('_', " "),
                    detail.map(|d| format!(": {d}")).unwrap_or_default()
                );
            }
            if fresh {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Err(e) => {
            if args.json {
                outln!(
                    "{}",
                    serde_json::json!({
                        "base": args.out.display().to_string(),
                        "mesh": args.mesh.display().to_string(),
                        "error": super::one_line(&e),
                    })
                );
            }
            eprintln!("error: {}", super::one_line(&e));
            ExitCode::from(2)
        }
    }
}
