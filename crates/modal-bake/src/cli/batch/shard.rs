//! Shards of a manifest: `--shard I/N` puts entry `k` (its 0-based position in the manifest)
//! in shard `k mod N`, so every entry is in exactly one of the shards `0/N … (N−1)/N`, the
//! shards differ in size by at most one entry, and the split depends on nothing but the
//! manifest's order. `I` may be read from an environment variable the farm sets
//! (`--shard env:JOB_COMPLETION_INDEX/8`), never implicitly.

use std::fmt;

/// The largest shard count accepted (more shards than entries leaves some empty).
pub const MAX_SHARDS: u64 = 1_000_000;

/// Where the shard index comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ShardIndex {
    /// Given on the command line.
    Given(u64),
    /// Read from this environment variable when the batch starts.
    Env(String),
}

/// A `--shard` value as given: the index (or its variable) and the shard count.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShardSpec {
    /// The 0-based shard index, or the variable holding it.
    pub index: ShardIndex,
    /// The number of shards N ≥ 1.
    pub count: u64,
}

/// A resolved shard: index `I` (0 ≤ I < N) of `N`, and where `I` came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shard {
    /// The 0-based index.
    pub index: u64,
    /// The shard count.
    pub count: u64,
    /// `--shard`, or `$NAME` when the index came from an environment variable.
    pub source: String,
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The whole manifest as one shard (no `--shard`).
    pub fn whole() -> Shard {
        Shard {
            index: 0,
            count: 1,
            source: "no --shard: the whole manifest".into(),
        }
    }

    /// Whether the entry at 0-based manifest position `k` belongs to this shard.
    pub fn contains(&self, k: usize) -> bool {
        k as u64 % self.count == self.index
    }
}

/// Parses `I/N` or `env:NAME/N` (clap value parser).
///
/// # Errors
/// A message saying what is wrong and the accepted forms.
pub fn parse(s: &str) -> Result<ShardSpec, String> {
    let forms = "expected I/N with 0 ≤ I < N (0-based, e.g. 0/4 … 3/4) or env:NAME/N \
                 (I read from the variable NAME, e.g. env:JOB_COMPLETION_INDEX/4)";
    let (i, n) = s
        .trim()
        .rsplit_once('/')
        .ok_or_else(|| format!("`{s}`: {forms}"))?;
    let count: u64 = n
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: the shard count `{n}` is not a whole number; {forms}"))?;
    if count == 0 || count > MAX_SHARDS {
        return Err(format!(
            "`{s}`: the shard count must be 1 … {MAX_SHARDS}, got {count}"
        ));
    }
    let index = match i.trim().strip_prefix("env:") {
        Some(name) => {
            let valid =
                !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !valid {
                return Err(format!(
                    "`{s}`: `{name}` is not an environment variable name (letters, digits, _)"
                ));
            }
            ShardIndex::Env(name.to_string())
        }
        None => {
            let index: u64 = i.trim().parse().map_err(|_| {
                format!("`{s}`: the shard index `{i}` is not a whole number; {forms}")
            })?;
            check_index(index, count).map_err(|e| format!("`{s}`: {e}"))?;
            ShardIndex::Given(index)
        }
    };
    Ok(ShardSpec { index, count })
}

fn check_index(index: u64, count: u64) -> Result<(), String> {
    if index >= count {
        return Err(format!(
            "the shard index {index} is not below the shard count {count} (indices are 0-based: 0 … {})",
            count - 1
        ));
    }
    Ok(())
}

impl ShardSpec {
    /// The shard, reading the index from its environment variable when it names one.
    ///
    /// # Errors
    /// The variable unset, not a whole number, or not below the count (message names it).
    pub fn resolve(&self) -> Result<Shard, String> {
        match &self.index {
            ShardIndex::Given(i) => Ok(Shard {
                index: *i,
                count: self.count,
                source: "--shard".into(),
            }),
            ShardIndex::Env(name) => {
                let raw = std::env::var(name).map_err(|_| {
                    format!(
                        "--shard env:{name}/{}: the environment variable {name} is not set \
                         (Kubernetes indexed Jobs set JOB_COMPLETION_INDEX, Slurm job arrays \
                         SLURM_ARRAY_TASK_ID; or give the index, --shard I/{})",
                        self.count, self.count
                    )
                })?;
                let index: u64 = raw.trim().parse().map_err(|_| {
                    format!(
                        "--shard env:{name}/{}: {name}={raw:?} is not a whole number",
                        self.count
                    )
                })?;
                check_index(index, self.count).map_err(|e| {
                    format!(
                        "--shard env:{name}/{}: {name}={index}: {e}; a Slurm array must start at 0 (--array=0-{})",
                        self.count,
                        self.count - 1
                    )
                })?;
                if name == "SLURM_ARRAY_TASK_ID" {
                    check_slurm_array(self.count)?;
                }
                Ok(Shard {
                    index,
                    count: self.count,
                    source: format!("${name}"),
                })
            }
        }
    }
}

/// A Slurm array must be numbered 0 … N−1 for `SLURM_ARRAY_TASK_ID` to be the shard index:
/// `SLURM_ARRAY_TASK_MIN` (when set) must be 0 and `SLURM_ARRAY_TASK_COUNT` (when set) N, or
/// some entries would silently belong to no task.
fn check_slurm_array(count: u64) -> Result<(), String> {
    let var = |n: &str| {
        std::env::var(n)
            .ok()
            .and_then(|v| v.trim().parse::<u64>().ok())
    };
    if let Some(min) = var("SLURM_ARRAY_TASK_MIN").filter(|&m| m != 0) {
        return Err(format!(
            "--shard env:SLURM_ARRAY_TASK_ID/{count}: the job array starts at {min} (SLURM_ARRAY_TASK_MIN); \
             number it from 0 (--array=0-{}) so that every shard runs",
            count - 1
        ));
    }
    if let Some(tasks) = var("SLURM_ARRAY_TASK_COUNT").filter(|&t| t != count) {
        return Err(format!(
            "--shard env:SLURM_ARRAY_TASK_ID/{count}: the job array has {tasks} tasks (SLURM_ARRAY_TASK_COUNT), \
             not {count}; give --shard env:SLURM_ARRAY_TASK_ID/{tasks} or --array=0-{}",
            count - 1
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_position_is_in_exactly_one_shard() {
        for count in [1u64, 2, 3, 7, 50] {
            let shards: Vec<Shard> = (0..count)
                .map(|index| Shard {
                    index,
                    count,
                    source: String::new(),
                })
                .collect();
            let mut sizes = vec![0usize; count as usize];
            for k in 0..103 {
                let owners: Vec<_> = shards.iter().filter(|s| s.contains(k)).collect();
                assert_eq!(owners.len(), 1, "position {k} of {count} shards");
                sizes[owners[0].index as usize] += 1;
            }
            let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
            assert!(hi - lo <= 1, "{count} shards: sizes {sizes:?}");
        }
    }

    #[test]
    fn parses_the_forms_and_refuses_the_rest() {
        assert_eq!(
            parse("2/5").unwrap(),
            ShardSpec {
                index: ShardIndex::Given(2),
                count: 5
            }
        );
        assert_eq!(
            parse("env:JOB_COMPLETION_INDEX/8").unwrap().index,
            ShardIndex::Env("JOB_COMPLETION_INDEX".into())
        );
        for bad in [
            "5/5",
            "1/0",
            "-1/4",
            "a/4",
            "3",
            "0/1e9",
            "env:/4",
            "env:A B/4",
            "0/2000000",
        ] {
            let e = parse(bad).unwrap_err();
            assert!(e.contains(bad), "{bad}: {e}");
        }
    }

    #[test]
    fn an_index_from_the_environment_is_checked() {
        let name = "DCR_TEST_SHARD_INDEX_FARM";
        let spec = parse(&format!("env:{name}/4")).unwrap();
        // Unset: refused, naming the variable.
        std::env::remove_var(name);
        assert!(spec.resolve().unwrap_err().contains(name));
        std::env::set_var(name, "3");
        let shard = spec.resolve().unwrap();
        assert_eq!((shard.index, shard.count), (3, 4));
        assert_eq!(shard.source, format!("${name}"));
        for bad in ["4", "x", "-1"] {
            std::env::set_var(name, bad);
            assert!(spec.resolve().unwrap_err().contains(name), "{bad}");
        }
        std::env::remove_var(name);

        // A Slurm array not numbered 0 … N−1 is refused (some entries would run nowhere).
        let slurm = parse("env:SLURM_ARRAY_TASK_ID/4").unwrap();
        std::env::set_var("SLURM_ARRAY_TASK_ID", "2");
        std::env::set_var("SLURM_ARRAY_TASK_MIN", "1");
        assert!(slurm.resolve().unwrap_err().contains("starts at 1"));
        std::env::set_var("SLURM_ARRAY_TASK_MIN", "0");
        std::env::set_var("SLURM_ARRAY_TASK_COUNT", "3");
        assert!(slurm.resolve().unwrap_err().contains("3 tasks"));
        std::env::set_var("SLURM_ARRAY_TASK_COUNT", "4");
        assert_eq!(slurm.resolve().unwrap().index, 2);
        for v in [
            "SLURM_ARRAY_TASK_ID",
            "SLURM_ARRAY_TASK_MIN",
            "SLURM_ARRAY_TASK_COUNT",
        ] {
            std::env::remove_var(v);
        }
    }
}
