//! meshio-style JSON reader.
//!
//! Layout (meshio's JSON-compatible form): `points` (n×3 numbers, m), `cells` a list of
//! `{"type", "data"}` blocks with 0-based point indices (`tetra` for 4-node tetrahedra,
//! `tetra10` for 10-node ones in meshio's (VTK's) node order, `triangle` / `triangle6`; other
//! volume cells refused, other types skipped with a note), and optional named groups as meshio
//! `cell_sets` (`{name: [per-block lists of cell indices]}`) or gmsh-style
//! `cell_data["gmsh:physical"]` (per-block tag lists) with `field_data` (`{name: [tag, dim]}`).
//!
//! Cell types: `cell_info` gives each known type's node count (the width every row of its
//! block must have) and dimension (for `gmsh:physical` names); `CellFiler` decides what a
//! block becomes (`tetra` → tetrahedra, `triangle` → triangles, another volume cell an error,
//! anything else a note). Both
//! readers below go through these two, so a new cell type is a row in `cell_info` and an arm
//! in `CellFiler::file`.

use std::collections::BTreeMap;

use serde_json::Value;

use super::mesh_builder::MeshBuilder;
use super::mesh_error::{Location, MeshError, MeshErrorKind};
use super::tet_mesh::TetMesh;

/// Node count and dimension of a meshio cell type.
fn cell_info(ty: &str) -> Option<(usize, i32)> {
    Some(match ty {
        "vertex" => (1, 0),
        "line" => (2, 1),
        "line3" => (3, 1),
        "triangle" => (3, 2),
        "triangle6" => (6, 2),
        "quad" => (4, 2),
        "quad8" => (8, 2),
        "quad9" => (9, 2),
        "tetra" => (4, 3),
        "tetra10" => (10, 3),
        "hexahedron" => (8, 3),
        "hexahedron20" => (20, 3),
        "hexahedron27" => (27, 3),
        "wedge" => (6, 3),
        "pyramid" => (5, 3),
        _ => return None,
    })
}

/// Files cell blocks into a [`MeshBuilder`] by type — the one place a meshio cell type is
/// dispatched (both readers use it): `tetra` → `MeshBuilder::push_tet` (ids are 1-based
/// positions across `tetra` blocks), `triangle` → `MeshBuilder::push_triangle`, every other
/// type counted, one note per type in order of first appearance (other volume cells —
/// `hexahedron`, `wedge`, `pyramid`, `polyhedron*`, ... — make the build fail). Rows have the width
/// [`cell_info`] gives their type (checked by the readers).
#[derive(Default)]
struct CellFiler {
    tet_id: u64,
    /// (what, count, whether they are volume cells).
    skipped: Vec<(String, u64, bool)>,
}

impl CellFiler {
    fn file<'r>(
        &mut self,
        builder: &mut MeshBuilder,
        ty: &str,
        rows: impl ExactSizeIterator<Item = &'r [usize]>,
    ) {
        match ty {
            "tetra" => {
                for row in rows {
                    self.tet_id += 1;
                    builder.push_tet(self.tet_id, [row[0], row[1], row[2], row[3]]);
                }
            }
            "tetra10" => {
                for row in rows {
                    self.tet_id += 1;
                    builder.push_tet10(self.tet_id, tetra10_to_gmsh(row));
                }
            }
            "triangle" | "triangle6" => {
                for row in rows {
                    builder.push_triangle([row[0], row[1], row[2]]);
                }
            }
            other => {
                let what = format!("of type {other:?}");
                let n = rows.len() as u64;
                let volume = cell_info(other).is_some_and(|(_, dim)| dim == 3)
                    || other.starts_with("polyhedron");
                match self.skipped.iter_mut().find(|s| s.0 == what) {
                    Some(s) => s.1 += n,
                    None => self.skipped.push((what, n, volume)),
                }
            }
        }
    }

    /// Records the skipped types as notes.
    fn finish(self, builder: &mut MeshBuilder) {
        for (what, n, volume) in &self.skipped {
            let noun = if *n == 1 { "cell" } else { "cells" };
            builder.skip(&format!("{noun} {what}"), *n, *volume);
        }
    }
}

/// One cell block as read: its type and rows of point indices.
struct Block {
    ty: String,
    dim: Option<i32>,
    rows: Vec<Vec<usize>>,
}

struct JsonReader<'a> {
    file: &'a str,
}

impl JsonReader<'_> {
    fn err(&self, path: impl Into<String>, kind: MeshErrorKind) -> MeshError {
        MeshError::new(self.file, Location::Path(path.into()), kind)
    }

    fn shape(&self, path: impl Into<String>, msg: impl Into<String>) -> MeshError {
        self.err(path, MeshErrorKind::Shape(msg.into()))
    }

    fn array<'v>(&self, v: &'v Value, path: &str, what: &str) -> Result<&'v [Value], MeshError> {
        v.as_array().map(Vec::as_slice).ok_or_else(|| {
            self.shape(
                path,
                format!("{what} must be an array, found {}", kind_of(v)),
            )
        })
    }

    /// A non-negative integer index.
    fn index(&self, v: &Value, path: &str) -> Result<u64, MeshError> {
        if let Some(i) = v.as_u64() {
            return Ok(i);
        }
        if let Some(i) = v.as_i64() {
            return Err(self.err(path, MeshErrorKind::NegativeIndex(i)));
        }
        Err(self.shape(
            path,
            format!("expected an integer index, found {}", kind_of(v)),
        ))
    }

    fn points(&self, root: &Value) -> Result<Vec<(u64, [f64; 3])>, MeshError> {
        let points = root
            .get("points")
            .ok_or_else(|| self.err("points", MeshErrorKind::MissingSection("\"points\"")))?;
        let rows = self.array(points, "points", "\"points\"")?;
        let mut nodes = Vec::with_capacity(rows.len());
        for (i, row) in rows.iter().enumerate() {
            let path = format!("points[{i}]");
            let row = self.array(row, &path, "a point")?;
            if row.len() != 3 {
                return Err(self.shape(
                    &path,
                    format!("a point must have 3 coordinates, found {}", row.len()),
                ));
            }
            let mut x = [0.0; 3];
            for (k, v) in row.iter().enumerate() {
                x[k] = v.as_f64().ok_or_else(|| {
                    self.shape(
                        format!("{path}[{k}]"),
                        format!("expected a number, found {}", kind_of(v)),
                    )
                })?;
            }
            if !x.iter().all(|v| v.is_finite()) {
                return Err(self.err(path, MeshErrorKind::NonFiniteCoordinate { node: i as u64 }));
            }
            nodes.push((i as u64, x));
        }
        Ok(nodes)
    }

    fn blocks(&self, root: &Value, npoints: usize) -> Result<Vec<Block>, MeshError> {
        let cells = root
            .get("cells")
            .ok_or_else(|| self.err("cells", MeshErrorKind::MissingSection("\"cells\"")))?;
        let cells = self.array(cells, "cells", "\"cells\"")?;
        let mut blocks = Vec::with_capacity(cells.len());
        for (b, cell) in cells.iter().enumerate() {
            let path = format!("cells[{b}]");
            let ty = cell
                .get("type")
                .and_then(Value::as_str)
                .ok_or_else(|| self.shape(&path, "a cell block needs a string \"type\""))?;
            let data = cell
                .get("data")
                .ok_or_else(|| self.shape(&path, "a cell block needs a \"data\" array"))?;
            let data = self.array(data, &format!("{path}.data"), "\"data\"")?;
            let info = cell_info(ty);
            let mut rows = Vec::with_capacity(data.len());
            for (r, row) in data.iter().enumerate() {
                let rpath = format!("{path}.data[{r}]");
                let row = self.array(row, &rpath, "a cell")?;
                let want = info.map_or(rows.first().map_or(row.len(), Vec::len), |i| i.0);
                if row.len() != want || row.is_empty() {
                    return Err(self.shape(
                        &rpath,
                        format!(
                            "a {ty:?} cell must have {want} node indices, found {}",
                            row.len()
                        ),
                    ));
                }
                let mut ids = Vec::with_capacity(row.len());
                for (k, v) in row.iter().enumerate() {
                    let node = self.index(v, &format!("{rpath}[{k}]"))?;
                    if node >= npoints as u64 {
                        return Err(self.err(
                            &rpath,
                            MeshErrorKind::MissingNode {
                                element: r as u64 + 1,
                                node,
                            },
                        ));
                    }
                    ids.push(node as usize);
                }
                rows.push(ids);
            }
            blocks.push(Block {
                ty: ty.to_string(),
                dim: info.map(|i| i.1),
                rows,
            });
        }
        Ok(blocks)
    }

    /// meshio `cell_sets`: `{name: [per-block cell index lists or null]}`.
    fn cell_sets(
        &self,
        root: &Value,
        blocks: &[Block],
        builder: &mut MeshBuilder,
    ) -> Result<(), MeshError> {
        let Some(sets) = root.get("cell_sets") else {
            return Ok(());
        };
        let sets = sets
            .as_object()
            .ok_or_else(|| self.shape("cell_sets", "\"cell_sets\" must be an object"))?;
        for (name, per_block) in sets {
            let path = format!("cell_sets[{name:?}]");
            let per_block = self.array(per_block, &path, "a cell set")?;
            if per_block.len() != blocks.len() {
                return Err(self.shape(
                    &path,
                    format!(
                        "a cell set needs one entry per cell block ({}), found {}",
                        blocks.len(),
                        per_block.len()
                    ),
                ));
            }
            let mut nodes = Vec::new();
            for (b, (list, block)) in per_block.iter().zip(blocks).enumerate() {
                if list.is_null() {
                    continue;
                }
                let bpath = format!("{path}[{b}]");
                for (k, v) in self
                    .array(list, &bpath, "a cell index list")?
                    .iter()
                    .enumerate()
                {
                    let ipath = format!("{bpath}[{k}]");
                    let i = self.index(v, &ipath)?;
                    let row = usize::try_from(i)
                        .ok()
                        .and_then(|i| block.rows.get(i))
                        .ok_or_else(|| {
                            self.shape(
                                &ipath,
                                format!(
                                    "cell index {i} out of range (block has {} cells)",
                                    block.rows.len()
                                ),
                            )
                        })?;
                    nodes.extend_from_slice(row);
                }
            }
            builder.add_to_group(name, &nodes);
        }
        Ok(())
    }

    /// Group names by (dimension, tag) from `field_data` (`{name: [tag, dim]}`), if present.
    fn field_names(
        &self,
        field_data: Option<&Value>,
    ) -> Result<BTreeMap<(i64, i64), String>, MeshError> {
        let mut names = BTreeMap::new();
        if let Some(fields) = field_data {
            let fields = fields
                .as_object()
                .ok_or_else(|| self.shape("field_data", "\"field_data\" must be an object"))?;
            for (name, v) in fields {
                let path = format!("field_data[{name:?}]");
                let pair = self.array(v, &path, "a field_data entry")?;
                let (Some(tag), Some(dim)) = (
                    pair.first().and_then(Value::as_i64),
                    pair.get(1).and_then(Value::as_i64),
                ) else {
                    return Err(self.shape(path, "a field_data entry must be [tag, dim] integers"));
                };
                names.insert((dim, tag), name.clone());
            }
        }
        Ok(names)
    }

    /// `cell_data["gmsh:physical"]` (per-block tag lists) named through `field_data`.
    fn gmsh_physical(
        &self,
        root: &Value,
        blocks: &[Block],
        builder: &mut MeshBuilder,
    ) -> Result<(), MeshError> {
        let Some(tags) = root.get("cell_data").and_then(|d| d.get("gmsh:physical")) else {
            return Ok(());
        };
        let names = self.field_names(root.get("field_data"))?;
        let path = "cell_data[\"gmsh:physical\"]";
        let per_block = self.array(tags, path, "\"gmsh:physical\"")?;
        if per_block.len() != blocks.len() {
            return Err(self.shape(
                path,
                format!(
                    "\"gmsh:physical\" needs one list per cell block ({}), found {}",
                    blocks.len(),
                    per_block.len()
                ),
            ));
        }
        let mut members: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        for (b, (list, block)) in per_block.iter().zip(blocks).enumerate() {
            let bpath = format!("{path}[{b}]");
            let list = self.array(list, &bpath, "a tag list")?;
            if list.len() != block.rows.len() {
                return Err(self.shape(
                    &bpath,
                    format!(
                        "one tag per cell needed ({}), found {}",
                        block.rows.len(),
                        list.len()
                    ),
                ));
            }
            for (k, (v, row)) in list.iter().zip(&block.rows).enumerate() {
                let tag = v.as_i64().ok_or_else(|| {
                    self.shape(
                        format!("{bpath}[{k}]"),
                        format!("expected an integer tag, found {}", kind_of(v)),
                    )
                })?;
                if tag == 0 {
                    continue;
                }
                let dim = i64::from(block.dim.unwrap_or(-1));
                let name = names
                    .get(&(dim, tag))
                    .cloned()
                    .unwrap_or_else(|| tag.to_string());
                members.entry(name).or_default().extend_from_slice(row);
            }
        }
        for (name, nodes) in members {
            builder.add_to_group(&name, &nodes);
        }
        Ok(())
    }
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Reads a meshio-style JSON mesh from memory; `file` names it in errors.
///
/// Two readers, one result: the typed reader ([`fast::parse`]) deserializes straight into flat
/// buffers (faster than building a `serde_json::Value` tree; docs/benchmarks.md, "Design
/// measurements"), and
/// refuses — without a message — anything but a well-formed mesh; the document reader
/// ([`parse_json_dom`]) then reads the input again to find and locate the error (or, for the
/// rare valid layouts the typed reader does not take, e.g. duplicated keys, to read it). Errors
/// are therefore exactly the document reader's, and a mesh the typed reader accepts is the one
/// the document reader would build (`tests::typed_reader_equals_document_reader`).
pub(crate) fn parse_json(data: &[u8], file: &str) -> Result<TetMesh, MeshError> {
    match fast::parse(data, file) {
        Some(mesh) => Ok(mesh),
        None => parse_json_dom(data, file),
    }
}

/// The document reader: parses into a `serde_json::Value` and walks it, naming the JSON path
/// (or the line, for syntax errors) of the first error.
pub(crate) fn parse_json_dom(data: &[u8], file: &str) -> Result<TetMesh, MeshError> {
    let r = JsonReader { file };
    let root: Value = serde_json::from_slice(data).map_err(|e| {
        let msg = e.to_string();
        let msg = msg
            .find(" at line ")
            .map_or(msg.clone(), |i| msg[..i].to_string());
        MeshError::new(file, Location::Line(e.line()), MeshErrorKind::Json(msg))
    })?;
    if !root.is_object() {
        return Err(r.shape(
            "(root)",
            format!("expected a JSON object, found {}", kind_of(&root)),
        ));
    }
    let nodes = r.points(&root)?;
    let npoints = nodes.len();
    let mut builder = MeshBuilder::default();
    builder
        .set_nodes(nodes)
        .map_err(|kind| r.err("points", kind))?;
    let blocks = r.blocks(&root, npoints)?;
    let mut cells = CellFiler::default();
    for block in &blocks {
        cells.file(
            &mut builder,
            &block.ty,
            block.rows.iter().map(Vec::as_slice),
        );
    }
    cells.finish(&mut builder);
    r.cell_sets(&root, &blocks, &mut builder)?;
    r.gmsh_physical(&root, &blocks, &mut builder)?;
    builder.finish(file)
}

/// A meshio `tetra10` row (VTK order: corners, then edges (0,1), (1,2), (0,2), (0,3), (1,3),
/// (2,3)) in gmsh's type-11 order (its last two mid-edge nodes swapped: (2,3) then (1,3)).
fn tetra10_to_gmsh(row: &[usize]) -> [usize; 10] {
    [
        row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7], row[9], row[8],
    ]
}

/// The typed reader: serde visitors that write points and cell rows straight into flat
/// buffers. It returns `None` on anything but a well-formed mesh and never builds an error;
/// [`parse_json`] then falls back on [`parse_json_dom`]. To accept exactly what the document
/// reader accepts, every value goes through the same `serde_json` number and string parsing
/// (values it does not use are parsed as `Value`, not skipped: serde_json's skipping neither
/// range-checks numbers nor limits nesting), and layouts whose document reading depends on
/// `serde_json::Map` (a repeated key) are left to the document reader.
mod fast {
    use std::collections::{BTreeMap, BTreeSet};
    use std::fmt;

    use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
    use serde_json::Value;

    use super::{cell_info, CellFiler, JsonReader, MeshBuilder, TetMesh};

    /// One `cells` block: its type and `width` node indices per row, row after row.
    struct Block {
        ty: String,
        width: usize,
        data: Vec<usize>,
    }

    impl Block {
        fn rows(&self) -> std::slice::ChunksExact<'_, usize> {
            // Width 0 only for a block without rows (rows are never empty).
            self.data.chunks_exact(self.width.max(1))
        }

        /// Row `i`, if the block has it.
        fn row(&self, i: usize) -> Option<&[usize]> {
            (i < self.rows().len()).then(|| &self.data[i * self.width..(i + 1) * self.width])
        }
    }

    /// `cell_sets` as read: (name, per-block cell index list or `null`).
    type Sets = Vec<(String, Vec<Option<Vec<u64>>>)>;

    /// The parts of the document the reader uses.
    #[derive(Default)]
    struct Doc {
        points: Option<Vec<[f64; 3]>>,
        cells: Option<Vec<Block>>,
        cell_sets: Option<Sets>,
        /// `cell_data["gmsh:physical"]`.
        physical: Option<Vec<Vec<i64>>>,
        field_data: Option<Value>,
    }

    /// Refusal: the message is never shown (the document reader reports the error).
    fn refuse<E: de::Error>() -> E {
        E::custom("not a well-formed mesh")
    }

    /// Stores `v` in an empty slot; a repeated key is refused.
    fn once<T, E: de::Error>(slot: &mut Option<T>, v: T) -> Result<(), E> {
        match slot.replace(v) {
            None => Ok(()),
            Some(_) => Err(refuse()),
        }
    }

    struct RootVisitor;

    impl<'de> Visitor<'de> for RootVisitor {
        type Value = Doc;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a meshio JSON object")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Doc, A::Error> {
            let mut doc = Doc::default();
            let mut keys = BTreeSet::new();
            while let Some(key) = map.next_key::<String>()? {
                // A repeated key, even an unused one, is left to the document reader.
                if !keys.insert(key.clone()) {
                    return Err(refuse());
                }
                match key.as_str() {
                    "points" => once(&mut doc.points, map.next_value_seed(Points)?)?,
                    "cells" => once(&mut doc.cells, map.next_value_seed(Cells)?)?,
                    "cell_sets" => once(&mut doc.cell_sets, map.next_value_seed(CellSets)?)?,
                    "cell_data" => {
                        if let Some(tags) = map.next_value_seed(CellData)? {
                            once(&mut doc.physical, tags)?;
                        }
                    }
                    "field_data" => once(&mut doc.field_data, map.next_value::<Value>()?)?,
                    _ => {
                        map.next_value::<Value>()?;
                    }
                }
            }
            Ok(doc)
        }
    }

    /// `points`: rows of exactly three numbers.
    struct Points;

    impl<'de> DeserializeSeed<'de> for Points {
        type Value = Vec<[f64; 3]>;

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_seq(self)
        }
    }

    impl<'de> Visitor<'de> for Points {
        type Value = Vec<[f64; 3]>;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("an array of points")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut out = Vec::new();
            while let Some(x) = seq.next_element_seed(Point)? {
                out.push(x);
            }
            Ok(out)
        }
    }

    struct Point;

    impl<'de> DeserializeSeed<'de> for Point {
        type Value = [f64; 3];

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<[f64; 3], D::Error> {
            d.deserialize_seq(self)
        }
    }

    impl<'de> Visitor<'de> for Point {
        type Value = [f64; 3];

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("three coordinates")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; 3], A::Error> {
            let mut x = [0.0; 3];
            for v in &mut x {
                *v = seq.next_element::<f64>()?.ok_or_else(refuse)?;
            }
            match seq.next_element::<Value>()? {
                None => Ok(x),
                Some(_) => Err(refuse()),
            }
        }
    }

    /// `cells`: an array of blocks.
    struct Cells;

    impl<'de> DeserializeSeed<'de> for Cells {
        type Value = Vec<Block>;

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Vec<Block>, D::Error> {
            d.deserialize_seq(self)
        }
    }

    impl<'de> Visitor<'de> for Cells {
        type Value = Vec<Block>;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("an array of cell blocks")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<Block>, A::Error> {
            let mut out = Vec::new();
            while let Some(b) = seq.next_element_seed(BlockSeed)? {
                out.push(b);
            }
            Ok(out)
        }
    }

    /// One block `{"type": ..., "data": [[...], ...]}`, keys in any order.
    struct BlockSeed;

    impl<'de> DeserializeSeed<'de> for BlockSeed {
        type Value = Block;

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Block, D::Error> {
            d.deserialize_map(self)
        }
    }

    impl<'de> Visitor<'de> for BlockSeed {
        type Value = Block;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a cell block")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Block, A::Error> {
            let (mut ty, mut data) = (None, None);
            while let Some(key) = map.next_key::<String>()? {
                match key.as_str() {
                    "type" => once(&mut ty, map.next_value::<String>()?)?,
                    "data" => once(&mut data, map.next_value_seed(Rows)?)?,
                    _ => {
                        map.next_value::<Value>()?;
                    }
                }
            }
            let (Some(ty), Some((width, data))) = (ty, data) else {
                return Err(refuse());
            };
            Ok(Block { ty, width, data })
        }
    }

    /// Rows of node indices, all of one non-zero width: (width, flat indices).
    struct Rows;

    impl<'de> DeserializeSeed<'de> for Rows {
        type Value = (usize, Vec<usize>);

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_seq(self)
        }
    }

    impl<'de> Visitor<'de> for Rows {
        type Value = (usize, Vec<usize>);

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("rows of node indices")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut data = Vec::new();
            let mut width = None;
            while let Some(n) = seq.next_element_seed(Row(&mut data))? {
                if n == 0 || *width.get_or_insert(n) != n {
                    return Err(refuse());
                }
            }
            Ok((width.unwrap_or(0), data))
        }
    }

    /// One row, appended to the flat index buffer; its length.
    struct Row<'a>(&'a mut Vec<usize>);

    impl<'de> DeserializeSeed<'de> for Row<'_> {
        type Value = usize;

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<usize, D::Error> {
            d.deserialize_seq(self)
        }
    }

    impl<'de> Visitor<'de> for Row<'_> {
        type Value = usize;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a row of node indices")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<usize, A::Error> {
            let mut n = 0;
            // `u64` takes exactly the JSON numbers `Value::as_u64` takes (non-negative
            // integers), as the document reader requires.
            while let Some(v) = seq.next_element::<u64>()? {
                self.0.push(usize::try_from(v).map_err(|_| refuse())?);
                n += 1;
            }
            Ok(n)
        }
    }

    /// `cell_sets`: `{name: [per-block index list or null]}`, names unique.
    struct CellSets;

    impl<'de> DeserializeSeed<'de> for CellSets {
        type Value = Sets;

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Sets, D::Error> {
            d.deserialize_map(self)
        }
    }

    impl<'de> Visitor<'de> for CellSets {
        type Value = Sets;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("cell sets")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Sets, A::Error> {
            let mut out = Vec::new();
            let mut names = BTreeSet::new();
            while let Some(name) = map.next_key::<String>()? {
                if !names.insert(name.clone()) {
                    return Err(refuse());
                }
                out.push((name, map.next_value()?));
            }
            Ok(out)
        }
    }

    /// `cell_data` (an object): its `gmsh:physical` tag lists, if any.
    struct CellData;

    impl<'de> DeserializeSeed<'de> for CellData {
        type Value = Option<Vec<Vec<i64>>>;

        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_map(self)
        }
    }

    impl<'de> Visitor<'de> for CellData {
        type Value = Option<Vec<Vec<i64>>>;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("cell data")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut tags = None;
            let mut keys = BTreeSet::new();
            while let Some(key) = map.next_key::<String>()? {
                if !keys.insert(key.clone()) {
                    return Err(refuse());
                }
                if key == "gmsh:physical" {
                    // `i64` takes exactly what `Value::as_i64` takes.
                    tags = Some(map.next_value::<Vec<Vec<i64>>>()?);
                } else {
                    map.next_value::<Value>()?;
                }
            }
            Ok(tags)
        }
    }

    /// The typed read of a well-formed mesh; `None` for anything else (see the module docs).
    pub(super) fn parse(data: &[u8], file: &str) -> Option<TetMesh> {
        let mut de = serde_json::Deserializer::from_slice(data);
        let doc = de.deserialize_map(RootVisitor).ok()?;
        de.end().ok()?;
        let points = doc.points?;
        let blocks = doc.cells?;
        if !points.iter().flatten().all(|v| v.is_finite()) {
            return None;
        }
        let npoints = points.len();
        let mut dims = Vec::with_capacity(blocks.len());
        for b in &blocks {
            let info = cell_info(&b.ty);
            if info.is_some_and(|(w, _)| !b.data.is_empty() && b.width != w)
                || b.data.iter().any(|&v| v >= npoints)
            {
                return None;
            }
            dims.push(i64::from(info.map_or(-1, |i| i.1)));
        }

        let mut builder = MeshBuilder::default();
        builder
            .set_nodes(
                points
                    .into_iter()
                    .enumerate()
                    .map(|(i, x)| (i as u64, x))
                    .collect(),
            )
            .ok()?;
        let mut cells = CellFiler::default();
        for block in &blocks {
            cells.file(&mut builder, &block.ty, block.rows());
        }
        cells.finish(&mut builder);

        for (name, per_block) in doc.cell_sets.unwrap_or_default() {
            if per_block.len() != blocks.len() {
                return None;
            }
            let mut nodes = Vec::new();
            for (list, block) in per_block.iter().zip(&blocks) {
                for &i in list.iter().flatten() {
                    let row = usize::try_from(i).ok().and_then(|i| block.row(i))?;
                    nodes.extend_from_slice(row);
                }
            }
            builder.add_to_group(&name, &nodes);
        }

        if let Some(per_block) = doc.physical {
            let reader = JsonReader { file };
            let names = reader.field_names(doc.field_data.as_ref()).ok()?;
            if per_block.len() != blocks.len() {
                return None;
            }
            let mut members: BTreeMap<String, Vec<usize>> = BTreeMap::new();
            for ((tags, block), &dim) in per_block.iter().zip(&blocks).zip(&dims) {
                if tags.len() != block.rows().len() {
                    return None;
                }
                for (&tag, row) in tags.iter().zip(block.rows()) {
                    if tag == 0 {
                        continue;
                    }
                    let name = names
                        .get(&(dim, tag))
                        .cloned()
                        .unwrap_or_else(|| tag.to_string());
                    members.entry(name).or_default().extend_from_slice(row);
                }
            }
            for (name, nodes) in members {
                builder.add_to_group(&name, &nodes);
            }
        }
        builder.finish(file).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(rel: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data")
            .join(rel)
    }

    /// The typed reader accepts `bytes` and builds the document reader's mesh, bit for bit.
    fn assert_typed_equals_document(bytes: &[u8], what: &str) -> TetMesh {
        let typed = fast::parse(bytes, "t.json").unwrap_or_else(|| panic!("{what}: refused"));
        let doc = parse_json_dom(bytes, "t.json").unwrap();
        assert_same(&typed, &doc, what);
        typed
    }

    fn assert_same(a: &TetMesh, b: &TetMesh, what: &str) {
        let bits = |m: &TetMesh| -> Vec<[u64; 3]> {
            m.nodes.iter().map(|x| x.map(f64::to_bits)).collect()
        };
        assert_eq!(bits(a), bits(b), "{what}: nodes");
        assert_eq!(a, b, "{what}");
    }

    /// Whatever the bytes, [`parse_json`] (typed reader first) gives exactly the document
    /// reader's result, and the typed reader never accepts what the document reader refuses.
    fn assert_agrees(bytes: &[u8], what: &str) {
        let doc = parse_json_dom(bytes, "t.json");
        if let Some(typed) = fast::parse(bytes, "t.json") {
            let doc = doc
                .as_ref()
                .unwrap_or_else(|e| panic!("{what}: typed accepts, document says {e}"));
            assert_same(&typed, doc, what);
        }
        assert_eq!(parse_json(bytes, "t.json"), doc, "{what}");
    }

    /// A structured box as the bake bench writes it (points, a tetra and a vertex block,
    /// `cell_sets`), with coordinates perturbed to arbitrary bit patterns so that every
    /// digit of the shortest round-trip form is exercised.
    fn bench_like_json() -> Vec<u8> {
        let mut mesh = TetMesh::structured_box([5, 3, 2], [2.0, 0.7, 0.3]);
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        for x in mesh.nodes.iter_mut().flatten() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            *x += (state >> 11) as f64 * 2f64.powi(-53) * 1e-3;
        }
        let v = mesh.to_meshio_json("xmin", "clamp");
        serde_json::to_vec(&v).unwrap()
    }

    #[test]
    fn typed_reader_equals_document_reader() {
        for rel in [
            "meshes/cube_cell_sets.json",
            "meshes/cube_gmsh_physical.json",
        ] {
            let bytes = std::fs::read(data(rel)).unwrap();
            let m = assert_typed_equals_document(&bytes, rel);
            assert!(!m.groups.is_empty(), "{rel}: groups");
        }
        let bench = bench_like_json();
        let m = assert_typed_equals_document(&bench, "bench-like box");
        assert_eq!(m.groups["clamp"].len(), 12);
        // Keys in another order, numbers written as integers, exponents and long decimals,
        // unused keys (parsed, not skipped), and a `null` cell-set entry.
        let text = r#"{"meta": {"x": [1, 2.5e300, null]},
            "cells": [{"data": [[0, 1, 2, 3], [1, 2, 3, 4]], "type": "tetra", "note": "v"},
                      {"data": [[0, 1]], "type": "line"},
                      {"type": "polygon7", "data": [[0, 1, 2, 3, 4, 0, 1]]},
                      {"type": "triangle", "data": []}],
            "points": [[0, 0, 0], [1, 0.0, -0], [0, 1e0, 0.0], [0, 0, 1.00000000000000000000001],
                       [0.1234567890123456789, 1.7976931348623157e308, -2.2250738585072014e-308]],
            "cell_sets": {"a": [[1], null, [0], []], "b": [null, [0], null, null]}}"#;
        let m = assert_typed_equals_document(text.as_bytes(), "reordered");
        assert_eq!(m.groups["b"], vec![0, 1]);
        assert_eq!(m.notes.len(), 2, "{:?}", m.notes);
    }

    /// Inputs the typed reader leaves to the document reader, valid or not: the result is
    /// the document reader's (same mesh, or same located error).
    #[test]
    fn refused_inputs_get_the_document_readers_result() {
        let ok = r#"{"points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
                     "cells": [{"type": "tetra", "data": [[0,1,2,3]]}]"#;
        let cases = [
            // Valid, but left to the document reader (its `Map` keeps the last of a key).
            format!(r#"{ok}, "cell_data": [1, 2]}}"#),
            format!(r#"{ok}, "cell_sets": {{"a": [[0]]}}, "cell_sets": {{"b": [[0]]}}}}"#),
            format!(r#"{ok}, "cell_data": {{"gmsh:physical": [[3]]}}, "cell_data": {{}}}}"#),
            format!(r#"{ok}, "x": 1, "x": 2}}"#),
            // Invalid.
            format!(r#"{ok}, "cell_sets": {{"a": [[1]]}}}}"#),
            format!(r#"{ok}, "cell_sets": {{"a": [[0], []]}}}}"#),
            format!(r#"{ok}, "cell_data": {{"gmsh:physical": [[1.5]]}}}}"#),
            format!(r#"{ok}, "cell_data": {{"gmsh:physical": [[1]]}}, "field_data": 3}}"#),
            format!(r#"{ok}, "ignored": [1e999]}}"#),
            format!(
                r#"{ok}, "ignored": {}1{}}}"#,
                "[".repeat(200),
                "]".repeat(200)
            ),
            r#"{"points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
                "cells": [{"type": "tetra", "data": [[0,1,2,3.0]]}]}"#
                .to_string(),
            r#"{"points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
                "cells": [{"type": "tetra", "data": [[0,1,2,3,0]]}]}"#
                .to_string(),
            r#"{"points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
                "cells": [{"type": "polygon", "data": [[0,1,2],[0,1]]}]}"#
                .to_string(),
            r#"{"points": [], "cells": []}"#.to_string(),
            "[1, 2]".to_string(),
        ];
        for (i, text) in cases.iter().enumerate() {
            assert_agrees(text.as_bytes(), &format!("case {i}: {text}"));
        }
        for entry in std::fs::read_dir(data("bad")).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                let bytes = std::fs::read(&path).unwrap();
                assert!(fast::parse(&bytes, "t.json").is_none(), "{path:?}");
                assert_agrees(&bytes, &path.display().to_string());
            }
        }
    }

    /// Truncations and byte corruptions of valid files: the two readers never disagree.
    #[test]
    fn corrupted_inputs_agree() {
        let mut files = vec![bench_like_json()];
        for rel in [
            "meshes/cube_cell_sets.json",
            "meshes/cube_gmsh_physical.json",
        ] {
            files.push(std::fs::read(data(rel)).unwrap());
        }
        for bytes in &files {
            for cut in (0..bytes.len()).step_by(97) {
                assert_agrees(&bytes[..cut], &format!("prefix {cut}"));
            }
            for (i, at) in (0..bytes.len()).step_by(89).enumerate() {
                let mut b = bytes.clone();
                b[at] = [b'9', b'-', b'.', b'e', b'"', b'[', b']', b',', b'n'][i % 9];
                assert_agrees(&b, &format!("byte {at} replaced"));
            }
        }
    }
}
