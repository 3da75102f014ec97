//! The error every mesh reader and mesh check returns: file, location and kind.

use std::fmt;

/// Where in the input a [`MeshError`] was found.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// The whole file (or no file: a check on an in-memory mesh).
    None,
    /// 1-based line number in an ASCII file (or an ASCII header line of a binary file).
    Line(usize),
    /// 0-based byte offset in binary data.
    Byte(usize),
    /// An element tag (MSH) or 1-based tetrahedron index (JSON), for semantic errors.
    Element(u64),
    /// A path into a JSON document, e.g. `cells[1].data[3]`.
    Path(String),
    /// A 1-based node in canonical order (ascending file tag), for checks on positions.
    Node(u64),
}

/// A mesh that could not be read or fails a check, with the file name and a location.
///
/// Displays like `data/bad/nan_coordinate.msh:17: non-finite coordinate in node 5`.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct MeshError {
    /// The file (display name) the error is in; empty for checks on an in-memory mesh.
    pub file: String,
    /// Where in the file.
    pub location: Location,
    /// What went wrong.
    pub kind: MeshErrorKind,
}

/// What went wrong while reading or checking a mesh.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshErrorKind {
    /// The file could not be read.
    #[error("cannot read file: {0}")]
    Io(String),
    /// The path is not a regular file (a directory, device, FIFO or socket): meshes are read
    /// from regular files only, whose size bounds the read.
    #[error("not a regular file ({0}); give the path of a mesh file")]
    NotARegularFile(&'static str),
    /// Neither `$MeshFormat` nor a JSON object, and no known extension.
    #[error(
        "unrecognised mesh format: modal-bake reads volume meshes as gmsh .msh (2.2 or 4.1) or meshio-style .json and surface assets as .obj, .stl, .ply, .glb or .gltf; convert another volume mesh (VTK/VTU, Abaqus .inp, Medit .mesh, TetGen, ...) with meshio (`pip install meshio`, then `meshio convert IN OUT.msh -o gmsh`), export another surface format (FBX, 3MF, DAE, ...) as glTF or OBJ"
    )]
    UnknownFormat,
    /// A `.msh` that is an ANSYS Fluent mesh (it starts with `(`), not a gmsh one.
    #[error(
        "an ANSYS Fluent mesh (it starts with `(`), not a gmsh one: `meshio convert` writes this for a .msh name unless told the format; convert with `meshio convert IN OUT.msh -o gmsh`"
    )]
    FluentMsh,
    /// An MSH version other than 2.2 or 4.1.
    #[error("unsupported MSH version {0} (supported: 2.0–2.2 and 4.1); re-save it with gmsh: `gmsh IN.msh -save -format msh41 -o OUT.msh`")]
    UnsupportedVersion(String),
    /// gmsh's first file format (`$NOD` … `$ELM`), as Netgen's "Gmsh Format" export writes.
    #[error("gmsh's MSH 1 format (`$NOD` … `$ELM`), which is not read: re-save it with gmsh, `gmsh IN.msh -save -format msh41 -o OUT.msh` (from Netgen, export \"Gmsh2 Format\")")]
    Msh1,
    /// A binary data-size other than supported (8 for 2.2; 4 or 8 for 4.1).
    #[error("unsupported data-size {0} in $MeshFormat")]
    UnsupportedDataSize(u64),
    /// The binary endianness check integer is neither 1 little- nor big-endian.
    #[error("bad endianness check integer {0:#010x} (expected 1)")]
    BadEndianness(u32),
    /// The file ends where more data was expected.
    #[error("truncated file: expected {0}")]
    Truncated(&'static str),
    /// A field that should be a number is not.
    #[error("expected {expected}, found {found:?}")]
    NotANumber {
        /// What kind of number was expected ("integer", "coordinate").
        expected: &'static str,
        /// The text found instead (shortened).
        found: String,
    },
    /// A keyword or value other than the one the format requires.
    #[error("expected {expected}, found {found:?}")]
    Unexpected {
        /// What the format requires here.
        expected: String,
        /// What the file holds (shortened).
        found: String,
    },
    /// A node coordinate is NaN or infinite.
    #[error("non-finite coordinate in node {node}")]
    NonFiniteCoordinate {
        /// The node tag (MSH) or 0-based point index (JSON).
        node: u64,
    },
    /// Two nodes share one tag.
    #[error("duplicate node tag {node}")]
    DuplicateNode {
        /// The repeated node tag.
        node: u64,
    },
    /// An element names a node the file does not define.
    #[error("element {element} names node {node}, which does not exist")]
    MissingNode {
        /// The element tag (MSH) or 1-based index within its cell block (JSON).
        element: u64,
        /// The missing node tag (MSH) or point index (JSON).
        node: u64,
    },
    /// A binary element block of a gmsh element type this reader does not know the size of.
    #[error("unsupported gmsh element type {0} in binary data")]
    UnsupportedElementType(i64),
    /// A declared count larger than the rest of the file can hold, or one that overflows.
    #[error("declared {what} count {count} exceeds what the file can hold")]
    CountTooLarge {
        /// What is counted ("nodes", "elements", ...).
        what: &'static str,
        /// The declared count.
        count: u64,
    },
    /// A section total that disagrees with the sum of its blocks.
    #[error("declared {what} count {declared}, but the blocks hold {found}")]
    CountMismatch {
        /// What is counted.
        what: &'static str,
        /// The count in the section header.
        declared: u64,
        /// The count actually present.
        found: u64,
    },
    /// A required section is absent (or out of order).
    #[error("missing section {0}")]
    MissingSection(&'static str),
    /// A section a file holds once appears again.
    #[error("section ${section} appears a second time (the first is at line {first}); a mesh file holds it once")]
    DuplicateSection {
        /// The section name without `$`.
        section: &'static str,
        /// 1-based line of its first header.
        first: usize,
    },
    /// A section that must come after another one comes before it.
    #[error("section ${section} comes before ${before}, which it depends on")]
    SectionOrder {
        /// The section found too early.
        section: &'static str,
        /// The section that must precede it.
        before: &'static str,
    },
    /// A node or element tag that is zero or negative (gmsh tags start at 1).
    #[error("{what} {found} is not a positive tag (gmsh tags start at 1)")]
    InvalidTag {
        /// What the tag names ("node tag", "element tag", "element node tag").
        what: &'static str,
        /// The value found.
        found: String,
    },
    /// An ASCII record with more values than its layout has.
    #[error("extra value {found:?} at the end of {record} (expected the end of the line)")]
    ExtraValue {
        /// The record ("an element line", "the $Nodes header", ...).
        record: &'static str,
        /// The first extra token (shortened).
        found: String,
    },
    /// An ASCII record that ends (line break) before all its values.
    #[error("the line ends before its {0}")]
    ShortLine(&'static str),
    /// Two elements with the same four nodes in another order (one would count twice).
    #[error("elements {first} and {second} have the same four nodes (overlapping tetrahedra); remove one")]
    DuplicateTet {
        /// The first element's id (MSH tag, JSON 1-based position).
        first: u64,
        /// The second element's id.
        second: u64,
    },
    /// Two positively oriented tetrahedra share a face and lie on the same side of it.
    #[error(
        "elements {first} and {second} overlap: they share a face and lie on the same side of it"
    )]
    OverlappingTets {
        /// One element id.
        first: u64,
        /// The other element id.
        second: u64,
    },
    /// The file holds no 4-node or 10-node tetrahedra; `found` lists what it holds instead
    /// (counts and types, or "no elements") and `how` how to mesh what modal-bake bakes.
    #[error("no 4-node or 10-node tetrahedra in the mesh (it holds {found}): {how}")]
    NoTets {
        /// The elements the file holds instead, e.g. "726 triangles, 70 elements of gmsh
        /// type 1 (2-node line)".
        found: String,
        /// The fix: other volume elements meshed as tetrahedra of order 1 or 2, or a volume
        /// meshed at all.
        how: &'static str,
    },
    /// No tetrahedron of the file belongs to the object (a 3-D physical group) asked for.
    #[error("no tetrahedron belongs to the object {name:?}; the file's volumes (3-D physical groups): {available}")]
    UnknownObject {
        /// The name asked for.
        name: String,
        /// The 3-D physical groups the file's tetrahedra belong to, comma-separated.
        available: String,
    },
    /// An object was asked of a meshio JSON file, which has no physical volumes.
    #[error(
        "--object selects an object of a surface asset or a physical volume of a gmsh .msh, not of a meshio JSON mesh: select one of its connected pieces with --piece N, or write one object's cells per file"
    )]
    ObjectOfJson,
    /// The mesh has no connected piece of the number asked for (pieces are numbered from 1,
    /// largest volume first).
    #[error("no piece {asked}: the mesh has {count} connected piece(s), largest first: {list}")]
    NoSuchPiece {
        /// The piece number asked for.
        asked: usize,
        /// How many pieces the mesh has.
        count: usize,
        /// The pieces, largest first (number, tetrahedra, volume, bounding box).
        list: String,
    },
    /// The file holds volume elements other than 4- and 10-node tetrahedra (hexahedra, prisms,
    /// pyramids, higher-order tetrahedra) beside its tetrahedra: leaving them out would bake
    /// part of the object.
    #[error(
        "the mesh holds {found} beside its tetrahedra: only 4- and 10-node tetrahedra are baked, and leaving the others out would bake part of the object (a wrong mass and wrong modes); mesh the volume with tetrahedra only (gmsh: no `Recombine` in `Extrude`, `Mesh.RecombineAll = 0`, `Mesh.Recombine3DAll = 0`, element order 1 or 2)"
    )]
    OtherVolumeElements {
        /// The other volume elements, e.g. "12,342 6-node prisms (gmsh type 6)".
        found: String,
    },
    /// The file mixes 4-node and 10-node tetrahedra.
    #[error(
        "the mesh mixes {linear} 4-node and {quadratic} 10-node tetrahedra; use one element order"
    )]
    MixedOrder {
        /// 4-node tetrahedra found.
        linear: usize,
        /// 10-node tetrahedra found.
        quadratic: usize,
    },
    /// The JSON text does not parse.
    #[error("invalid JSON: {0}")]
    Json(String),
    /// A JSON value of the wrong type or shape (ragged rows, wrong lengths, ...).
    #[error("{0}")]
    Shape(String),
    /// A negative node index in JSON cells.
    #[error("negative node index {0}")]
    NegativeIndex(i64),
    /// A node coordinate outside ±[`dcr_runtime::format::MAX_COORDINATE_M`].
    #[error(
        "coordinate {value:e} m is outside the supported ±{max:e} m (bake expects metres: is the mesh in other units, or is this node misplaced?)"
    )]
    CoordinateOutOfRange {
        /// The coordinate (m).
        value: f64,
        /// The limit (m).
        max: f64,
    },
    /// A mesh smaller than [`dcr_runtime::format::MIN_EXTENT_M`].
    #[error("the mesh is {extent:e} m across (bounding-box diagonal); at least {min:e} m is supported (bake expects metres)")]
    TooSmall {
        /// Bounding-box diagonal (m).
        extent: f64,
        /// The limit (m).
        min: f64,
    },
    /// A tetrahedron of (near-)zero or NaN volume.
    #[error(
        "degenerate tetrahedron {element}: |volume| {volume:e} m³ below {threshold:e} m³ \
         (relative tolerance × mean tet volume)"
    )]
    DegenerateTet {
        /// The element id (see [`crate::mesh::TetMesh::tet_ids`]).
        element: u64,
        /// Its signed volume (m³), possibly NaN.
        volume: f64,
        /// The threshold it fell below (m³).
        threshold: f64,
    },
    /// A second-order tetrahedron with a mid-edge node off its edge's midpoint.
    #[error(
        "curved 10-node tetrahedron {element}: a mid-edge node is {offset:e} m off its edge's \
         midpoint (edge length {edge_length:e} m); only straight-sided second-order elements are \
         supported: bake it with --straighten (every mid-edge node moved to its edge's \
         midpoint: the boundary faceted at the corners, as `modal-bake mesh --order 2` makes it), \
         mesh with gmsh's `Mesh.SecondOrderLinear = 1`, or bake the linear mesh"
    )]
    CurvedTet {
        /// The element id (see [`crate::mesh::TetMesh::tet_ids`]).
        element: u64,
        /// Distance of the mid-edge node from the midpoint (m).
        offset: f64,
        /// Length of the edge (m).
        edge_length: f64,
    },
    /// Second-order tetrahedra that disagree on their shared edges' mid-edge nodes.
    #[error("non-conforming 10-node tetrahedron {element}: {detail}")]
    NonConforming {
        /// The element id (see [`crate::mesh::TetMesh::tet_ids`]).
        element: u64,
        /// What disagrees.
        detail: String,
    },
    /// A group name the mesh does not have.
    #[error(
        "no node group named {name:?}; available groups: {}",
        available_list(available)
    )]
    UnknownGroup {
        /// The requested name.
        name: String,
        /// The names the mesh has, sorted.
        available: Vec<String>,
    },
}

fn available_list(names: &[String]) -> String {
    if names.is_empty() {
        "(none)".to_string()
    } else {
        names.join(", ")
    }
}

impl MeshError {
    /// A new error in `file` at `location`.
    pub fn new(file: impl Into<String>, location: Location, kind: MeshErrorKind) -> MeshError {
        MeshError {
            file: file.into(),
            location,
            kind,
        }
    }

    /// What went wrong.
    pub fn kind(&self) -> &MeshErrorKind {
        &self.kind
    }
}

impl std::error::Error for MeshError {}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut sep = "";
        if !self.file.is_empty() {
            write!(f, "{}", self.file)?;
            sep = ": ";
        }
        match &self.location {
            Location::None => {}
            Location::Line(line) if !self.file.is_empty() => write!(f, ":{line}")?,
            Location::Line(line) => write!(f, "line {line}")?,
            Location::Byte(offset) => write!(f, "{sep}byte {offset}")?,
            Location::Element(id) => write!(f, "{sep}element {id}")?,
            Location::Path(path) => write!(f, "{sep}{path}")?,
            Location::Node(n) => write!(f, "{sep}node {n}")?,
        }
        if self.file.is_empty() && self.location == Location::None {
            write!(f, "{}", self.kind)
        } else {
            write!(f, ": {}", self.kind)
        }
    }
}

/// Shortens `text` for an error message (at most 40 characters, lossy UTF-8).
pub(crate) fn shorten(text: &[u8]) -> String {
    let s = String::from_utf8_lossy(&text[..text.len().min(40)]).into_owned();
    if text.len() > 40 {
        s + "…"
    } else {
        s
    }
}
