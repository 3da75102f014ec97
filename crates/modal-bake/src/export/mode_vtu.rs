//! [`write_modes_vtu`]: a base's surface as a VTK XML unstructured grid (`.vtu`) with one
//! point-data vector array per mode, written with `vtkio` (XML, inline base64 binary arrays,
//! uncompressed) — the format ParaView and meshio read natively. Cell connectivity and
//! offsets are retagged from vtkio's UInt64 to VTK's usual Int64 (same bytes) so meshio reads
//! integer cells.

use std::path::Path;

use dcr_runtime::format::ModesFile;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use super::{mode_label, write_file_atomic, ExportError, ExportSurface};

/// Writes the surface of `base` with the lowest `modes` mode shapes to `path` (VTK XML
/// UnstructuredGrid, `.vtu`).
///
/// Points are the surface vertices (m, object frame); cells are the outward linear triangles
/// (VTK type 5). Point data, one three-component `Float64` array per mode named by
/// [`mode_label`] (e.g. `mode_01_12.3Hz`): the displacement (m, object frame) of each vertex for
/// a unit modal coordinate q_j = 1 kg^½·m, i.e. the surface rows of the M-orthonormal basis U.
/// Also `surface_to_volume` (`Int64`, the volume-mesh node of each vertex). In ParaView: *Warp
/// By Vector* with a mode's array; any scale factor shows the same shape.
///
/// The file is written atomically (temporary file + rename).
///
/// # Errors
/// [`ExportError::Invalid`] for `modes` of 0 or above the base's count, `Encode` if vtkio
/// refuses the content, `Io` on write failures.
///
/// ```no_run
/// let base = dcr_runtime::format::ModesFile::read("table.modes".as_ref()).unwrap();
/// modal_bake::export::write_modes_vtu(&base, 8, "table.vtu".as_ref()).unwrap();
/// ```
pub fn write_modes_vtu(base: &ModesFile, modes: usize, path: &Path) -> Result<(), ExportError> {
    let m = base.num_modes();
    if modes == 0 || modes > m {
        return Err(ExportError::Invalid(format!(
            "cannot export {modes} modes from a base with {m}"
        )));
    }
    let surf = ExportSurface::of(base);
    let ns = surf.len();
    let freqs = base.frequencies_hz();
    let tris = &surf.triangles;
    let points: Vec<f64> = surf.positions.iter().flatten().copied().collect();
    let connectivity: Vec<u64> = tris.iter().flatten().map(|&i| i as u64).collect();
    let offsets: Vec<u64> = (1..=tris.len() as u64).map(|k| 3 * k).collect();
    let mut point = Vec::with_capacity(modes + 1);
    for (j, &hz) in freqs.iter().enumerate().take(modes) {
        let data: Vec<f64> = (0..ns).flat_map(|v| surf.mode_vec(v, j)).collect();
        point.push(Attribute::DataArray(DataArray {
            name: mode_label(j, hz),
            elem: ElementType::Vectors,
            data: IOBuffer::F64(data),
        }));
    }
    point.push(Attribute::DataArray(DataArray {
        name: "surface_to_volume".into(),
        elem: ElementType::Scalars {
            num_comp: 1,
            lookup_table: None,
        },
        data: IOBuffer::I64(surf.volume_node.iter().map(|&i| i as i64).collect()),
    }));
    let vtk = Vtk {
        version: Version::new(),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity,
                    offsets,
                },
                types: vec![CellType::Triangle; tris.len()],
            },
            data: Attributes {
                point,
                cell: Vec::new(),
            },
        }),
    };
    let mut bytes = Vec::new();
    vtk.write_xml(&mut bytes).map_err(|e| ExportError::Encode {
        path: path.to_path_buf(),
        detail: format!("{e:?}"),
    })?;
    // vtkio types cell connectivity and offsets as UInt64; meshio mixes them with int64 and
    // hands its users float64 cell arrays. VTK's own writers use Int64 (vtkIdType): retag the
    // two arrays (same little-endian bytes, every index < 2^63).
    let text = String::from_utf8(bytes).map_err(|e| ExportError::Encode {
        path: path.to_path_buf(),
        detail: e.to_string(),
    })?;
    let text = text
        .replacen(
            r#"type="UInt64" Name="connectivity""#,
            r#"type="Int64" Name="connectivity""#,
            1,
        )
        .replacen(
            r#"type="UInt64" Name="offsets""#,
            r#"type="Int64" Name="offsets""#,
            1,
        );
    write_file_atomic(path, text.as_bytes())
}
