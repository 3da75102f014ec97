//! `dcr-lab accuracy`: regenerates the accuracy report (see [`dcr_lab::accuracy`]).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

#[derive(Args, Clone, Debug)]
pub struct AccuracyArgs {
    /// Folder of the report: writes OUT/accuracy.md and OUT/accuracy/*.svg.
    #[arg(long, value_name = "DIR", default_value = "docs")]
    pub out: PathBuf,
    /// A short run (the table only, up to 40 modes) to check the pipeline.
    #[arg(long)]
    pub quick: bool,
    /// Only the transfer-table study of each object.
    #[arg(long)]
    pub transfer_only: bool,
}

pub fn run(args: &AccuracyArgs) -> anyhow::Result<()> {
    std::fs::create_dir_all(args.out.join("accuracy"))
        .with_context(|| format!("creating {}", args.out.join("accuracy").display()))?;
    let md = dcr_lab::accuracy::generate(&args.out, args.quick, args.transfer_only);
    let path = args.out.join("accuracy.md");
    let tmp = args
        .out
        .join(format!(".accuracy.md.tmp-{}", std::process::id()));
    std::fs::write(&tmp, md).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, &path).with_context(|| format!("writing {}", path.display()))?;
    eprintln!(
        "wrote {} and {}",
        path.display(),
        args.out.join("accuracy/*.svg").display()
    );
    Ok(())
}
