//! Surface assets in: OBJ, STL (ASCII and binary), PLY (ASCII and binary) and glTF 2.0
//! (`.glb`, `.gltf`; [`gltf_asset`](self) has what is read) read into a
//! [`SurfaceMesh`] and checked to bound a solid ([`SurfaceMesh::check_closed`]) before
//! [`crate::mesh::gmsh`] fills it with tetrahedra.
//!
//! Parsers: `tobj` (OBJ; every object and group of the file, polygons fan-triangulated, f64
//! positions), `stl_io` (STL), `ply-rs-bw` (PLY: `vertex` x/y/z, `face` `vertex_indices` or
//! `vertex_index`, polygons fan-triangulated). Bit-identical positions are welded into one
//! vertex (STL stores every triangle's corners separately, OBJ objects their own vertices).
//! Unsupported: non-triangle primitives other than planar polygons, textures and materials
//! (ignored).

mod gltf_asset;
mod inspect;
mod surface_error;
mod surface_mesh;

use std::io::{BufReader, Cursor};
use std::path::Path;

pub use gltf_asset::{
    gltf_component, read_beside, read_gltf_scene, validate_document, GltfPlacement, GltfScene,
};
pub use inspect::{inspect_surface, Defect, DefectKind, SurfaceInspection, MAX_EXAMPLES};
pub use surface_error::SurfaceError;
pub use surface_mesh::{SurfaceInfo, SurfaceMesh};

/// Whether `path` has a surface-asset extension (`.obj`, `.stl`, `.ply`, `.glb`, `.gltf`, any
/// case).
pub fn is_surface_asset(path: &Path) -> bool {
    format_of(path).is_some()
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Obj,
    Stl,
    Ply,
    Gltf,
}

fn format_of(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
    match ext.as_str() {
        "obj" => Some(Format::Obj),
        "stl" => Some(Format::Stl),
        "ply" => Some(Format::Ply),
        "glb" | "gltf" => Some(Format::Gltf),
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
    read_surface_object(path, None)
}

/// [`read_surface`] of one named object of the asset: a glTF node (with its children) or
/// mesh, or an OBJ object or group (`o`/`g`); `None`: the whole asset.
///
/// # Errors
/// As [`read_surface`], and [`SurfaceError::Object`] when no object or several nodes have that
/// name (listing the names the file has), or for STL and PLY, which name no objects.
pub fn read_surface_object(path: &Path, object: Option<&str>) -> Result<SurfaceMesh, SurfaceError> {
    let (data, file) = read_asset_file(path)?;
    let (positions, triangles) = read_surface_unwelded_object(&data, &file, object)?;
    Ok(SurfaceMesh::welded(positions, triangles))
}

/// The bytes of the asset at `path` and its name for messages. Only a regular file is opened
/// (a FIFO would block, `/dev/zero` never ends), and no more than its length when opened is
/// read.
fn read_asset_file(path: &Path) -> Result<(Vec<u8>, String), SurfaceError> {
    use dcr_runtime::format::open_regular_file;
    use std::io::Read;
    let file = path.display().to_string();
    let io = |detail: String| SurfaceError::Io {
        file: file.clone(),
        detail,
    };
    let (f, len) = open_regular_file(path).map_err(|e| io(e.to_string()))?;
    let mut data = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    f.take(len)
        .read_to_end(&mut data)
        .map_err(|e| io(e.to_string()))?;
    Ok((data, file))
}

/// [`read_surface`] on bytes in memory; `name` (a file name) chooses the format by its
/// extension and names the file in errors. A `.gltf`'s buffer files are read from `name`'s
/// folder.
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
    read_surface_unwelded_object(data, name, None)
}

/// [`read_surface_unwelded`] of one named object ([`read_surface_object`]); `None`: all.
///
/// # Errors
/// As [`read_surface_object`].
pub fn read_surface_unwelded_object(
    data: &[u8],
    name: &str,
    object: Option<&str>,
) -> Result<Soup3, SurfaceError> {
    let file = || name.to_string();
    let format = format_of(Path::new(name));
    if object.is_some() && matches!(format, Some(Format::Stl | Format::Ply)) {
        return Err(SurfaceError::Object {
            file: file(),
            detail: "--object names an object of a glTF or OBJ asset; STL and PLY files name no objects (export the one object)".into(),
        });
    }
    let (positions, faces) = match format {
        Some(Format::Obj) => read_obj(data, name, object)?,
        Some(Format::Stl) => read_stl(data, name)?,
        Some(Format::Ply) => read_ply(data, name)?,
        // Triangles already, their indices checked against each primitive's vertices.
        Some(Format::Gltf) => {
            let (positions, triangles) = gltf_asset::read_gltf(data, name, object)?;
            return finite_and_nonempty(positions, triangles, name);
        }
        None => return Err(SurfaceError::UnknownFormat { file: file() }),
    };
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
    finite_and_nonempty(positions, triangles, name)
}

/// The object names `--object` accepts in the asset at `path` that hold triangles: a glTF's
/// named nodes with a mesh in their subtree and its meshes' names, an OBJ's `o`/`g` names with
/// faces (in the file's order, each once); none for STL and PLY.
///
/// # Errors
/// [`SurfaceError`] naming the file: unreadable, unknown extension, a glTF the reader refuses.
pub fn object_names(path: &Path) -> Result<Vec<String>, SurfaceError> {
    let (data, name) = read_asset_file(path)?;
    match format_of(path) {
        Some(Format::Gltf) => gltf_asset::gltf_object_names(&data, &name),
        Some(Format::Obj) => {
            let text = String::from_utf8_lossy(&data);
            let (mut out, mut current): (Vec<String>, String) = (Vec::new(), String::new());
            for line in text.lines() {
                let mut tok = line.split_whitespace();
                match tok.next() {
                    Some("o" | "g") => current = tok.collect::<Vec<_>>().join(" "),
                    Some("f") if !current.is_empty() && !out.contains(&current) => {
                        out.push(current.clone())
                    }
                    _ => {}
                }
            }
            Ok(out)
        }
        Some(Format::Stl | Format::Ply) => Ok(Vec::new()),
        None => Err(SurfaceError::UnknownFormat { file: name }),
    }
}

/// `the file's objects: `a`, `b`, … (N in all)`: the distinct names, the first 20.
pub(crate) fn list_names(names: &[&str]) -> String {
    let mut seen: Vec<&str> = Vec::new();
    for n in names {
        if !seen.contains(n) {
            seen.push(n);
        }
    }
    let shown: Vec<String> = seen.iter().take(20).map(|n| format!("`{n}`")).collect();
    match seen.len() {
        0 => "the file names no objects".into(),
        k if k > 20 => format!("the file's objects: {}, … ({k} in all)", shown.join(", ")),
        _ => format!("the file's objects: {}", shown.join(", ")),
    }
}

/// The soup, refused when a coordinate is not finite or there is no triangle.
fn finite_and_nonempty(
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    name: &str,
) -> Result<Soup3, SurfaceError> {
    let file = || name.to_string();
    if let Some(v) = positions
        .iter()
        .position(|p| !p.iter().all(|x| x.is_finite()))
    {
        return Err(SurfaceError::NonFinite {
            file: file(),
            vertex: v,
        });
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

/// The line (1-based) of the first byte of `data` that is not UTF-8, if any.
fn first_non_utf8_line(data: &[u8]) -> Option<usize> {
    std::str::from_utf8(data).err().map(|e| {
        data[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    })
}

/// A PLY parser error as one line with its location: the parser's `Line N: what` and the
/// offending text, without its grammar internals; a non-UTF-8 header located by line.
fn ply_error(data: &[u8], name: &str, e: &dyn std::fmt::Display) -> SurfaceError {
    let text = e.to_string();
    let mut lines = text.lines();
    let first = lines.next().unwrap_or("").trim();
    let detail = if text.contains("valid UTF-8") {
        match first_non_utf8_line(data) {
            Some(line) => format!("line {line}: not ASCII text"),
            None => "not ASCII text".to_string(),
        }
    } else {
        let first = match first.strip_prefix("Line ") {
            Some(rest) => format!("line {rest}"),
            None => first.to_string(),
        };
        match lines
            .map(str::trim)
            .find_map(|l| l.strip_prefix("String: "))
        {
            Some(what) => format!(
                "{}: `{}`",
                first.trim_end_matches('.'),
                what.trim().trim_matches('\'').trim()
            ),
            None => first,
        }
    };
    parse_err(name, "PLY", detail)
}

/// Where an OBJ the `tobj` parser refused goes wrong (its messages carry no line): the first
/// line that is not UTF-8 text, or the first `v`, `vt`, `vn` or `f` line whose fields do not
/// parse.
fn obj_error_line(data: &[u8]) -> Option<usize> {
    if let Some(line) = first_non_utf8_line(data) {
        return Some(line);
    }
    let text = std::str::from_utf8(data).ok()?;
    text.lines()
        .position(|l| {
            let mut f = l.split_whitespace();
            match f.next() {
                Some(key @ ("v" | "vt" | "vn")) => {
                    let nums: Vec<&str> = f.collect();
                    let least = if key == "vt" { 1 } else { 3 };
                    nums.len() < least || nums.iter().any(|x| x.parse::<f64>().is_err())
                }
                Some("f") => {
                    let idx: Vec<&str> = f.collect();
                    idx.len() < 3
                        || idx.iter().any(|x| {
                            x.split('/')
                                .next()
                                .is_none_or(|i| i.parse::<i64>().map_or(true, |i| i == 0))
                        })
                }
                _ => false,
            }
        })
        .map(|i| i + 1)
}

fn read_obj(data: &[u8], name: &str, object: Option<&str>) -> Result<Soup, SurfaceError> {
    let opts = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(Cursor::new(data)), &opts, |_| {
        Ok(Default::default())
    })
    .map_err(|e| match obj_error_line(data) {
        Some(line) => parse_err(name, "OBJ", format!("line {line}: {e}")),
        None => parse_err(name, "OBJ", e),
    })?;
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    if let Some(o) = object {
        if !models.iter().any(|m| m.name == o) {
            let names: Vec<&str> = models.iter().map(|m| m.name.as_str()).collect();
            return Err(SurfaceError::Object {
                file: name.to_string(),
                detail: format!("no object or group named `{o}`; {}", list_names(&names)),
            });
        }
    }
    for model in models.iter().filter(|m| object.is_none_or(|o| m.name == o)) {
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
    // Binary STL: 80-byte header (which may itself start with `solid`), u32 count, 50 bytes
    // per triangle. One decision: binary exactly when the length is 84 + 50·n.
    let binary = data.len() >= 84 && {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        84 + 50 * n == data.len() as u64
    };
    if binary {
        let mesh =
            stl_io::read_stl(&mut Cursor::new(data)).map_err(|e| parse_err(name, "STL", e))?;
        let positions = mesh.vertices.iter().map(|v| v.0.map(f64::from)).collect();
        let faces = mesh
            .faces
            .iter()
            .map(|f| f.vertices.iter().map(|&v| v as i64).collect())
            .collect();
        return Ok((positions, faces));
    }
    let starts_solid = data
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .map(u8::to_ascii_lowercase)
        .eq(b"solid".iter().copied());
    if !starts_solid {
        let detail = if data.len() >= 84 {
            let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
            format!(
                "neither ASCII (no leading `solid`) nor binary: the binary header declares {n} \
                 triangles ({} bytes) but the file has {} bytes",
                84 + 50 * n,
                data.len()
            )
        } else {
            format!(
                "neither ASCII (no leading `solid`) nor binary ({} bytes, shorter than the \
                 84-byte binary header)",
                data.len()
            )
        };
        return Err(parse_err(name, "STL", detail));
    }
    read_ascii_stl(data, name)
}

/// ASCII STL: every `solid … endsolid` block of the file (keywords in any case, the solid's
/// name optional, blank lines anywhere), each facet `facet normal nx ny nz / outer loop /
/// vertex x y z ×3 / endloop / endfacet`. Errors name the line.
///
/// Written here rather than through `stl_io`, whose ASCII reader stops at the first
/// `endsolid` and refuses a missing name, upper-case keywords and leading blank lines.
fn read_ascii_stl(data: &[u8], name: &str) -> Result<Soup, SurfaceError> {
    let text = std::str::from_utf8(data).map_err(|e| {
        let line = data[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        parse_err(name, "STL", format!("line {line}: not ASCII text"))
    })?;
    let mut c = StlTokens {
        tokens: text
            .lines()
            .enumerate()
            .flat_map(|(i, l)| {
                l.split_ascii_whitespace()
                    .enumerate()
                    .map(move |(k, t)| (i + 1, k, t))
            })
            .collect(),
        at: 0,
        name,
    };
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<Vec<i64>> = Vec::new();
    while let Some((line, _, _)) = c.peek() {
        c.word("solid")?;
        c.skip_rest_of_line(line);
        loop {
            match c.peek() {
                None => return Err(c.err(line, "the solid opened here has no `endsolid`")),
                Some((l, _, t)) if t.eq_ignore_ascii_case("endsolid") => {
                    c.at += 1;
                    c.skip_rest_of_line(l);
                    break;
                }
                Some(_) => {}
            }
            c.word("facet")?;
            c.word("normal")?;
            for axis in ["nx", "ny", "nz"] {
                c.number(axis)?;
            }
            c.word("outer")?;
            c.word("loop")?;
            let mut face = Vec::with_capacity(3);
            for _ in 0..3 {
                c.word("vertex")?;
                let p = [c.number("x")?, c.number("y")?, c.number("z")?];
                face.push(positions.len() as i64);
                positions.push(p);
            }
            c.word("endloop")?;
            c.word("endfacet")?;
            faces.push(face);
        }
    }
    Ok((positions, faces))
}

/// The tokens of an ASCII STL: (line, position on the line, text), and the next one's index.
struct StlTokens<'a> {
    tokens: Vec<(usize, usize, &'a str)>,
    at: usize,
    name: &'a str,
}

impl<'a> StlTokens<'a> {
    fn peek(&self) -> Option<(usize, usize, &'a str)> {
        self.tokens.get(self.at).copied()
    }

    fn err(&self, line: usize, what: &str) -> SurfaceError {
        parse_err(self.name, "STL", format!("line {line}: {what}"))
    }

    fn next(&mut self, what: &str) -> Result<(usize, &'a str), SurfaceError> {
        match self.peek() {
            Some((l, _, t)) => {
                self.at += 1;
                Ok((l, t))
            }
            None => {
                let last = self.tokens.last().map_or(1, |t| t.0);
                Err(self.err(last, &format!("the file ends where {what} was expected")))
            }
        }
    }

    /// The keyword `w` (any case).
    fn word(&mut self, w: &str) -> Result<(), SurfaceError> {
        let (l, t) = self.next(&format!("`{w}`"))?;
        if t.eq_ignore_ascii_case(w) {
            Ok(())
        } else {
            Err(self.err(l, &format!("expected `{w}`, found `{t}`")))
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, SurfaceError> {
        let (l, t) = self.next(&format!("the number {what}"))?;
        t.parse::<f64>()
            .map_err(|_| self.err(l, &format!("expected the number {what}, found `{t}`")))
    }

    /// Skips the tokens after the first on `line` (a solid's name).
    fn skip_rest_of_line(&mut self, line: usize) {
        while self.peek().is_some_and(|(l, k, _)| l == line && k > 0) {
            self.at += 1;
        }
    }
}

fn read_ply(data: &[u8], name: &str) -> Result<Soup, SurfaceError> {
    use ply_rs_bw::parser::{Parser, Reader};
    use ply_rs_bw::ply::{DefaultElement, Encoding, Property};
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(Cursor::new(data));
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| ply_error(data, name, &e))?;
    let payload = parser
        .read_payload(&mut reader, &header)
        .map_err(|e| ply_error(data, name, &e))?;
    // Everything the header declares has been read: anything but white space after it is
    // data the header does not count (more faces than declared), refused rather than dropped.
    let consumed =
        usize::try_from(reader.get_ref().position()).map_or(data.len(), |p| p.min(data.len()));
    if let Some(off) = data[consumed..]
        .iter()
        .position(|b| !b.is_ascii_whitespace())
    {
        let at = consumed + off;
        let declared: Vec<String> = header
            .elements
            .iter()
            .map(|(n, e)| format!("{} {n}", e.count))
            .collect();
        let place = match header.encoding {
            Encoding::Ascii => format!(
                "line {}",
                data[..at].iter().filter(|&&b| b == b'\n').count() + 1
            ),
            _ => format!("byte {at}"),
        };
        return Err(parse_err(
            name,
            "PLY",
            format!(
                "{place}: data after the elements the header declares ({}); fix the element counts in the header",
                declared.join(", ")
            ),
        ));
    }
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
    let vertices = payload
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
    let faces_el = payload
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
