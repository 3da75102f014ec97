//! [`render_contact_sheet`]: the lowest modes of a base side by side (the paper's Fig. 2), each
//! panel the surface displaced along one mode and coloured by the displacement magnitude over
//! a light-grey ghost of the rest shape (and its outline over the displaced surface), rendered on the CPU (our z-buffer rasterizer into a
//! tiny-skia pixmap, 2 × 2 supersampled). A title band names the object, the material and the
//! mesh; a legend band gives the colour scale and what it means.
//!
//! Camera: orthographic, per mode, chosen so the mode's motion lies in the image plane: d is
//! the dominant displacement direction (largest eigenvector of Σ_v u(v) u(v)ᵀ over the surface
//! vertices, by power iteration), and the view direction is the default one (azimuth
//! `azimuth_deg` about +y, elevation `elevation_deg`, object frame, y-up) with its component
//! along d removed — the nearest view that sees d side-on. A mode moving along the default
//! line of sight (invisible from the fixed camera) is therefore drawn from the side. The
//! projected rest and displaced surfaces fill the panel. Light: a headlight, Lambert |n·l|
//! with 35 % ambient. Colour: viridis of |u(v)| / max_v |u(v)| per mode (dark = still, yellow
//! = the largest displacement; normalised per mode, no unit).

use std::path::Path;

use dcr_runtime::format::ModesFile;
use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

use super::raster::{glyph, viridis, Raster};
use super::{bounding_box, diagonal, write_file_atomic, ExportError, ExportSurface};

/// Settings of [`render_contact_sheet`].
#[derive(Clone, Debug)]
pub struct SheetParams {
    /// Number of the lowest modes shown (1..=m).
    pub modes: usize,
    /// Panels per row. Default 4.
    pub columns: usize,
    /// Panel size (pixels). Default 320 × 240.
    pub panel: [usize; 2],
    /// Largest displacement drawn, as a fraction of the bounding-box diagonal. Default 0.05.
    pub scale: f64,
    /// Camera azimuth about +y (deg, 0 = looking along −z). Default 30.
    pub azimuth_deg: f64,
    /// Camera elevation above the x–z plane (deg). Default 25.
    pub elevation_deg: f64,
    /// Object name for the title band (e.g. the base's file stem); empty: "modes".
    pub title: String,
}

impl Default for SheetParams {
    fn default() -> Self {
        SheetParams {
            modes: 8,
            columns: 4,
            panel: [320, 240],
            scale: 0.05,
            azimuth_deg: 30.0,
            elevation_deg: 25.0,
            title: String::new(),
        }
    }
}

const BG: [f32; 3] = [1.0, 1.0, 1.0];
/// Rest-shape ghost colour (light grey).
const GHOST: [f32; 3] = [0.84, 0.84, 0.86];
/// Grey level of the rest shape's outline drawn over the displaced surface.
const OUTLINE: f32 = 0.97;
const SS: usize = 2;
const LABEL_H: usize = 22;
/// Height of the title band above the panels (pixels).
pub const SHEET_TITLE_H: usize = 44;
/// Height of the legend band below the panels (pixels).
pub const SHEET_LEGEND_H: usize = 56;

use dcr_runtime::math::{cross, dot, sub};
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        a
    }
}

/// Renders the contact sheet of `base`: a title band ([`SHEET_TITLE_H`] pixels: object,
/// material, mesh), the panels left to right, top to bottom (each labelled `mode N  F Hz`,
/// each from its own camera, see the module doc), and a legend band ([`SHEET_LEGEND_H`]
/// pixels: the colour scale and the drawn amplitude).
///
/// # Errors
/// [`ExportError::Invalid`] for a mode count out of range, zero columns, a panel smaller than
/// 64 × 86 pixels, a non-positive scale, or a sheet above 8192 pixels on a side.
///
/// ```no_run
/// use modal_bake::export::{render_contact_sheet, SheetParams};
/// let base = dcr_runtime::format::ModesFile::read("table.modes".as_ref()).unwrap();
/// let png = render_contact_sheet(&base, &SheetParams::default()).unwrap().encode_png().unwrap();
/// ```
pub fn render_contact_sheet(base: &ModesFile, p: &SheetParams) -> Result<Pixmap, ExportError> {
    let (cols, rows) = sheet_grid(base, p)?;
    let (pw, ph) = (p.panel[0], p.panel[1]);
    let (w, h) = (
        (cols * pw).max(1080),
        SHEET_TITLE_H + rows * ph + SHEET_LEGEND_H,
    );
    if w > 8192 || h > 8192 {
        return Err(ExportError::Invalid(format!(
            "a {w} × {h} sheet is too large (at most 8192 pixels on a side)"
        )));
    }
    let mut pix = Pixmap::new(w as u32, h as u32)
        .ok_or_else(|| ExportError::Invalid("cannot allocate the image".into()))?;
    pix.fill(Color::WHITE);

    let surf = ExportSurface::of(base);
    let (lo, hi) = bounding_box(&surf.positions);
    let centre = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    let (az, el) = (p.azimuth_deg.to_radians(), p.elevation_deg.to_radians());
    let panel = PanelView {
        surf: &surf,
        centre,
        diag: diagonal(&surf.positions),
        eye0: [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()],
        size: [pw, ph - LABEL_H],
        scale: p.scale,
    };
    let freqs = base.frequencies_hz();
    for j in 0..p.modes {
        let (col, row) = (j % cols, j / cols);
        let r = panel.render(j);
        let (x0, y0) = (col * pw, SHEET_TITLE_H + row * ph + LABEL_H);
        blit(&mut pix, &r, x0, y0);
        let label = format!("mode {}  {} Hz", j + 1, format_hz(freqs[j]));
        draw_text(
            &mut pix,
            &label,
            (x0 + 8) as f32,
            (SHEET_TITLE_H + row * ph + 3) as f32,
            2.0,
        );
    }
    draw_separators(&mut pix, [cols, rows], [pw, ph]);
    draw_title(&mut pix, base, p);
    draw_legend(&mut pix, p, SHEET_TITLE_H + rows * ph);
    Ok(pix)
}

/// The sheet's (columns, rows) after checking the mode count, the panel size and the scale.
fn sheet_grid(base: &ModesFile, p: &SheetParams) -> Result<(usize, usize), ExportError> {
    let m = base.num_modes();
    if p.modes == 0 || p.modes > m {
        return Err(ExportError::Invalid(format!(
            "cannot show {} modes from a base with {m}",
            p.modes
        )));
    }
    if p.columns == 0 || p.panel[0] < 64 || p.panel[1] < 64 + LABEL_H {
        return Err(ExportError::Invalid(
            "the sheet needs at least one column and panels of at least 64 × 86 pixels".into(),
        ));
    }
    if !(p.scale > 0.0 && p.scale <= super::MAX_SCALE) {
        return Err(ExportError::Invalid(format!(
            "parameter `scale` (--scale) must be in (0, {}] (the largest displacement as a \
             fraction of the bounding-box diagonal), got {}",
            super::MAX_SCALE,
            p.scale
        )));
    }
    let cols = p.columns.min(p.modes);
    Ok((cols, p.modes.div_ceil(cols)))
}

/// What every panel of a sheet shares: the surface, its centre (m) and diagonal (m), the
/// default view direction, the picture's size in pixels (without the label) and the scale.
struct PanelView<'a> {
    surf: &'a ExportSurface,
    centre: [f64; 3],
    diag: f64,
    eye0: [f64; 3],
    size: [usize; 2],
    scale: f64,
}

impl PanelView<'_> {
    /// Mode `j`'s picture: the surface displaced by the mode (largest displacement
    /// `scale · diag`), coloured by displacement magnitude, over its rest shape, seen from the
    /// mode's view direction and fitted to the panel; rendered at [`SS`]× and downsampled.
    fn render(&self, j: usize) -> Raster {
        let (surf, centre) = (self.surf, self.centre);
        let ns = surf.len();
        let peak = surf.mode_max_norm(j);
        let a = if peak > 0.0 {
            self.scale * self.diag / peak
        } else {
            0.0
        };
        let eye = view_for_mode(surf, j, self.eye0);
        let right = normalize(if cross([0.0, 1.0, 0.0], eye) == [0.0; 3] {
            [1.0, 0.0, 0.0]
        } else {
            cross([0.0, 1.0, 0.0], eye)
        });
        let up = cross(eye, right);
        // Displaced positions (object frame) and per-vertex colour.
        let mut pos = Vec::with_capacity(ns);
        let mut col_v = Vec::with_capacity(ns);
        for v in 0..ns {
            let u = surf.mode_vec(v, j);
            let x = surf.positions[v];
            pos.push([x[0] + a * u[0], x[1] + a * u[1], x[2] + a * u[2]]);
            let mag = dot(u, u).sqrt();
            col_v.push(viridis(if peak > 0.0 { mag / peak } else { 0.0 }));
        }
        // Fit the projected rest and displaced surfaces to the panel.
        let (mut x0s, mut x1s, mut y0s, mut y1s) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for q in surf.positions.iter().chain(&pos) {
            let d = sub(*q, centre);
            let (x, y) = (dot(d, right), dot(d, up));
            x0s = x0s.min(x);
            x1s = x1s.max(x);
            y0s = y0s.min(y);
            y1s = y1s.max(y);
        }
        let (ext_x, ext_y) = (x1s - x0s, y1s - y0s);
        let (mid_x, mid_y) = (0.5 * (x0s + x1s), 0.5 * (y0s + y1s));
        let [pw, ph] = self.size;
        let ppm = 0.92 * (pw as f64 / ext_x).min(ph as f64 / ext_y);
        let ppm = if ppm.is_finite() && ppm > 0.0 {
            ppm
        } else {
            1.0
        };
        let (sw, sh) = (pw * SS, ph * SS);
        let s = ppm * SS as f64;
        let screen = |q: [f64; 3]| -> [f32; 3] {
            let d = sub(q, centre);
            [
                (0.5 * sw as f64 + s * (dot(d, right) - mid_x)) as f32,
                (0.5 * sh as f64 - s * (dot(d, up) - mid_y)) as f32,
                (-dot(d, eye)) as f32,
            ]
        };
        let draw = |points: &[[f64; 3]], colour: &dyn Fn(usize) -> [f32; 3]| {
            let mut r = Raster::new(sw, sh, BG);
            for t in &surf.triangles {
                let q = [
                    points[t[0] as usize],
                    points[t[1] as usize],
                    points[t[2] as usize],
                ];
                let n = normalize(cross(sub(q[1], q[0]), sub(q[2], q[0])));
                let shade = (0.35 + 0.65 * dot(n, eye).abs()) as f32;
                let c = |i: usize| colour(t[i] as usize).map(|x| x * shade);
                r.triangle(
                    [screen(q[0]), screen(q[1]), screen(q[2])],
                    [c(0), c(1), c(2)],
                );
            }
            r
        };
        let ghost = draw(&surf.positions, &|_| GHOST);
        let mut r = draw(&pos, &|v| col_v[v]);
        overlay_rest_shape(&mut r, &ghost, sw, sh);
        r.downsample(SS)
    }
}

/// The rest shape (`ghost`) shows where the displaced surface (`r`, `sw` × `sh`) does not
/// cover it, and its outline is drawn over the displaced surface (motion within the
/// silhouette: stretching, twisting).
fn overlay_rest_shape(r: &mut Raster, ghost: &Raster, sw: usize, sh: usize) {
    let covered: Vec<bool> = ghost.color.iter().map(|g| *g != BG).collect();
    for (k, (c, g)) in r.color.iter_mut().zip(&ghost.color).enumerate() {
        if *c == BG {
            *c = *g;
        } else if covered[k] {
            let (x, y) = (k % sw, k / sw);
            let edge = x == 0
                || y == 0
                || x + 1 == sw
                || y + 1 == sh
                || !covered[k - 1]
                || !covered[k + 1]
                || !covered[k - sw]
                || !covered[k + sw];
            if edge {
                *c = c.map(|v| 0.35 * v + 0.65 * OUTLINE);
            }
        }
    }
}

/// Thin separators between the `[cols, rows]` panels of `[pw, ph]` pixels.
fn draw_separators(pix: &mut Pixmap, [cols, rows]: [usize; 2], [pw, ph]: [usize; 2]) {
    let mut paint = Paint::default();
    paint.set_color_rgba8(200, 200, 200, 255);
    let w = pix.width() as f32;
    let panels_h = (rows * ph) as f32;
    for c in 1..cols {
        if let Some(rect) = Rect::from_xywh((c * pw) as f32, SHEET_TITLE_H as f32, 1.0, panels_h) {
            pix.fill_rect(rect, &paint, Transform::identity(), None);
        }
    }
    for rr in 0..=rows {
        let y = (SHEET_TITLE_H + rr * ph) as f32;
        if let Some(rect) = Rect::from_xywh(0.0, y, w, 1.0) {
            pix.fill_rect(rect, &paint, Transform::identity(), None);
        }
    }
}

/// Frequency for a label: one decimal from 1 Hz, three significant digits below.
fn format_hz(hz: f64) -> String {
    if hz >= 1.0 {
        format!("{hz:.1}")
    } else {
        super::format_sig(hz, 3)
    }
}

/// Copies a raster (linear 0..1 colours) into the pixmap at (x0, y0).
fn blit(pix: &mut Pixmap, r: &Raster, x0: usize, y0: usize) {
    let w = pix.width() as usize;
    let data = pix.data_mut();
    for y in 0..r.h {
        for x in 0..r.w {
            let c = r.color[y * r.w + x];
            let i = ((y0 + y) * w + x0 + x) * 4;
            data[i] = (c[0].clamp(0.0, 1.0) * 255.0).round() as u8;
            data[i + 1] = (c[1].clamp(0.0, 1.0) * 255.0).round() as u8;
            data[i + 2] = (c[2].clamp(0.0, 1.0) * 255.0).round() as u8;
            data[i + 3] = 255;
        }
    }
}

/// The view direction (unit, object frame, pointing from the object to the camera) for mode
/// j: `eye0` with its component along the mode's dominant displacement direction d removed,
/// so that d lies in the image plane. When `eye0` is within ~12° of ±d, the horizontal
/// direction perpendicular to d (or +z when d is vertical) is used instead.
pub(crate) fn view_for_mode(surf: &ExportSurface, j: usize, eye0: [f64; 3]) -> [f64; 3] {
    let d = dominant_direction(surf, j);
    if d == [0.0; 3] {
        return eye0;
    }
    let e = sub(eye0, scale3(d, dot(eye0, d)));
    if dot(e, e).sqrt() > 0.2 {
        return normalize(e);
    }
    let side = cross(d, [0.0, 1.0, 0.0]);
    if dot(side, side).sqrt() > 1e-6 {
        normalize(side)
    } else {
        [0.0, 0.0, 1.0]
    }
}

fn scale3(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Largest eigenvector of C = Σ_v u(v) u(v)ᵀ (the mode's dominant displacement direction,
/// unit; zero for a zero mode), by 60 power iterations from the axis with the largest
/// diagonal entry. Deterministic.
pub(crate) fn dominant_direction(surf: &ExportSurface, j: usize) -> [f64; 3] {
    let mut c = [[0.0; 3]; 3];
    for v in 0..surf.len() {
        let u = surf.mode_vec(v, j);
        for (a, row) in c.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate() {
                *x += u[a] * u[b];
            }
        }
    }
    let k = (0..3)
        .max_by(|&a, &b| c[a][a].total_cmp(&c[b][b]))
        .unwrap_or(0);
    if !(c[k][k] > 0.0) {
        return [0.0; 3];
    }
    let mut x = [0.0; 3];
    x[k] = 1.0;
    for _ in 0..60 {
        let y = [dot(c[0], x), dot(c[1], x), dot(c[2], x)];
        let n = dot(y, y).sqrt();
        if !(n > 0.0) {
            break;
        }
        x = scale3(y, 1.0 / n);
    }
    x
}

/// Title band: object, material (name when the bake recorded one; E, ν, ρ) and mesh.
fn draw_title(pix: &mut Pixmap, base: &ModesFile, p: &SheetParams) {
    let mat = &base.material;
    let name = base
        .meta
        .bake_params
        .get("material")
        .and_then(|m| m.get("name").or(Some(m)))
        .and_then(|n| n.as_str())
        .map(|n| format!("{n}: "))
        .unwrap_or_default();
    let object = if p.title.is_empty() {
        "modes"
    } else {
        p.title.as_str()
    };
    let order = if base.quadratic.is_some() { 2 } else { 1 };
    let line1 = format!(
        "{object} - {name}E {} GPa, nu {:.3}, rho {:.0} kg/m3",
        super::format_sig(mat.youngs / 1e9, 3),
        mat.poisson,
        mat.density
    );
    let fixed = if base.fixed_nodes.is_empty() {
        "free-free".to_string()
    } else {
        format!("{} fixed nodes", base.fixed_nodes.len())
    };
    let line2 = format!(
        "mesh: {} nodes, {} tetrahedra, order {order} ({}-node); {fixed}; {} modes shown",
        base.meta.volume_nodes,
        base.meta.volume_tets,
        if order == 2 { 10 } else { 4 },
        p.modes
    );
    draw_text(pix, &line1, 8.0, 4.0, 2.0);
    draw_text(pix, &line2, 8.0, 26.0, 1.0);
}

/// Legend band at `y0`: the viridis bar from 0 to 1 and what colour and shape mean.
fn draw_legend(pix: &mut Pixmap, p: &SheetParams, y0: usize) {
    let (bx, by, bw, bh) = (8usize, y0 + 8, 200usize, 14usize);
    let mut paint = Paint::default();
    for x in 0..bw {
        let c = viridis(x as f64 / (bw - 1) as f64);
        paint.set_color_rgba8(
            (c[0] * 255.0).round() as u8,
            (c[1] * 255.0).round() as u8,
            (c[2] * 255.0).round() as u8,
            255,
        );
        if let Some(rect) = Rect::from_xywh((bx + x) as f32, by as f32, 1.0, bh as f32) {
            pix.fill_rect(rect, &paint, Transform::identity(), None);
        }
    }
    draw_text(pix, "0", bx as f32, (by + bh + 3) as f32, 1.0);
    draw_text(pix, "1", (bx + bw - 8) as f32, (by + bh + 3) as f32, 1.0);
    let tx = (bx + bw + 12) as f32;
    draw_text(
        pix,
        "colour: displacement magnitude |u| / max |u| of each mode (normalised, no unit)",
        tx,
        by as f32,
        1.0,
    );
    draw_text(
        pix,
        &format!(
            "grey: rest shape; largest displacement drawn = {} % of the diagonal; view side-on to each mode's motion",
            super::format_sig(100.0 * p.scale, 3)
        ),
        tx,
        (by + 14) as f32,
        1.0,
    );
}

/// Draws `text` in the 8 × 8 public-domain bitmap font of the `font8x8` crate (printable
/// ASCII; other characters are blank), `px` pixels per dot, top-left at (x, y).
fn draw_text(pix: &mut Pixmap, text: &str, x: f32, y: f32, px: f32) {
    let mut paint = Paint::default();
    paint.set_color_rgba8(30, 30, 30, 255);
    paint.anti_alias = false;
    for (k, ch) in text.chars().enumerate() {
        let g = glyph(ch);
        let gx = x + k as f32 * 8.0 * px;
        for (row, bits) in g.iter().enumerate() {
            for colb in 0..8 {
                if bits & (1 << colb) != 0 {
                    if let Some(rect) =
                        Rect::from_xywh(gx + colb as f32 * px, y + row as f32 * px, px, px)
                    {
                        pix.fill_rect(rect, &paint, Transform::identity(), None);
                    }
                }
            }
        }
    }
}

/// Renders the contact sheet and writes it as PNG to `path` (atomically).
///
/// # Errors
/// As [`render_contact_sheet`]; `Encode` if PNG encoding fails; `Io` on write failures.
pub fn write_modes_png(base: &ModesFile, p: &SheetParams, path: &Path) -> Result<(), ExportError> {
    let pix = render_contact_sheet(base, p)?;
    let bytes = pix.encode_png().map_err(|e| ExportError::Encode {
        path: path.to_path_buf(),
        detail: e.to_string(),
    })?;
    write_file_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use dcr_runtime::testing::{box_surface, synthetic_base};

    /// A 1 × 0.2 × 0.1 m box base whose mode 0 translates every vertex along `d0` and mode 1
    /// along `d1` (unit vectors; the rows are not M-orthonormal, which the sheet does not need).
    fn translating_base(d0: [f64; 3], d1: [f64; 3]) -> ModesFile {
        let mut base = synthetic_base(
            box_surface(4, [1.0, 0.2, 0.1]),
            &[100.0, 200.0],
            [0.0, 0.0],
            7,
        );
        let m = base.num_modes();
        for v in 0..base.surface_vertices.len() {
            for a in 0..3 {
                base.modes[(v * 3 + a) * m] = d0[a];
                base.modes[(v * 3 + a) * m + 1] = d1[a];
            }
        }
        base
    }

    fn default_eye() -> [f64; 3] {
        let p = SheetParams::default();
        let (az, el) = (p.azimuth_deg.to_radians(), p.elevation_deg.to_radians());
        [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()]
    }

    /// Each mode's camera sees its dominant direction side-on: view ⟂ d, also when d is the
    /// default line of sight; for d ⟂ the default view, the default view is kept.
    #[test]
    fn each_modes_view_is_perpendicular_to_its_dominant_motion() {
        let eye0 = default_eye();
        let x = [1.0, 0.0, 0.0];
        let base = translating_base(eye0, x);
        let surf = ExportSurface::of(&base);
        for (j, d) in [(0, eye0), (1, x)] {
            let dd = dominant_direction(&surf, j);
            assert!((dot(dd, d).abs() - 1.0).abs() < 1e-9, "mode {j}: {dd:?}");
            let e = view_for_mode(&surf, j, eye0);
            assert!((dot(e, e) - 1.0).abs() < 1e-12);
            assert!(
                dot(e, d).abs() < 1e-9,
                "mode {j}: view {e:?} sees d {d:?} head-on"
            );
        }
        let base = translating_base([-eye0[2], 0.0, eye0[0]], x);
        let e = view_for_mode(&ExportSurface::of(&base), 0, eye0);
        assert!((dot(e, eye0) - 1.0).abs() < 1e-9, "{e:?}");
    }

    /// Light-grey rest-shape pixels left uncovered by the displaced surface in panel j.
    fn ghost_pixels(pix: &Pixmap, p: &SheetParams, j: usize) -> usize {
        let (pw, ph) = (p.panel[0] as u32, p.panel[1] as u32);
        let (x0, y0) = (
            (j % p.columns) as u32 * pw,
            SHEET_TITLE_H as u32 + (j / p.columns) as u32 * ph,
        );
        let mut n = 0;
        for y in y0 + LABEL_H as u32 + 1..y0 + ph - 1 {
            for x in x0 + 1..x0 + pw - 1 {
                let c = pix.pixel(x, y).unwrap();
                let (r, g, b) = (c.red() as i32, c.green() as i32, c.blue() as i32);
                if (r - g).abs() < 6 && (g - b).abs() < 8 && (60..225).contains(&r) {
                    n += 1;
                }
            }
        }
        n
    }

    /// A mode moving along the default line of sight (invisible to a fixed orthographic
    /// camera: the displaced surface would cover the rest shape exactly) shows its motion: the
    /// rest shape's ghost is visible beside the displaced surface, as for a sideways mode.
    #[test]
    fn a_mode_along_the_default_line_of_sight_is_drawn_visibly_moving() {
        let base = translating_base(default_eye(), [1.0, 0.0, 0.0]);
        let p = SheetParams {
            modes: 2,
            scale: 0.1,
            ..Default::default()
        };
        let pix = render_contact_sheet(&base, &p).unwrap();
        assert_eq!(
            pix.height() as usize,
            SHEET_TITLE_H + p.panel[1] + SHEET_LEGEND_H
        );
        for j in 0..2 {
            let n = ghost_pixels(&pix, &p, j);
            assert!(n > 500, "mode {j}: only {n} rest-shape pixels visible");
        }
    }
}
