//! [`ModesAsset`] and its [`ModesLoader`]: a `.modes` base as a Bevy asset.
//!
//! The loader reads the bytes through bevy's asset reader and parses them with dcr-runtime's
//! format reader ([`dcr_runtime::format::ModesFile::read_from`]) and model builder
//! ([`ModalModel::from_base`]): the `.modes` format is defined once, in the runtime.

use std::io::Cursor;
use std::path::PathBuf;
use std::sync::Arc;

use bevy::asset::io::Reader;
use bevy::asset::{Asset, AssetLoader, LoadContext};
use bevy::reflect::TypePath;
use dcr_runtime::format::{FormatError, ModesFile};
use dcr_runtime::{LoadError, ModalModel};

/// A baked modal base (a `.modes` file), shared by every elastic entity that uses it.
///
/// Load it with `asset_server.load("table.modes")` and give the handle to a
/// [`crate::DcrElastic`]. The base's object frame is the frame of the mesh it was baked from
/// (m); on an entity it is the rigid body's local frame.
#[derive(Asset, TypePath, Debug, Clone)]
pub struct ModesAsset {
    /// The validated model (modes, surface, the per-vertex data the queries reuse).
    pub model: Arc<ModalModel>,
}

/// The [`AssetLoader`] for files ending in `.modes` (registered by [`crate::DcrPlugin`]).
#[derive(Debug, Default, Clone, Copy, TypePath)]
pub struct ModesLoader;

/// Why a `.modes` asset could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModesLoaderError {
    /// The asset source could not be read.
    #[error("{path}: could not read the asset: {source}")]
    Io {
        /// The asset's path in its source.
        path: PathBuf,
        /// What the reader said.
        #[source]
        source: std::io::Error,
    },
    /// Not a valid `.modes` archive (corrupt, truncated, wrong version, mismatched shapes,
    /// NaN): the runtime's error starts with the path and names the entry or value at fault.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// A readable base the runtime cannot build a model on (e.g. a degenerate surface).
    #[error("{path}: {detail}")]
    Invalid {
        /// The asset's path in its source.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
}

impl AssetLoader for ModesLoader {
    type Asset = ModesAsset;
    type Settings = ();
    type Error = ModesLoaderError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<ModesAsset, ModesLoaderError> {
        let path = load_context.path().path().to_path_buf();
        let mut bytes = Vec::new();
        if let Err(source) = reader.read_to_end(&mut bytes).await {
            return Err(ModesLoaderError::Io { path, source });
        }
        let base = ModesFile::read_from(Cursor::new(bytes), &path)?;
        let model = ModalModel::from_base(base).map_err(|e| match e {
            LoadError::Format(e) => ModesLoaderError::Format(e),
            LoadError::Invalid { detail, .. } => ModesLoaderError::Invalid { path, detail },
            other => ModesLoaderError::Invalid {
                path,
                detail: other.to_string(),
            },
        })?;
        Ok(ModesAsset {
            model: Arc::new(model),
        })
    }

    fn extensions(&self) -> &[&str] {
        &["modes"]
    }
}
