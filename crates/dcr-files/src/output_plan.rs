//! The output policy every writing command applies before it writes anything: all of a
//! command's outputs are declared together with its inputs in an [`OutputPlan`], which refuses
//! (naming the option and the path)
//! - an output that is one of the inputs (the same file: a hard link, a symbolic link to it or
//!   another spelling such as `./sub/../BASE`, or on Windows `BASE.MODES`, count),
//! - an output that exists as anything but a regular file (a folder, a device, a FIFO, a
//!   socket: renaming a file over a device node would replace the node),
//! - a path that names no file (`.`, `..`, a trailing `/`) or whose nearest existing ancestor
//!   is not a folder,
//! - two outputs on one path (both options named), existing or not.
//!
//! The files themselves are then written through [`crate::AtomicFile`], which checks the type
//! of the destination again at the rename.

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

use crate::file_type::{describe_file_type, file_id, FileId};

/// Why an output path is refused ([`OutputPlan::output`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The output is one of the command's inputs.
    #[error("{option} {path} is {what} {input}; refusing to overwrite an input (choose another output path)")]
    IsInput {
        /// The option (or role) that names the output (`--vtu`, `-o`).
        option: String,
        /// The output path.
        path: PathBuf,
        /// What the input is (`the input`, `the base`, `the scene file`).
        what: String,
        /// The input path.
        input: PathBuf,
    },
    /// The output exists and is not a regular file.
    #[error("{option} {path} is {what}; give the path of a file to write")]
    NotRegular {
        /// The option.
        option: String,
        /// The output path.
        path: PathBuf,
        /// What it is ("a directory", "a FIFO", ...).
        what: &'static str,
    },
    /// The path names no file (`.`, `..`, empty, or ends in `/`).
    #[error("{option} {path:?} names a folder, not a file; give the path of a file to write (e.g. {example})")]
    NoFileName {
        /// The option.
        option: String,
        /// The output path.
        path: PathBuf,
        /// An example path of the right kind.
        example: String,
    },
    /// A folder the outputs go into exists as something else.
    #[error("{option} {path} is {what}; give the path of a folder (created when missing)")]
    NotAFolder {
        /// The option.
        option: String,
        /// The path.
        path: PathBuf,
        /// What it is ("a regular file", "a FIFO", ...).
        what: &'static str,
    },
    /// An ancestor of the output exists and is not a folder.
    #[error("{option} {path}: {ancestor} is {what}, not a folder")]
    AncestorNotFolder {
        /// The option.
        option: String,
        /// The output path.
        path: PathBuf,
        /// The ancestor.
        ancestor: PathBuf,
        /// What it is.
        what: &'static str,
    },
    /// Two outputs of the command name one file.
    #[error("{option} {path} and {other_option} {other} name the same file; give each output its own path")]
    SamePath {
        /// The option declared second.
        option: String,
        /// Its path.
        path: PathBuf,
        /// The option declared first.
        other_option: String,
        /// Its path.
        other: PathBuf,
    },
}

/// The inputs and outputs of one command, checked against each other before anything is
/// written (see the module docs).
///
/// ```
/// use dcr_files::OutputPlan;
/// let dir = tempfile::tempdir().unwrap();
/// let base = dir.path().join("a.modes");
/// std::fs::write(&base, b"base").unwrap();
/// let mut plan = OutputPlan::new();
/// plan.input("the base", &base);
/// assert!(plan.output("--vtu", &dir.path().join("a.vtu")).is_ok());
/// assert!(plan.output("--gltf", &base).is_err()); // the input
/// assert!(plan.output("--png", &dir.path().join("./a.vtu")).is_err()); // --vtu's path
/// ```
#[derive(Clone, Debug, Default)]
pub struct OutputPlan {
    inputs: Vec<(String, PathBuf)>,
    /// The first input of each existing file, by identity (a plan may hold a manifest's
    /// tens of thousands of paths: each check is a lookup, not a scan).
    input_ids: HashMap<FileId, usize>,
    /// (option, path as given, normalised path).
    outputs: Vec<(String, PathBuf, PathBuf)>,
    /// The output of each normalised path and of each existing file's identity.
    output_norms: HashMap<PathBuf, usize>,
    output_ids: HashMap<FileId, usize>,
    /// Folders outputs go into: (option, path as given, normalised path).
    folders: Vec<(String, PathBuf, PathBuf)>,
}

impl OutputPlan {
    /// An empty plan.
    pub fn new() -> OutputPlan {
        OutputPlan::default()
    }

    /// Declares an input the outputs must not overwrite; `what` says what it is in messages
    /// (`the input`, `the base`, `the scene file`). Declare the inputs before the outputs.
    pub fn input(&mut self, what: &str, path: &Path) -> &mut OutputPlan {
        if let Some(id) = file_id(path) {
            self.input_ids.entry(id).or_insert(self.inputs.len());
        }
        self.inputs.push((what.to_string(), path.to_path_buf()));
        self
    }

    /// Declares and checks an output named by `option`.
    ///
    /// # Errors
    /// [`OutputError`]: the output is an input, exists as a non-regular file, names no file,
    /// sits under a non-folder, or is the path of an output declared before.
    pub fn output(&mut self, option: &str, path: &Path) -> Result<(), OutputError> {
        let id = file_id(path);
        let input = id
            .as_ref()
            .and_then(|id| self.input_ids.get(id))
            .map(|&i| &self.inputs[i]);
        check_output_path(option, path, input)?;
        let norm = normalise(path);
        let earlier = self
            .output_norms
            .get(&norm)
            .or_else(|| id.as_ref().and_then(|id| self.output_ids.get(id)));
        if let Some(&i) = earlier {
            let (other_option, other, _) = &self.outputs[i];
            return Err(OutputError::SamePath {
                option: option.to_string(),
                path: path.to_path_buf(),
                other_option: other_option.clone(),
                other: other.clone(),
            });
        }
        for (other_option, other, other_norm) in &self.folders {
            if *other_norm == norm {
                return Err(OutputError::SamePath {
                    option: option.to_string(),
                    path: path.to_path_buf(),
                    other_option: format!("{other_option} (a folder)"),
                    other: other.clone(),
                });
            }
        }
        self.output_norms.insert(norm.clone(), self.outputs.len());
        if let Some(id) = id {
            self.output_ids.insert(id, self.outputs.len());
        }
        self.outputs
            .push((option.to_string(), path.to_path_buf(), norm));
        Ok(())
    }

    /// Declares and checks a folder named by `option` that outputs will be written into
    /// (created when missing): it must not exist as anything but a folder, and its nearest
    /// existing ancestor must be a folder.
    ///
    /// # Errors
    /// [`OutputError::NotAFolder`], [`OutputError::AncestorNotFolder`], or
    /// [`OutputError::SamePath`] when it is (or lies under) an output declared before; an
    /// output declared later on the folder's path is refused the same way.
    pub fn output_folder(&mut self, option: &str, dir: &Path) -> Result<(), OutputError> {
        let norm = normalise(dir);
        for (other_option, other, other_norm) in &self.outputs {
            if *other_norm == norm || norm.starts_with(other_norm) {
                return Err(OutputError::SamePath {
                    option: format!("{option} (a folder)"),
                    path: dir.to_path_buf(),
                    other_option: other_option.clone(),
                    other: other.clone(),
                });
            }
        }
        self.folders
            .push((option.to_string(), dir.to_path_buf(), norm));
        match std::fs::metadata(dir) {
            Ok(meta) if meta.is_dir() => return Ok(()),
            Ok(meta) => {
                return Err(OutputError::NotAFolder {
                    option: option.to_string(),
                    path: dir.to_path_buf(),
                    what: describe_file_type(meta.file_type()),
                })
            }
            Err(_) => {}
        }
        check_ancestors(option, dir, dir.parent())
    }

    /// The outputs declared so far: (option, path).
    pub fn outputs(&self) -> impl Iterator<Item = (&str, &Path)> {
        self.outputs
            .iter()
            .map(|(o, p, _)| (o.as_str(), p.as_path()))
    }
}

/// Checks one output path: not `input` (what, path: the input it is the same file as, if
/// any), not an existing non-regular file, names a file, its nearest existing ancestor a
/// folder.
fn check_output_path(
    option: &str,
    path: &Path,
    input: Option<&(String, PathBuf)>,
) -> Result<(), OutputError> {
    let names_file = !path.as_os_str().is_empty()
        && !path
            .as_os_str()
            .to_string_lossy()
            .ends_with(std::path::is_separator)
        && matches!(path.components().next_back(), Some(Component::Normal(_)));
    if !names_file {
        return Err(OutputError::NoFileName {
            option: option.to_string(),
            path: path.to_path_buf(),
            example: "out/result.ext".into(),
        });
    }
    if let Some((what, input)) = input {
        return Err(OutputError::IsInput {
            option: option.to_string(),
            path: path.to_path_buf(),
            what: what.clone(),
            input: input.clone(),
        });
    }
    if let Ok(meta) = std::fs::metadata(path) {
        if !meta.is_file() {
            return Err(OutputError::NotRegular {
                option: option.to_string(),
                path: path.to_path_buf(),
                what: describe_file_type(meta.file_type()),
            });
        }
    }
    check_ancestors(option, path, path.parent())
}

/// The nearest existing ancestor of `path` (from `first` up) must be a folder.
fn check_ancestors(option: &str, path: &Path, first: Option<&Path>) -> Result<(), OutputError> {
    let mut ancestor = first;
    while let Some(dir) = ancestor.filter(|d| !d.as_os_str().is_empty()) {
        match std::fs::metadata(dir) {
            Ok(meta) if meta.is_dir() => return Ok(()),
            Ok(meta) => {
                return Err(OutputError::AncestorNotFolder {
                    option: option.to_string(),
                    path: path.to_path_buf(),
                    ancestor: dir.to_path_buf(),
                    what: describe_file_type(meta.file_type()),
                })
            }
            Err(_) => ancestor = dir.parent(),
        }
    }
    Ok(())
}

/// `path` made absolute with its longest existing ancestor canonicalised (links and `..`
/// resolved by the file system) and the rest resolved lexically, so two spellings of one
/// file not yet written compare equal.
fn normalise(path: &Path) -> PathBuf {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()
            .unwrap_or_else(|_| PathBuf::from("/"))
            .join(path)
    };
    let mut existing = abs.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(c) = existing.canonicalize() {
            let mut out = c;
            for part in rest.iter().rev() {
                match part {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    other => out.push(other.as_os_str()),
                }
            }
            return out;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return abs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_one_new_file_collide() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("sub")).unwrap();
        let mut plan = OutputPlan::new();
        plan.output("--vtu", &d.join("x")).unwrap();
        let e = plan.output("--gltf", &d.join("sub/../x")).unwrap_err();
        assert!(
            e.to_string().contains("--vtu") && e.to_string().contains("--gltf"),
            "{e}"
        );
        let e = plan.output("--png", &d.join("./new/../x")).unwrap_err();
        assert!(matches!(e, OutputError::SamePath { .. }), "{e}");
        plan.output("--png", &d.join("y")).unwrap();
        // A file output on the path of a folder that will be created, and the reverse.
        plan.output_folder("--out", &d.join("run")).unwrap();
        assert!(plan.output("--gltf", &d.join("./run")).is_err());
        assert!(plan.output_folder("--out", &d.join("y/sub")).is_err());
    }

    #[test]
    fn inputs_folders_and_fifos_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let base = d.join("b.modes");
        std::fs::write(&base, b"x").unwrap();
        std::fs::create_dir(d.join("sub")).unwrap();
        let mut plan = OutputPlan::new();
        plan.input("the base", &base);
        for p in [d.join("sub/../b.modes"), d.join("sub/./../b.modes")] {
            assert!(matches!(
                plan.output("-o", &p),
                Err(OutputError::IsInput { .. })
            ));
        }
        assert!(matches!(
            plan.output("-o", &d.join("sub")),
            Err(OutputError::NotRegular { .. })
        ));
        assert!(matches!(
            plan.output("-o", Path::new(".")),
            Err(OutputError::NoFileName { .. })
        ));
        assert!(matches!(
            plan.output("-o", &d.join("b.modes/x")),
            Err(OutputError::AncestorNotFolder { .. })
        ));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&base, d.join("link")).unwrap();
            assert!(matches!(
                plan.output("-o", &d.join("link")),
                Err(OutputError::IsInput { .. })
            ));
        }
        // A hard link is the input under another name (Unix and Windows alike).
        std::fs::hard_link(&base, d.join("hard.modes")).unwrap();
        assert!(matches!(
            plan.output("-o", &d.join("hard.modes")),
            Err(OutputError::IsInput { .. })
        ));
        // On Windows the letter case does not name another file.
        #[cfg(windows)]
        assert!(matches!(
            plan.output("-o", &d.join("B.MODES")),
            Err(OutputError::IsInput { .. })
        ));
        // A trailing separator (`/`, and `\` on Windows) names a folder, not a file.
        let trailing = format!("{}{}", d.join("new").display(), std::path::MAIN_SEPARATOR);
        assert!(matches!(
            plan.output("-o", Path::new(&trailing)),
            Err(OutputError::NoFileName { .. })
        ));
        assert!(plan.output_folder("--out", &base).is_err());
        assert!(plan.output_folder("--out", &d.join("new/deeper")).is_ok());
    }
}
