//! Surface assets in: OBJ, STL (ASCII and binary) and PLY (ASCII and binary) read into a
//! [`SurfaceMesh`] and checked to bound a solid ([`SurfaceMesh::check_closed`]) before
//! [`crate::mesh::gmsh`] fills it with tetrahedra.
//!
//! Parsers: `tobj` (OBJ; every object and group of the file, polygons fan-triangulated, f64
//! positions), `stl_io` (STL), `ply-rs-bw` (PLY: `vertex` x/y/z, `face` `vertex_indices` or
//! `vertex_index`, polygons fan-triangulated). Bit-identical positions are welded into one
//! vertex (STL stores every triangle's corners separately, OBJ objects their own vertices).
//! Unsupported: non-triangle primitives other than planar polygons, textures and materials
//! (ignored).

mod inspect;
mod surface_error;
mod surface_mesh;

use std::io::{BufReader, Cursor};
use std::path::Path;

pub use inspect::{inspect_surface, Defect, DefectKind, SurfaceInspection, MAX_EXAMPLES};
pub use surface_error::SurfaceError;
pub use surface_mesh::{SurfaceInfo, SurfaceMesh};

/// Whether `path` has a surface-asset extension (`.obj`, `.stl`, `.ply`, any case).
pub fn is_surface_asset(path: &Path) -> bool {
    format_of(path).is_some()
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Obj,
    Stl,
    Ply,
}

fn format_of(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
    match ext.as_str() {
        "obj" => Some(Format::Obj),
        "stl" => Some(Format::Stl),
        "ply" => Some(Format::Ply),
        _ => None,
    }
}

/// Reads a surface asset (positions as written in the file, welded), choosing the format
/// from the extension. Does not check the surface: call [`SurfaceMesh::check_closed`].
///
/// # Errors
/// [`SurfaceError`] naming the file: unreadable, unknown extension, parse errors, indices out of
/// range, non-finite coordinates, no triangles.
pub fn read_surface(path: &Path) -> Result<SurfaceMesh, SurfaceError> {
    let file = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| SurfaceError::Io {
        file: file.clone(),
        detail: e.to_string(),
    })?;
    read_surface_bytes(&data, &file)
}

/// [`read_surface`] on bytes in memory; `name` (a file name) chooses the format by its
/// extension and names the file in errors.
///
/// # Errors
/// As [`read_surface`].
pub fn read_surface_bytes(data: &[u8], name: &str) -> Result<SurfaceMesh, SurfaceError> {
    let (positions, triangles) = read_surface_unwelded(data, name)?;
    Ok(SurfaceMesh::welded(positions, triangles))
}

/// The file's own vertices (in file order, none merged or dropped) and its polygons
/// fan-triangulated, as [`read_surface_bytes`] reads them before welding. OBJ files are
/// renumbered per object in first-use order by the parser (use a reader that keeps the `v`
/// order when that order matters).
///
/// # Errors
/// As [`read_surface`].
pub fn read_surface_unwelded(data: &[u8], name: &str) -> Result<Soup3, SurfaceError> {
    let file = || name.to_string();
    let (positions, faces) = match format_of(Path::new(name)) {
        Some(Format::Obj) => read_obj(data, name)?,
        Some(Format::Stl) => read_stl(data, name)?,
        Some(Format::Ply) => read_ply(data, name)?,
        None => return Err(SurfaceError::UnknownFormat { file: file() }),
    };
    if let Some(v) = positions
        .iter()
        .position(|p| !p.iter().all(|x| x.is_finite()))
    {
        return Err(SurfaceError::NonFinite {
            file: file(),
            vertex: v,
        });
    }
    let mut triangles = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        if let Some(&bad) = face
            .iter()
            .find(|&&v| v < 0 || v as usize >= positions.len())
        {
            return Err(SurfaceError::BadIndex {
                file: file(),
                face: f,
                vertex: bad,
                count: positions.len(),
            });
        }
        // Fan triangulation of a (planar, convex) polygon.
        for k in 1..face.len().saturating_sub(1) {
            triangles.push([face[0] as usize, face[k] as usize, face[k + 1] as usize]);
        }
    }
    if triangles.is_empty() {
        return Err(SurfaceError::Empty { file: file() });
    }
    Ok((positions, triangles))
}

/// Vertex positions (as in the file) and triangles (0-based indices into them).
pub type Soup3 = (Vec<[f64; 3]>, Vec<[usize; 3]>);

type Soup = (Vec<[f64; 3]>, Vec<Vec<i64>>);

fn parse_err(name: &str, format: &'static str, detail: impl ToString) -> SurfaceError {
    SurfaceError::Parse {
        file: name.to_string(),
        format,
        detail: detail.to_string(),
    }
}

fn read_obj(data: &[u8], name: &str) -> Result<Soup, SurfaceError> {
    let opts = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(Cursor::new(data)), &opts, |_| {
        Ok(Default::default())
    })
    .map_err(|e| parse_err(name, "OBJ", e))?;
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let base = positions.len() as i64;
        positions.extend(mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        let arity: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut at = 0;
        for a in arity {
            let Some(idx) = mesh.indices.get(at..at + a) else {
                return Err(parse_err(
                    name,
                    "OBJ",
                    "face indices run past the index list",
                ));
            };
            faces.push(idx.iter().map(|&i| base + i as i64).collect());
            at += a;
        }
    }
    Ok((positions, faces))
}

fn read_stl(data: &[u8], name: &str) -> Result<Soup, SurfaceError> {
    // Binary STL: 80-byte header, u32 count, 50 bytes per triangle. Check the count against
    // the bytes present before the parser allocates for it.
    let ascii = data
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .eq(b"solid".iter())
        && data.windows(5).any(|w| w == b"facet");
    if !ascii {
        if data.len() < 84 {
            return Err(parse_err(
                name,
                "STL",
                "shorter than a binary STL header (84 bytes)",
            ));
        }
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        if 84 + 50 * n != data.len() as u64 {
            return Err(parse_err(
                name,
                "STL",
                format!(
                    "binary header declares {n} triangles ({} bytes) but the file has {} bytes",
                    84 + 50 * n,
                    data.len()
                ),
            ));
        }
    }
    let mesh = stl_io::read_stl(&mut Cursor::new(data)).map_err(|e| parse_err(name, "STL", e))?;
    let positions = mesh.vertices.iter().map(|v| v.0.map(f64::from)).collect();
    let faces = mesh
        .faces
        .iter()
        .map(|f| f.vertices.iter().map(|&v| v as i64).collect())
        .collect();
    Ok((positions, faces))
}

fn read_ply(data: &[u8], name: &str) -> Result<Soup, SurfaceError> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut Cursor::new(data))
        .map_err(|e| parse_err(name, "PLY", e))?;
    let scalar = |p: &Property| -> Option<f64> {
        Some(match p {
            Property::Char(x) => *x as f64,
            Property::UChar(x) => *x as f64,
            Property::Short(x) => *x as f64,
            Property::UShort(x) => *x as f64,
            Property::Int(x) => *x as f64,
            Property::UInt(x) => *x as f64,
            Property::Float(x) => *x as f64,
            Property::Double(x) => *x,
            _ => return None,
        })
    };
    let list = |p: &Property| -> Option<Vec<i64>> {
        Some(match p {
            Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
            _ => return None,
        })
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| parse_err(name, "PLY", "no `vertex` element"))?;
    let mut positions = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let mut p = [0.0; 3];
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            p[k] = v.get(*axis).and_then(scalar).ok_or_else(|| {
                parse_err(name, "PLY", format!("vertex {i} has no numeric `{axis}`"))
            })?;
        }
        positions.push(p);
    }
    let faces_el = ply
        .payload
        .get("face")
        .ok_or_else(|| parse_err(name, "PLY", "no `face` element"))?;
    let mut faces = Vec::with_capacity(faces_el.len());
    for (i, f) in faces_el.iter().enumerate() {
        let idx = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(list)
            .ok_or_else(|| {
                parse_err(
                    name,
                    "PLY",
                    format!("face {i} has no integer list `vertex_indices`"),
                )
            })?;
        faces.push(idx);
    }
    Ok((positions, faces))
}
