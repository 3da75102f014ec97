//! meshio-style JSON reader.
//!
//! Layout (meshio's JSON-compatible form): `points` (n×3 numbers, m), `cells` a list of
//! `{"type", "data"}` blocks with 0-based point indices (`tetra` for 4-node tetrahedra,
//! `triangle`; other types skipped with a note), and optional named groups as meshio
//! `cell_sets` (`{name: [per-block lists of cell indices]}`) or gmsh-style
//! `cell_data["gmsh:physical"]` (per-block tag lists) with `field_data` (`{name: [tag, dim]}`).

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
        let mut names = BTreeMap::new();
        if let Some(fields) = root.get("field_data") {
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
pub(crate) fn parse_json(data: &[u8], file: &str) -> Result<TetMesh, MeshError> {
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
    let mut tet_id = 0u64;
    let mut skipped: Vec<(String, u64)> = Vec::new();
    for block in &blocks {
        match block.ty.as_str() {
            "tetra" => {
                for row in &block.rows {
                    tet_id += 1;
                    builder.push_tet(tet_id, [row[0], row[1], row[2], row[3]]);
                }
            }
            "triangle" => {
                for row in &block.rows {
                    builder.push_triangle([row[0], row[1], row[2]]);
                }
            }
            other => {
                let what = format!("cells of type {other:?}");
                match skipped.iter_mut().find(|s| s.0 == what) {
                    Some(s) => s.1 += block.rows.len() as u64,
                    None => skipped.push((what, block.rows.len() as u64)),
                }
            }
        }
    }
    for (what, n) in &skipped {
        builder.skip(what, *n);
    }
    r.cell_sets(&root, &blocks, &mut builder)?;
    r.gmsh_physical(&root, &blocks, &mut builder)?;
    builder.finish(file)
}
