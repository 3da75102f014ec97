//! `dcr-lab accuracy`: regenerates the accuracy report (see [`dcr_lab::accuracy`]).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use dcr_lab::accuracy::{all_objects, AccuracyOptions};

#[derive(Args, Clone, Debug)]
pub struct AccuracyArgs {
    /// Folder of the report: writes OUT/accuracy.md and OUT/accuracy/*.svg.
    #[arg(long, value_name = "DIR", default_value = "docs")]
    pub out: PathBuf,
    /// Repository root (scene meshes are read from ROOT/data/scenes).
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub root: PathBuf,
    /// Only these objects (repeatable): table, roof, scaffold, ground, cliff, floor, fridge,
    /// fridge-surface, slab.
    #[arg(long, value_name = "NAME")]
    pub only: Vec<String>,
    /// Fewer method rows and no attenuation fit (a pipeline check).
    #[arg(long)]
    pub quick: bool,
    /// Impacts of the objects whose truth is Newmark (the scaffold and the cliff: more than
    /// 6000 free dofs; every impact is one more Newmark solve at each step of every level of
    /// the refinement). Default: the same 6 as every object.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=6))]
    pub newmark_impacts: Option<u64>,
    /// Impacts of one object, NAME=N (repeatable; 1 ≤ N ≤ 6), overriding --newmark-impacts:
    /// e.g. `--impacts cliff=2`, whose Newmark truth on 18k free dofs costs most per impact.
    #[arg(long, value_name = "NAME=N", value_parser = parse_impacts)]
    pub impacts: Vec<(String, usize)>,
    /// Folder of cached full-order truths (one JSON file per object, keyed by a SHA-256 of the
    /// matrices, points and settings): a rerun reuses them instead of repeating the refinement.
    /// Relative paths are under ROOT.
    #[arg(long, value_name = "DIR", default_value = "out/truth-cache")]
    pub truth_cache: PathBuf,
    /// Compute every truth afresh (neither read nor write the truth cache).
    #[arg(long)]
    pub no_truth_cache: bool,
    /// Leave out the energy-bound section (every scene run unbounded and at η = 1, 0.5, 0.1).
    #[arg(long)]
    pub no_energy: bool,
}

/// `NAME=N` with 1 ≤ N ≤ 6.
fn parse_impacts(s: &str) -> Result<(String, usize), String> {
    let (name, n) = s
        .split_once('=')
        .ok_or_else(|| format!("{s:?}: expected NAME=N, e.g. cliff=2"))?;
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| format!("{s:?}: N must be a whole number from 1 to 6"))?;
    if !(1..=6).contains(&n) {
        return Err(format!("{s:?}: N must be from 1 to 6"));
    }
    Ok((name.trim().to_string(), n))
}

pub fn run(args: &AccuracyArgs) -> anyhow::Result<()> {
    let known: Vec<&str> = all_objects().iter().map(|o| o.name).collect();
    if let Some(bad) = args.only.iter().find(|n| !known.contains(&n.as_str())) {
        anyhow::bail!("--only {bad}: no such object (known: {})", known.join(", "));
    }
    if let Some((bad, _)) = args
        .impacts
        .iter()
        .find(|(n, _)| !known.contains(&n.as_str()))
    {
        anyhow::bail!(
            "--impacts {bad}=…: no such object (known: {})",
            known.join(", ")
        );
    }
    // Inputs and outputs are checked before any work; folders are created only when the
    // report is written.
    let scenes = args.root.join("data").join("scenes");
    if !scenes.is_dir() {
        anyhow::bail!(
            "--root {}: {} is not a folder (give the repository root, which holds data/scenes)",
            args.root.display(),
            scenes.display()
        );
    }
    let svg = args.out.join("accuracy");
    let path = args.out.join("accuracy.md");
    let mut plan = dcr_files::OutputPlan::new();
    plan.output_folder("--out", &args.out)?;
    plan.output_folder("--out", &svg)?;
    plan.output("--out", &path)?;
    plan.output("--out", &svg.join("summary.svg"))?;
    let opts = AccuracyOptions {
        only: args.only.clone(),
        quick: args.quick,
        newmark_impacts: args.newmark_impacts.map(|n| n as usize),
        impacts: args.impacts.clone(),
        truth_cache: (!args.no_truth_cache).then(|| args.root.join(&args.truth_cache)),
        no_energy: args.no_energy,
    };
    let md = dcr_lab::accuracy::generate(&args.root, &args.out, &opts)?;
    dcr_files::write_atomic(&path, md.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!(
        "wrote {} and {}",
        path.display(),
        svg.join("*.svg").display()
    );
    Ok(())
}
