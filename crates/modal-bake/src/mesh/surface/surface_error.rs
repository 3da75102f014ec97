//! [`SurfaceError`]: why a surface asset cannot be meshed.

/// Why a surface asset (OBJ, STL, PLY, glTF) was refused. Every variant names the file; defects of
/// the surface give a position in metres (after the unit scaling) so it can be found in a
/// modelling tool.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceError {
    /// The file could not be read.
    #[error("{file}: cannot read file: {detail}")]
    Io {
        /// The file.
        file: String,
        /// What the operating system said.
        detail: String,
    },
    /// The extension is not one of `.obj`, `.stl`, `.ply`, `.glb`, `.gltf`; the message says
    /// what to do with the file (bake a volume mesh directly, convert another format).
    #[error(
        "{file}: unrecognised surface format (surface assets are .obj, .stl, .ply, .glb or .gltf): {}",
        format_hint(file)
    )]
    UnknownFormat {
        /// The file.
        file: String,
    },
    /// The format's parser refused the file.
    #[error("{file}: invalid {format} file: {detail}")]
    Parse {
        /// The file.
        file: String,
        /// `OBJ`, `STL`, `PLY` or `glTF`.
        format: &'static str,
        /// What the parser said.
        detail: String,
    },
    /// The named object (`--object`) is not in the file, is ambiguous, or the format has no
    /// named objects.
    #[error("{file}: {detail}")]
    Object {
        /// The file.
        file: String,
        /// What is wrong, with the names the file has.
        detail: String,
    },
    /// No triangle in the file.
    #[error("{file}: the file holds no triangles")]
    Empty {
        /// The file.
        file: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("{file}: vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The file.
        file: String,
        /// 0-based vertex index in the file.
        vertex: usize,
    },
    /// A face names a vertex that does not exist.
    #[error("{file}: face {face} names vertex {vertex}, but the file has {count} vertices")]
    BadIndex {
        /// The file.
        file: String,
        /// 0-based face index.
        face: usize,
        /// The index named.
        vertex: i64,
        /// Vertices in the file.
        count: usize,
    },
    /// A triangle with two equal corners or zero area.
    #[error("{file}: triangle {triangle} is degenerate (zero area) at ({:.6}, {:.6}, {:.6}) m", at[0], at[1], at[2])]
    Degenerate {
        /// The file.
        file: String,
        /// 0-based triangle index (after polygon triangulation).
        triangle: usize,
        /// Its first corner (m).
        at: [f64; 3],
    },
    /// An edge with one triangle: the surface has a hole.
    #[error(
        "{file}: the surface is not closed: open edge from ({:.6}, {:.6}, {:.6}) to ({:.6}, {:.6}, {:.6}) m \
         ({open_edges} open edges in all); fill the hole in the modelling tool",
        a[0], a[1], a[2], b[0], b[1], b[2]
    )]
    OpenEdge {
        /// The file.
        file: String,
        /// One end of the first open edge (m).
        a: [f64; 3],
        /// The other end (m).
        b: [f64; 3],
        /// Number of open edges.
        open_edges: usize,
    },
    /// An edge shared by more than two triangles.
    #[error(
        "{file}: non-manifold edge from ({:.6}, {:.6}, {:.6}) to ({:.6}, {:.6}, {:.6}) m, shared by {triangles} triangles",
        a[0], a[1], a[2], b[0], b[1], b[2]
    )]
    NonManifoldEdge {
        /// The file.
        file: String,
        /// One end (m).
        a: [f64; 3],
        /// The other end (m).
        b: [f64; 3],
        /// Triangles on the edge.
        triangles: usize,
    },
    /// A vertex where two separate fans of triangles touch (e.g. two cones tip to tip).
    #[error("{file}: non-manifold vertex at ({:.6}, {:.6}, {:.6}) m: {fans} separate fans of triangles meet there", at[0], at[1], at[2])]
    NonManifoldVertex {
        /// The file.
        file: String,
        /// Its position (m).
        at: [f64; 3],
        /// Fans meeting at it.
        fans: usize,
    },
    /// Two neighbouring triangles with opposite orientations.
    #[error(
        "{file}: inconsistent orientation: the two triangles on the edge from ({:.6}, {:.6}, {:.6}) to ({:.6}, {:.6}, {:.6}) m \
         run the same way (recalculate normals in the modelling tool)",
        a[0], a[1], a[2], b[0], b[1], b[2]
    )]
    Orientation {
        /// The file.
        file: String,
        /// One end (m).
        a: [f64; 3],
        /// The other end (m).
        b: [f64; 3],
    },
    /// Several separate closed shells.
    #[error("{file}: the surface has {shells} separate closed shells; export and bake each object on its own")]
    Shells {
        /// The file.
        file: String,
        /// Number of shells.
        shells: usize,
    },
}

/// What to do with `file`, which is not a surface asset, by its extension.
fn format_hint(file: &str) -> String {
    let ext = std::path::Path::new(file)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("msh" | "json") => format!(
            "{file} is a volume mesh, meshed already: bake it directly (`modal-bake bake {file} -o OUT.modes`; `modal-bake info {file}` summarises it first)"
        ),
        _ => "export another format (FBX, 3MF, DAE, …) as glTF or OBJ (Blender: File ▸ Export); convert a surface in VTK, VTU or OFF with meshio (`pip install meshio`, `meshio convert IN OUT.stl`)".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::SurfaceError;

    // Expectation: a volume mesh given where a surface asset is read is told to bake it
    // directly; another format is told how to convert it.
    #[test]
    fn an_unknown_surface_format_is_told_what_to_do() {
        let text = |file: &str| SurfaceError::UnknownFormat { file: file.into() }.to_string();
        assert!(text("t5.msh").contains("`modal-bake bake t5.msh -o OUT.modes`"));
        assert!(text("m.JSON").contains("is a volume mesh"));
        for file in ["chair.fbx", "part.3mf", "s.vtu"] {
            let t = text(file);
            assert!(
                t.starts_with(file) && t.contains("as glTF or OBJ") && t.contains("meshio convert"),
                "{t}"
            );
        }
    }
}
