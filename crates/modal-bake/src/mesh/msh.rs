//! gmsh MSH reader: versions 2.2 (and 2.0, 2.1, which write nodes and elements alike) and 4.1,
//! ASCII and binary. MSH 1 (`$NOD`) and 4.0 are refused with gmsh's command to re-save them.
//!
//! Format reference: gmsh manual §10 "Gmsh file formats" (MSH 4.1) and the legacy MSH 2.2
//! description.
//!
//! **Sections.** Read front to back. `$MeshFormat`, `$PhysicalNames`, `$Entities` (4.1),
//! `$Nodes` and `$Elements` are read, each at most once
//! ([`MeshErrorKind::DuplicateSection`]), `$MeshFormat` before the others
//! ([`MeshErrorKind::SectionOrder`]) and `$Nodes` before `$Elements`. Every other section
//! (`$Comments`, `$NodeData`, `$Periodic`, ...) is skipped wherever it is, also before
//! `$MeshFormat`, as gmsh does.
//!
//! **Records.** ASCII data is read line by line (a node, an element, a block header per line,
//! as gmsh writes them): a missing or extra value is refused at its line
//! ([`MeshErrorKind::ShortLine`], [`MeshErrorKind::ExtraValue`]). Node and element tags must be
//! positive ([`MeshErrorKind::InvalidTag`]). Declared counts are checked against the bytes
//! left before anything is allocated ([`MeshErrorKind::CountTooLarge`]).
//!
//! **Element types.** One table, `element_info`, gives each gmsh element type's node count
//! and dimension: how many node tags a record carries, so a type the mesh does not use is
//! still read exactly (its nodes join its physical groups) and then skipped. What a record
//! becomes is decided in one place, `MshReader::add_element`: type 4 (4-node tetrahedron) →
//! `MeshBuilder::push_tet`, type 11 (10-node tetrahedron, gmsh node order: corners, then the
//! mid-edge nodes of edges (0,1), (1,2), (2,0), (3,0), (3,2), (3,1)) → `MeshBuilder::push_tet10`,
//! types 2 and 9 (3- and 6-node triangles, corners) → `MeshBuilder::push_triangle`, every
//! other type is counted: other volume elements (hexahedra, prisms, pyramids, tetrahedra of
//! higher order) are refused ([`MeshErrorKind::OtherVolumeElements`]: leaving them out would
//! bake part of the object), the rest (points, lines, quadrangles) reported in
//! [`TetMesh::notes`]. Supporting another type is an arm
//! there and a `MeshBuilder` method; binary MSH 2.2 and 4.1 element blocks of a type missing
//! from `element_info` cannot be skipped (their record size is unknown) and are refused.

use std::collections::BTreeMap;

use super::cursor::Cursor;
use super::mesh_builder::MeshBuilder;
use super::mesh_error::{shorten, MeshError, MeshErrorKind};
use super::tet_mesh::TetMesh;

/// Node count, dimension and name of a gmsh element type.
fn element_info(ty: i64) -> Option<(usize, i32, &'static str)> {
    Some(match ty {
        1 => (2, 1, "2-node line"),
        2 => (3, 2, "3-node triangle"),
        3 => (4, 2, "4-node quadrangle"),
        4 => (4, 3, "4-node tetrahedron"),
        5 => (8, 3, "8-node hexahedron"),
        6 => (6, 3, "6-node prism"),
        7 => (5, 3, "5-node pyramid"),
        8 => (3, 1, "3-node line"),
        9 => (6, 2, "6-node triangle"),
        10 => (9, 2, "9-node quadrangle"),
        11 => (10, 3, "10-node tetrahedron"),
        12 => (27, 3, "27-node hexahedron"),
        13 => (18, 3, "18-node prism"),
        14 => (14, 3, "14-node pyramid"),
        15 => (1, 0, "1-node point"),
        16 => (8, 2, "8-node quadrangle"),
        17 => (20, 3, "20-node hexahedron"),
        18 => (15, 3, "15-node prism"),
        19 => (13, 3, "13-node pyramid"),
        20 => (9, 2, "9-node triangle"),
        21 => (10, 2, "10-node triangle"),
        22 => (12, 2, "12-node triangle"),
        23 => (15, 2, "15-node triangle"),
        24 => (15, 2, "15-node incomplete triangle"),
        25 => (21, 2, "21-node triangle"),
        26 => (4, 1, "4-node line"),
        27 => (5, 1, "5-node line"),
        28 => (6, 1, "6-node line"),
        29 => (20, 3, "20-node tetrahedron"),
        30 => (35, 3, "35-node tetrahedron"),
        31 => (56, 3, "56-node tetrahedron"),
        92 => (64, 3, "64-node hexahedron"),
        93 => (125, 3, "125-node hexahedron"),
        _ => return None,
    })
}

/// The MSH format revisions this reader supports.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Version {
    V22,
    V41,
}

/// The sections this reader reads (each at most once); `None` for sections it skips.
fn known_section(name: &[u8]) -> Option<&'static str> {
    Some(match name {
        b"MeshFormat" => "MeshFormat",
        b"PhysicalNames" => "PhysicalNames",
        b"Entities" => "Entities",
        b"Nodes" => "Nodes",
        b"Elements" => "Elements",
        _ => return None,
    })
}

/// Reader state shared by both versions.
struct MshReader<'a> {
    c: Cursor<'a>,
    file: &'a str,
    version: Version,
    builder: MeshBuilder,
    /// Sections read so far and the byte offset of each header.
    seen: Vec<(&'static str, usize)>,
    /// `$PhysicalNames`: (dim, tag) → name.
    names: BTreeMap<(i32, i64), String>,
    /// MSH 4.1 `$Entities`: (dim, entity tag) → physical tags.
    entity_physicals: BTreeMap<(i32, i64), Vec<i64>>,
    /// Node table indices per physical group (2.2) or per entity (4.1), keyed by (dim, tag).
    members: BTreeMap<(i32, i64), Vec<usize>>,
    /// Skipped element counts per type, in first-seen order.
    skipped: Vec<(i64, u64)>,
    /// Scratch buffer of node indices of the current element.
    scratch: Vec<usize>,
    /// Keep only the tetrahedra of this 3-D physical group (name, or number without a name).
    select: Option<&'a str>,
    /// The 3-D physical groups the tetrahedra belong to, for the error when `select` matches
    /// none.
    volume_groups: std::collections::BTreeSet<String>,
    /// Tetrahedra kept by `select`.
    selected: u64,
}

/// Reads a gmsh MSH 2.2 or 4.1 file (ASCII or binary) from memory; `file` names it in errors.
pub(crate) fn parse_msh(data: &[u8], file: &str) -> Result<TetMesh, MeshError> {
    parse_msh_object(data, file, None)
}

/// [`parse_msh`] keeping, with `select`, only the tetrahedra of that 3-D physical group
/// (its name, or its number when it has none): one object of a file of several.
///
/// # Errors
/// As [`parse_msh`], and [`MeshErrorKind::UnknownObject`] (with the file's 3-D groups) when no
/// tetrahedron belongs to `select`.
pub(crate) fn parse_msh_object(
    data: &[u8],
    file: &str,
    select: Option<&str>,
) -> Result<TetMesh, MeshError> {
    let mut c = Cursor::new(data, file);
    let (version, format_pos) = read_header(&mut c)?;
    let mut r = MshReader {
        c,
        file,
        version,
        builder: MeshBuilder::default(),
        seen: vec![("MeshFormat", format_pos)],
        names: BTreeMap::new(),
        entity_physicals: BTreeMap::new(),
        members: BTreeMap::new(),
        skipped: Vec::new(),
        scratch: Vec::new(),
        select,
        volume_groups: std::collections::BTreeSet::new(),
        selected: 0,
    };
    r.read_sections()?;
    r.finish()
}

/// Skips unknown sections up to `$MeshFormat`, reads it, sets the cursor's binary mode and
/// returns the version and the byte offset of the `$MeshFormat` header.
fn read_header(c: &mut Cursor<'_>) -> Result<(Version, usize), MeshError> {
    let format_pos = loop {
        let (start, tok) = c.token("$MeshFormat")?;
        match tok.strip_prefix(b"$") {
            Some(b"MeshFormat") => break start,
            Some(b"NOD" | b"NOE") => {
                return Err(c.error_at(start, false, MeshErrorKind::Msh1));
            }
            Some(name) if !name.is_empty() && !name.starts_with(b"End") => {
                if let Some(section) = known_section(name) {
                    return Err(c.error_at(
                        start,
                        false,
                        MeshErrorKind::SectionOrder {
                            section,
                            before: "MeshFormat",
                        },
                    ));
                }
                c.rest_of_line();
                c.skip_section(name)?;
            }
            _ => {
                return Err(c.error_at(
                    start,
                    false,
                    MeshErrorKind::MissingSection("$MeshFormat (at the start of the file)"),
                ))
            }
        }
    };
    c.rest_of_line();
    let vpos = c.line();
    let (_, vtok) = c.token("MSH version")?;
    // gmsh writes "2.2" and "4.1"; others write the number their own way (Netgen "2.000000").
    // MSH 2.0 and 2.1 write nodes and elements as 2.2 does (2.1 added `$PhysicalNames`).
    let number = std::str::from_utf8(vtok)
        .ok()
        .and_then(|t| t.parse::<f64>().ok());
    let version = match number {
        Some(2.0 | 2.1 | 2.2) => Version::V22,
        Some(4.1) => Version::V41,
        _ => {
            return Err(c.error_at(
                vpos,
                false,
                MeshErrorKind::UnsupportedVersion(shorten(vtok)),
            ))
        }
    };
    let tpos = c.line();
    let file_type = c.ascii_u64("file-type")?;
    let dpos = c.line();
    let data_size = c.ascii_u64("data-size")?;
    c.end_line("the $MeshFormat line")?;
    let supported = match version {
        Version::V22 => data_size == 8,
        Version::V41 => data_size == 4 || data_size == 8,
    };
    if !supported {
        return Err(c.error_at(dpos, false, MeshErrorKind::UnsupportedDataSize(data_size)));
    }
    match file_type {
        0 => {}
        1 => {
            let epos = c.pos();
            let b: [u8; 4] = c
                .bytes(4, "endianness check integer")?
                .try_into()
                .expect("4 bytes");
            let big_endian = if u32::from_le_bytes(b) == 1 {
                false
            } else if u32::from_be_bytes(b) == 1 {
                true
            } else {
                return Err(c.error_at(
                    epos,
                    true,
                    MeshErrorKind::BadEndianness(u32::from_le_bytes(b)),
                ));
            };
            c.set_binary(big_endian, data_size as usize);
        }
        other => {
            return Err(c.error_at(
                tpos,
                false,
                MeshErrorKind::Unexpected {
                    expected: "file-type 0 (ASCII) or 1 (binary)".to_string(),
                    found: other.to_string(),
                },
            ))
        }
    }
    c.expect("$EndMeshFormat")?;
    Ok((version, format_pos))
}

impl MshReader<'_> {
    fn read_sections(&mut self) -> Result<(), MeshError> {
        while !self.c.at_end() {
            let (start, tok) = self.c.token("section")?;
            let Some(name) = tok.strip_prefix(b"$") else {
                return Err(self.c.error_at(
                    start,
                    false,
                    MeshErrorKind::Unexpected {
                        expected: "a $Section header".to_string(),
                        found: shorten(tok),
                    },
                ));
            };
            self.c.rest_of_line();
            let Some(section) = known_section(name) else {
                self.c.skip_section(name)?;
                continue;
            };
            if let Some(&(_, first)) = self.seen.iter().find(|s| s.0 == section) {
                let first = self.c.line_at(first);
                return Err(self.c.error_at(
                    start,
                    false,
                    MeshErrorKind::DuplicateSection { section, first },
                ));
            }
            self.seen.push((section, start));
            // `$MeshFormat` is in `seen` from the start: only the four data sections get here.
            match (section, self.version) {
                ("PhysicalNames", _) => self.read_physical_names()?,
                ("Entities", Version::V41) => self.read_entities()?,
                ("Entities", Version::V22) => self.c.skip_section(name)?,
                ("Nodes", Version::V22) => self.read_nodes_v22()?,
                ("Nodes", Version::V41) => self.read_nodes_v41()?,
                (_, version) => {
                    if !self.has("Nodes") {
                        return Err(self.c.error_at(
                            start,
                            false,
                            MeshErrorKind::MissingSection("$Nodes (before $Elements)"),
                        ));
                    }
                    match version {
                        Version::V22 => self.read_elements_v22()?,
                        Version::V41 => self.read_elements_v41()?,
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether section `name` has been read.
    fn has(&self, name: &str) -> bool {
        self.seen.iter().any(|s| s.0 == name)
    }

    fn finish(mut self) -> Result<TetMesh, MeshError> {
        let end = self.c.pos();
        for required in ["$Nodes", "$Elements"] {
            if !self.has(&required[1..]) {
                return Err(self
                    .c
                    .error_at(end, false, MeshErrorKind::MissingSection(required)));
            }
        }
        if let (Some(name), 0) = (self.select, self.selected) {
            let groups: Vec<String> = std::mem::take(&mut self.volume_groups)
                .into_iter()
                .collect();
            return Err(MeshError::new(
                self.file,
                super::mesh_error::Location::None,
                MeshErrorKind::UnknownObject {
                    name: name.to_string(),
                    available: if groups.is_empty() {
                        "none: its tetrahedra are in no physical group (define a `Physical Volume` in gmsh, or select a connected piece with --piece N)".into()
                    } else {
                        groups.join(", ")
                    },
                },
            ));
        }
        for &(ty, n) in &self.skipped {
            let noun = if n == 1 { "element" } else { "elements" };
            let (what, volume) = match element_info(ty) {
                Some((_, dim, name)) => (format!("{noun} of gmsh type {ty} ({name})"), dim == 3),
                None => (format!("{noun} of gmsh type {ty} (unknown type)"), false),
            };
            self.builder.skip(&what, n, volume);
        }
        let members = std::mem::take(&mut self.members);
        for (&key, nodes) in &members {
            for name in self.group_names(Some(key)) {
                self.builder.add_to_group(&name, nodes);
            }
        }
        self.builder.finish(self.file)
    }

    /// `$PhysicalNames` (ASCII in every file type): `dim tag "name"` per line.
    fn read_physical_names(&mut self) -> Result<(), MeshError> {
        let pos = self.c.line();
        let n = self.c.ascii_u64("number of physical names")?;
        self.c.end_line("the physical-name count")?;
        let n = self.c.check_count(pos, false, n, 6, "physical names")?;
        for _ in 0..n {
            let dpos = self.c.line();
            let dim = self.c.ascii_i64("physical group dimension")?;
            let tag = self.c.ascii_i64("physical tag")?;
            let name = self.c.rest_of_line();
            let name = String::from_utf8_lossy(name)
                .trim()
                .trim_matches('"')
                .to_string();
            let dim = i32::try_from(dim)
                .ok()
                .filter(|d| (0..=3).contains(d))
                .ok_or_else(|| {
                    self.c.error_at(
                        dpos,
                        false,
                        MeshErrorKind::Unexpected {
                            expected: "dimension 0..3".to_string(),
                            found: dim.to_string(),
                        },
                    )
                })?;
            self.names.insert((dim, tag), name);
        }
        self.c.expect("$EndPhysicalNames")
    }

    /// MSH 4.1 `$Entities`: the physical tags of every point, curve, surface and volume.
    fn read_entities(&mut self) -> Result<(), MeshError> {
        let binary = self.c.binary;
        let iw = if binary { 4 } else { 2 };
        let sw = if binary { self.c.size_width() } else { 2 };
        let mut counts = [0usize; 4];
        self.c.mark();
        for count in &mut counts {
            let pos = self.c.mark();
            let n = self.c.size("number of entities")?;
            // tag, ≥3 coordinates, a physical count.
            *count = self
                .c
                .check_count(pos, binary, n, iw + 3 * iw + sw, "entities")?;
        }
        self.c.end_record("the $Entities header")?;
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                self.c.mark();
                let tag = self.c.int("entity tag")?;
                for _ in 0..if dim == 0 { 3 } else { 6 } {
                    self.c.float("entity bounding box")?;
                }
                let pos = self.c.mark();
                let np = self.c.size("number of physical tags")?;
                let np = self.c.check_count(pos, binary, np, iw, "physical tags")?;
                let mut phys = Vec::with_capacity(np);
                for _ in 0..np {
                    phys.push(self.c.int("physical tag")?);
                }
                if dim > 0 {
                    let pos = self.c.mark();
                    let nb = self.c.size("number of bounding entities")?;
                    let nb = self
                        .c
                        .check_count(pos, binary, nb, iw, "bounding entities")?;
                    for _ in 0..nb {
                        self.c.int("bounding entity tag")?;
                    }
                }
                self.c.end_record("an entity line")?;
                if !phys.is_empty() {
                    self.entity_physicals.insert((dim as i32, tag), phys);
                }
            }
        }
        self.c.expect("$EndEntities")
    }

    /// A node or element tag of the record at `pos`: a C `int` (2.2) or `size_t` (4.1), and
    /// positive.
    fn read_tag(&mut self, pos: usize, what: &'static str) -> Result<u64, MeshError> {
        let (value, found) = match self.version {
            Version::V22 => {
                let v = self.c.int(what)?;
                (u64::try_from(v).unwrap_or(0), v.to_string())
            }
            Version::V41 => {
                let v = self.c.size(what)?;
                (v, v.to_string())
            }
        };
        if value == 0 {
            return Err(self
                .c
                .data_error(pos, MeshErrorKind::InvalidTag { what, found }));
        }
        Ok(value)
    }

    /// Reads x y z of node `tag` (record starting at `pos`), rejecting non-finite values.
    fn read_xyz(&mut self, pos: usize, tag: u64) -> Result<[f64; 3], MeshError> {
        let mut x = [0.0; 3];
        for v in &mut x {
            *v = self.c.float("node coordinate")?;
        }
        if !x.iter().all(|v| v.is_finite()) {
            return Err(self
                .c
                .data_error(pos, MeshErrorKind::NonFiniteCoordinate { node: tag }));
        }
        Ok(x)
    }

    fn set_nodes(&mut self, pos: usize, nodes: Vec<(u64, [f64; 3])>) -> Result<(), MeshError> {
        self.builder
            .set_nodes(nodes)
            .map_err(|kind| self.c.error_at(pos, false, kind))
    }

    /// MSH 2.2 `$Nodes`: count (ASCII line), then `tag x y z` per node.
    fn read_nodes_v22(&mut self) -> Result<(), MeshError> {
        let section = self.c.line();
        let n = self.c.ascii_u64("number of nodes")?;
        self.c.end_line("the node count")?;
        let n = self.c.check_count(
            section,
            false,
            n,
            if self.c.binary { 28 } else { 8 },
            "nodes",
        )?;
        let mut nodes = Vec::with_capacity(n);
        for _ in 0..n {
            let pos = self.c.mark();
            let tag = self.read_tag(pos, "node tag")?;
            let x = self.read_xyz(pos, tag)?;
            self.c.end_record("a node line")?;
            nodes.push((tag, x));
        }
        self.c.expect("$EndNodes")?;
        self.set_nodes(section, nodes)
    }

    /// MSH 4.1 `$Nodes`: entity blocks of tags, then coordinates.
    fn read_nodes_v41(&mut self) -> Result<(), MeshError> {
        let binary = self.c.binary;
        let sw = if binary { self.c.size_width() } else { 2 };
        let iw = if binary { 4 } else { 2 };
        let fw = if binary { 8 } else { 2 };
        let section = self.c.mark();
        let nblocks = self.c.size("number of node blocks")?;
        let total = self.c.size("number of nodes")?;
        self.c.size("minimum node tag")?;
        self.c.size("maximum node tag")?;
        self.c.end_record("the $Nodes header")?;
        let nblocks = self
            .c
            .check_count(section, binary, nblocks, 3 * iw + sw, "node blocks")?;
        let total = self
            .c
            .check_count(section, binary, total, sw + 3 * fw, "nodes")?;
        let mut nodes = Vec::with_capacity(total);
        let mut tags = Vec::new();
        for _ in 0..nblocks {
            let bpos = self.c.mark();
            let dim = self.c.int("entity dimension")?;
            self.c.int("entity tag")?;
            let parametric = self.c.int("parametric flag")?;
            let n = self.c.size("number of nodes in block")?;
            self.c.end_record("a node block header")?;
            let n = self
                .c
                .check_count(bpos, binary, n, sw + 3 * fw, "nodes in block")?;
            if nodes.len() + n > total {
                return Err(self.c.data_error(
                    bpos,
                    MeshErrorKind::CountMismatch {
                        what: "nodes",
                        declared: total as u64,
                        found: (nodes.len() + n) as u64,
                    },
                ));
            }
            let extra = if parametric != 0 { dim.clamp(0, 3) } else { 0 };
            tags.clear();
            for _ in 0..n {
                let pos = self.c.mark();
                tags.push(self.read_tag(pos, "node tag")?);
                self.c.end_record("a node tag line")?;
            }
            for &tag in &tags {
                let pos = self.c.mark();
                let x = self.read_xyz(pos, tag)?;
                for _ in 0..extra {
                    self.c.float("parametric coordinate")?;
                }
                self.c.end_record("a node coordinate line")?;
                nodes.push((tag, x));
            }
        }
        if nodes.len() != total {
            return Err(self.c.data_error(
                self.c.pos(),
                MeshErrorKind::CountMismatch {
                    what: "nodes",
                    declared: total as u64,
                    found: nodes.len() as u64,
                },
            ));
        }
        self.c.expect("$EndNodes")?;
        self.set_nodes(section, nodes)
    }

    /// Reads `count` node tags of element `tag` (record at `pos`) into `self.scratch` as node
    /// table indices.
    fn read_element_nodes(&mut self, pos: usize, tag: u64, count: usize) -> Result<(), MeshError> {
        self.scratch.clear();
        for _ in 0..count {
            let node = self.read_tag(pos, "element node tag")?;
            let index = self.builder.node_index(node).ok_or_else(|| {
                self.c
                    .data_error(pos, MeshErrorKind::MissingNode { element: tag, node })
            })?;
            self.scratch.push(index);
        }
        Ok(())
    }

    /// The physical group names (or numbers) of an element filed under `group` (MSH 2.2:
    /// its physical tag; 4.1: its entity, whose physical tags `$Entities` gave).
    fn group_names(&self, group: Option<(i32, i64)>) -> Vec<String> {
        let Some((dim, tag)) = group else {
            return Vec::new();
        };
        let name = |p: i64| {
            self.names
                .get(&(dim, p))
                .cloned()
                .unwrap_or_else(|| p.to_string())
        };
        match self.version {
            Version::V22 => vec![name(tag)],
            Version::V41 => self
                .entity_physicals
                .get(&(dim, tag))
                .into_iter()
                .flatten()
                .map(|&p| name(p))
                .collect(),
        }
    }

    /// Files the element in `self.scratch` (type `ty`, tag `tag`) and under `group` if any.
    fn add_element(&mut self, ty: i64, tag: u64, group: Option<(i32, i64)>) {
        if let (Some(select), 4 | 11) = (self.select, ty) {
            let names = self.group_names(group);
            let keep = names.iter().any(|n| n == select);
            self.volume_groups.extend(names);
            if !keep {
                return;
            }
            self.selected += 1;
        }
        let v = &self.scratch;
        match ty {
            4 => self.builder.push_tet(tag, [v[0], v[1], v[2], v[3]]),
            11 => self.builder.push_tet10(
                tag,
                [v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]],
            ),
            2 | 9 => self.builder.push_triangle([v[0], v[1], v[2]]),
            _ => self.count_skipped(ty, 1),
        }
        if let Some(key) = group {
            self.members
                .entry(key)
                .or_default()
                .extend_from_slice(&self.scratch);
        }
    }

    fn count_skipped(&mut self, ty: i64, n: u64) {
        match self.skipped.iter_mut().find(|s| s.0 == ty) {
            Some(s) => s.1 += n,
            None => self.skipped.push((ty, n)),
        }
    }

    /// MSH 2.2 `$Elements`. ASCII: `tag type ntags tags... nodes...` per line. Binary: blocks
    /// of `type count ntags` headers, each followed by `tag tags... nodes...` as `int`s.
    fn read_elements_v22(&mut self) -> Result<(), MeshError> {
        let section = self.c.line();
        let n = self.c.ascii_u64("number of elements")?;
        self.c.end_line("the element count")?;
        let binary = self.c.binary;
        let n = self.c.check_count(section, false, n, 8, "elements")?;
        let mut tags: Vec<i64> = Vec::new();
        if !binary {
            for _ in 0..n {
                let pos = self.c.mark();
                let tag = self.read_tag(pos, "element tag")?;
                let ty = self.c.ascii_i64("element type")?;
                let tpos = self.c.mark();
                let ntags = self.c.ascii_u64("number of element tags")?;
                let ntags = self.c.check_count(tpos, false, ntags, 2, "element tags")?;
                tags.clear();
                for _ in 0..ntags {
                    tags.push(self.c.ascii_i64("element tag")?);
                }
                let Some((nn, dim, _)) = element_info(ty) else {
                    self.c.rest_of_line();
                    self.count_skipped(ty, 1);
                    continue;
                };
                self.read_element_nodes(pos, tag, nn)?;
                self.c.end_record("an element line")?;
                let group = tags.first().filter(|&&p| p != 0).map(|&p| (dim, p));
                self.add_element(ty, tag, group);
            }
        } else {
            let mut read = 0usize;
            while read < n {
                let hpos = self.c.pos();
                let ty = self.c.int("element type")?;
                let follow = self.c.int("number of elements in block")?;
                let ntags = self.c.int("number of element tags")?;
                let Some((nn, dim, _)) = element_info(ty) else {
                    return Err(self
                        .c
                        .data_error(hpos, MeshErrorKind::UnsupportedElementType(ty)));
                };
                let ntags = usize::try_from(ntags).map_err(|_| {
                    self.c.data_error(
                        hpos,
                        MeshErrorKind::Unexpected {
                            expected: "non-negative number of element tags".to_string(),
                            found: ntags.to_string(),
                        },
                    )
                })?;
                let per = ntags
                    .checked_add(nn + 1)
                    .and_then(|k| k.checked_mul(4))
                    .unwrap_or(usize::MAX);
                let follow = u64::try_from(follow).unwrap_or(u64::MAX);
                let follow = self
                    .c
                    .check_count(hpos, true, follow, per, "elements in block")?;
                if follow > n - read {
                    return Err(self.c.data_error(
                        hpos,
                        MeshErrorKind::CountMismatch {
                            what: "elements",
                            declared: n as u64,
                            found: (read + follow) as u64,
                        },
                    ));
                }
                if follow == 0 {
                    return Err(self.c.data_error(
                        hpos,
                        MeshErrorKind::Unexpected {
                            expected: "a non-empty element block".to_string(),
                            found: "0 elements".to_string(),
                        },
                    ));
                }
                for _ in 0..follow {
                    let pos = self.c.pos();
                    let tag = self.read_tag(pos, "element tag")?;
                    tags.clear();
                    for _ in 0..ntags {
                        tags.push(self.c.int("element tag")?);
                    }
                    self.read_element_nodes(pos, tag, nn)?;
                    let group = tags.first().filter(|&&p| p != 0).map(|&p| (dim, p));
                    self.add_element(ty, tag, group);
                }
                read += follow;
            }
        }
        self.c.expect("$EndElements")
    }

    /// MSH 4.1 `$Elements`: entity blocks of `tag nodes...` records.
    fn read_elements_v41(&mut self) -> Result<(), MeshError> {
        let binary = self.c.binary;
        let sw = if binary { self.c.size_width() } else { 2 };
        let iw = if binary { 4 } else { 2 };
        let section = self.c.mark();
        let nblocks = self.c.size("number of element blocks")?;
        let total = self.c.size("number of elements")?;
        self.c.size("minimum element tag")?;
        self.c.size("maximum element tag")?;
        self.c.end_record("the $Elements header")?;
        let nblocks =
            self.c
                .check_count(section, binary, nblocks, 3 * iw + sw, "element blocks")?;
        let total = self
            .c
            .check_count(section, binary, total, 2 * sw, "elements")?;
        let mut read = 0usize;
        for _ in 0..nblocks {
            let bpos = self.c.mark();
            let dim = self.c.int("entity dimension")?;
            let entity = self.c.int("entity tag")?;
            let ty = self.c.int("element type")?;
            let n = self.c.size("number of elements in block")?;
            self.c.end_record("an element block header")?;
            let info = element_info(ty);
            let per = info.map_or(2, |(nn, _, _)| (nn + 1) * sw);
            let n = self
                .c
                .check_count(bpos, binary, n, per, "elements in block")?;
            if n > total - read {
                return Err(self.c.data_error(
                    bpos,
                    MeshErrorKind::CountMismatch {
                        what: "elements",
                        declared: total as u64,
                        found: (read + n) as u64,
                    },
                ));
            }
            read += n;
            let Some((nn, _, _)) = info else {
                if binary {
                    return Err(self
                        .c
                        .data_error(bpos, MeshErrorKind::UnsupportedElementType(ty)));
                }
                for _ in 0..n {
                    self.c.mark();
                    self.c.rest_of_line();
                }
                self.count_skipped(ty, n as u64);
                continue;
            };
            let group = i32::try_from(dim).ok().map(|d| (d, entity));
            for _ in 0..n {
                let pos = self.c.mark();
                let tag = self.read_tag(pos, "element tag")?;
                self.read_element_nodes(pos, tag, nn)?;
                self.c.end_record("an element line")?;
                self.add_element(ty, tag, group);
            }
        }
        if read != total {
            return Err(self.c.data_error(
                self.c.pos(),
                MeshErrorKind::CountMismatch {
                    what: "elements",
                    declared: total as u64,
                    found: read as u64,
                },
            ));
        }
        self.c.expect("$EndElements")
    }
}
