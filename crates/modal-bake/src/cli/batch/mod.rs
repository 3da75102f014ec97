//! `modal-bake batch MANIFEST [--shard I/N] [--jobs J]`: the bases a manifest lists, baked
//! with `check` semantics — a base that is up to date ([`modal_bake::bake::mesh_base_status`],
//! the comparison `check` makes) is skipped, any other is baked as `bake` bakes it — with the
//! reason for each in a JSON report.
//!
//! - Shards ([`shard`]): entry `k` of the manifest is in shard `k mod N`; each of the `N` runs
//!   of a CI matrix, Slurm job array or Kubernetes indexed Job bakes its own entries, and
//!   together they bake each entry once.
//! - Jobs: `--jobs J` threads take the shard's entries in manifest order; each bake is checked
//!   against the batch's budget (`--max-memory`, `--max-time`, as `bake` checks it), so the
//!   process holds at most `J` bakes of at most `--max-memory` each.
//! - Outputs: every base goes through the one atomic writer (a unique temporary renamed into
//!   place). Two runs baking the same entry at once both write complete, identical files, and
//!   the last rename wins: a reader sees one whole base, never a mix. A run killed mid-bake
//!   leaves its finished bases (up to date, skipped on the next run) and a temporary the next
//!   write of that base removes; SIGINT and SIGTERM remove the temporaries at once.
//! - The manifest is checked whole before any work ([`manifest`]), so every shard of a broken
//!   manifest refuses it the same way.

mod manifest;
mod shard;

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use clap::Args;
use modal_bake::bake::{self, BakeParams, BaseStatus};
use modal_bake::mesh::surface::is_surface_asset;

use self::manifest::Entry;
use self::shard::{Shard, ShardSpec};
use super::budget::BudgetOptions;

/// The most parallel bakes (`--jobs`).
const MAX_JOBS: usize = 256;

/// Arguments of `modal-bake batch`.
#[derive(Args)]
#[command(
    after_help = "Manifest (JSON, or TOML for a .toml file; paths relative to its folder):\n  \
    {\"version\": 1, \"entries\": [{\"mesh\": \"chair.obj\", \"out\": \"bases/chair.modes\",\n    \
    \"options\": {\"material\": \"oak\", \"modes\": 30}}]}\n\
    `options` are `modal-bake bake` options by long name (a value, true for a flag, an array \
    for a list or a repeated option). Each entry is checked as `modal-bake check` would: an \
    up-to-date base is skipped, a missing or stale one is baked. Shards are 0-based: entry k \
    is in shard k mod N. Recipes for CI matrices, Slurm arrays and Kubernetes indexed Jobs: \
    docs/farm.md. Exit 0 when every entry of the shard is up to date or baked, 1 otherwise."
)]
pub struct BatchArgs {
    /// The manifest: JSON (or TOML for a .toml file) listing {mesh, out, options} entries.
    pub manifest: PathBuf,
    /// Bake only shard I of N (0-based: 0/N … N−1/N); entry k of the manifest is in shard
    /// k mod N. `env:NAME/N` reads I from the environment variable NAME (e.g.
    /// env:JOB_COMPLETION_INDEX/8, env:SLURM_ARRAY_TASK_ID/8) [default: the whole manifest].
    #[arg(long, value_name = "I/N", value_parser = shard::parse)]
    pub shard: Option<ShardSpec>,
    /// Bakes run at once (1 … 256); each is held to --max-memory and --max-time.
    #[arg(short = 'j', long, value_name = "J", default_value_t = 1)]
    pub jobs: usize,
    /// Write the JSON report (one record per entry of the shard) to this file.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Check the manifest and list the shard's entries (index, mesh, output) without checking
    /// or baking any base and without writing anything.
    #[arg(long)]
    pub dry_run: bool,
    #[command(flatten)]
    pub budget: BudgetOptions,
}

/// What became of one entry.
#[derive(Clone, Debug, serde::Serialize)]
struct EntryRecord {
    /// `entries[index]` of the manifest.
    index: usize,
    mesh: String,
    out: String,
    /// `skipped` (up to date), `baked`, or `failed`.
    action: &'static str,
    /// The base's status before the run (`check`'s reasons: up_to_date, missing, unreadable,
    /// tool_changed, geometry_changed, parameters_changed, transfer_table_changed); null when
    /// the mesh could not be checked.
    reason: Option<&'static str>,
    /// What made the base stale, by the options that change it, or why it was unreadable;
    /// null when up to date or missing.
    detail: Option<String>,
    /// Why the entry failed.
    error: Option<String>,
}

/// A progress line (stderr, terminal and logs alike).
fn line(start: Instant, text: &str) {
    eprintln!("batch [{:7.1} s] {text}", start.elapsed().as_secs_f64());
}

pub fn run(args: &BatchArgs) -> anyhow::Result<ExitCode> {
    args.budget.budget()?;
    if !(1..=MAX_JOBS).contains(&args.jobs) {
        anyhow::bail!(
            "--jobs {} must be 1 … {MAX_JOBS} (each job may use up to --max-memory)",
            args.jobs
        );
    }
    let shard = match &args.shard {
        Some(spec) => spec.resolve().map_err(anyhow::Error::msg)?,
        None => Shard::whole(),
    };
    let entries = manifest::read_manifest(&args.manifest, &args.budget, args.report.as_deref())?;
    let mine: Vec<&Entry> = entries.iter().filter(|e| shard.contains(e.index)).collect();
    if args.dry_run {
        return dry_run(args, &shard, &mine, entries.len());
    }
    let start = Instant::now();
    let jobs = args.jobs.min(mine.len().max(1));
    line(
        start,
        &format!(
            "{}: shard {shard} ({}): {} of {} entries, {jobs} job{}",
            args.manifest.display(),
            shard.source,
            mine.len(),
            entries.len(),
            if jobs == 1 { "" } else { "s" }
        ),
    );
    let records = run_entries(&mine, args.jobs, start);
    let count = |a: &str| records.iter().filter(|r| r.action == a).count();
    let (skipped, baked, failed) = (count("skipped"), count("baked"), count("failed"));
    let report = serde_json::json!({
        "manifest": args.manifest.display().to_string(),
        "shard": {"index": shard.index, "count": shard.count, "source": shard.source},
        "entries": records,
        "totals": {"entries": records.len(), "skipped": skipped, "baked": baked, "failed": failed},
    });
    let text = serde_json::to_string_pretty(&report)? + "\n";
    if let Some(path) = &args.report {
        super::create_parent(path)?;
        dcr_files::write_atomic(path, text.as_bytes())?;
    }
    line(
        start,
        &format!(
            "shard {shard}: {} entries: {baked} baked, {skipped} up to date, {failed} failed",
            records.len()
        ),
    );
    if args.json {
        super::emit(&text);
    } else {
        for r in &records {
            match r.action {
                "failed" => outln!(
                    "entries[{}] {}: failed: {}",
                    r.index,
                    r.out,
                    r.error.as_deref().unwrap_or("")
                ),
                action => outln!(
                    "entries[{}] {}: {action} ({})",
                    r.index,
                    r.out,
                    r.reason.unwrap_or("").replace('_', " ")
                ),
            }
        }
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// `--dry-run`: the shard's entries (index, mesh, output) on stdout, nothing checked or written.
fn dry_run(
    args: &BatchArgs,
    shard: &Shard,
    mine: &[&Entry],
    total: usize,
) -> anyhow::Result<ExitCode> {
    if args.json {
        let list: Vec<_> = mine
            .iter()
            .map(|e| {
                serde_json::json!({
                    "index": e.index,
                    "mesh": e.args.mesh.display().to_string(),
                    "out": e.args.out.display().to_string(),
                })
            })
            .collect();
        let v = serde_json::json!({
            "manifest": args.manifest.display().to_string(),
            "shard": {"index": shard.index, "count": shard.count, "source": shard.source},
            "entries": list,
        });
        outln!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        outln!(
            "{}: valid; shard {shard} ({}): {} of {total} entries",
            args.manifest.display(),
            shard.source,
            mine.len()
        );
        for e in mine {
            outln!(
                "entries[{}] {} -> {}",
                e.index,
                e.args.mesh.display(),
                e.args.out.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Runs the entries on `jobs` threads, each taking the next entry in order; the records in
/// the entries' order.
fn run_entries(entries: &[&Entry], jobs: usize, start: Instant) -> Vec<EntryRecord> {
    let next = AtomicUsize::new(0);
    let records: Mutex<Vec<Option<EntryRecord>>> = Mutex::new(vec![None; entries.len()]);
    let total = entries.len();
    std::thread::scope(|scope| {
        for _ in 0..jobs.min(total.max(1)) {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(entry) = entries.get(k) else {
                    break;
                };
                let tag = format!("[{}/{total}] entries[{}]", k + 1, entry.index);
                // A bake never panics on input; should one, the other entries still run.
                let record = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    run_entry(entry, &tag, start)
                }))
                .unwrap_or_else(|_| {
                    let mut r = record_of(entry, "failed", None);
                    r.error = Some("internal error (a panic, reported above)".into());
                    line(start, &format!("{tag} {}: FAILED: internal error", r.out));
                    r
                });
                if let Ok(mut all) = records.lock() {
                    all[k] = Some(record);
                }
            });
        }
    });
    let all = match records.into_inner() {
        Ok(r) => r,
        Err(poisoned) => poisoned.into_inner(),
    };
    all.into_iter().flatten().collect()
}

fn record_of(entry: &Entry, action: &'static str, reason: Option<&'static str>) -> EntryRecord {
    EntryRecord {
        index: entry.index,
        mesh: entry.args.mesh.display().to_string(),
        out: entry.args.out.display().to_string(),
        action,
        reason,
        detail: None,
        error: None,
    }
}

/// Checks one entry's base and bakes it unless it is up to date.
fn run_entry(entry: &Entry, tag: &str, start: Instant) -> EntryRecord {
    let args = &entry.args;
    let t = Instant::now();
    line(
        start,
        &format!(
            "{tag} {} → {}: checking",
            args.mesh.display(),
            args.out.display()
        ),
    );
    let mut status_seen = None;
    let result = (|| -> anyhow::Result<(BaseStatus, bool)> {
        let table = args.transfer.transfer_h.is_some();
        let asset = super::bake::asset_for(&args.asset, table, &args.mesh);
        let params = BakeParams {
            transfer: args.transfer.params(),
            ..args.options.params()
        };
        if super::bake::unchanged_asset_up_to_date(&args.mesh, &asset, &params, &args.out)? {
            line(
                start,
                &format!(
                    "{tag} {}: the asset's surface, options, meshers and build are the base's: not meshed again",
                    args.out.display()
                ),
            );
            status_seen = Some(("up_to_date", None));
            return Ok((BaseStatus::UpToDate, false));
        }
        if is_surface_asset(&args.mesh) {
            args.budget.check_surface(
                &args.mesh,
                &asset,
                args.options.modes_for_estimate(),
                args.table_modes(),
            )?;
        }
        let loaded = super::bake::load_mesh(&args.mesh, &asset)?;
        let (mesh, read_s) = (loaded.mesh, loaded.seconds);
        let file = args.mesh.display().to_string();
        let status = bake::mesh_base_status(mesh.clone(), &file, &params, &args.out)?;
        // Read before the bake replaces the base.
        let detail = super::bake::stale_detail(&status, &args.out, &asset);
        status_seen = Some((status.reason(), detail.clone()));
        if status == BaseStatus::UpToDate {
            return Ok((status, false));
        }
        line(
            start,
            &format!(
                "{tag} {}: stale ({}{}): baking",
                args.out.display(),
                status.reason().replace('_', " "),
                detail.map(|d| format!(": {d}")).unwrap_or_default()
            ),
        );
        if let Some(w) = args.options.model.default_material_warning() {
            eprintln!("warning: {}: {w}", args.mesh.display());
        }
        let mut stage_name = "";
        let provenance = super::bake::Provenance {
            mesh_choice: None,
            asset_key: loaded.asset_key,
        };
        super::bake::bake_and_write(args, &asset, provenance, &params, mesh, read_s, &mut |s| {
            // Long bakes say which stage they are in.
            let name = s.label();
            if name != stage_name && t.elapsed().as_secs_f64() >= 5.0 {
                line(start, &format!("{tag} {}: {name}", args.out.display()));
            }
            stage_name = name;
        })?;
        Ok((status, true))
    })();
    let seconds = t.elapsed().as_secs_f64();
    match result {
        Ok((status, baked)) => {
            let mut r = record_of(
                entry,
                if baked { "baked" } else { "skipped" },
                Some(status.reason()),
            );
            r.detail = status_seen.and_then(|(_, d)| d);
            line(
                start,
                &format!(
                    "{tag} {}: {} in {seconds:.1} s",
                    args.out.display(),
                    if baked {
                        "baked"
                    } else {
                        "up to date, skipped"
                    }
                ),
            );
            r
        }
        Err(e) => {
            let (reason, detail) = status_seen.unzip();
            let mut r = record_of(entry, "failed", reason);
            r.detail = detail.flatten();
            let msg = super::one_line(&e);
            line(
                start,
                &format!("{tag} {}: FAILED: {msg}", args.out.display()),
            );
            r.error = Some(msg);
            r
        }
    }
}
