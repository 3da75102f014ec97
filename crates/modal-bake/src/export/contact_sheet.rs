//! [`render_contact_sheet`]: the lowest modes of a base side by side (the paper's Fig. 2), each
//! panel the surface displaced along one mode and coloured by the displacement magnitude,
//! rendered on the CPU (our z-buffer rasterizer into a tiny-skia pixmap, 2 × 2 supersampled).
//!
//! Camera: orthographic, fixed for every panel from the undeformed bounding box: looking at
//! its centre from azimuth `azimuth_deg` about +y and elevation `elevation_deg` (object frame,
//! y-up), the projected surface (grown by the largest displacement) filling the panel. Light: a
//! headlight, Lambert |n·l| with 35 % ambient. Colour: viridis of |u(v)| / max_v |u(v)| per
//! mode (dark = still, yellow = the largest displacement).

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
        }
    }
}

const BG: [f32; 3] = [1.0, 1.0, 1.0];
const SS: usize = 2;
const LABEL_H: usize = 22;

use crate::vec3::{cross, dot, sub};
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        a
    }
}

/// Renders the contact sheet of `base` (panels left to right, top to bottom; each labelled
/// `mode N  F Hz`).
///
/// # Errors
/// [`ExportError::Invalid`] for a mode count out of range, zero columns, a panel smaller than
/// 64 × 64 pixels, a non-positive scale, or a sheet above 8192 pixels on a side.
///
/// ```no_run
/// use modal_bake::export::{render_contact_sheet, SheetParams};
/// let base = dcr_runtime::format::ModesFile::read("table.modes".as_ref()).unwrap();
/// let png = render_contact_sheet(&base, &SheetParams::default()).unwrap().encode_png().unwrap();
/// ```
pub fn render_contact_sheet(base: &ModesFile, p: &SheetParams) -> Result<Pixmap, ExportError> {
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
    let rows = p.modes.div_ceil(cols);
    let (pw, ph) = (p.panel[0], p.panel[1]);
    let (w, h) = (cols * pw, rows * ph);
    if w > 8192 || h > 8192 {
        return Err(ExportError::Invalid(format!(
            "a {w} × {h} sheet is too large (at most 8192 pixels on a side)"
        )));
    }
    let mut pix = Pixmap::new(w as u32, h as u32)
        .ok_or_else(|| ExportError::Invalid("cannot allocate the image".into()))?;
    pix.fill(Color::WHITE);

    // Camera from the undeformed bounding box.
    let surf = ExportSurface::of(base);
    let (lo, hi) = bounding_box(&surf.positions);
    let centre = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    let diag = diagonal(&surf.positions);
    let (az, el) = (p.azimuth_deg.to_radians(), p.elevation_deg.to_radians());
    let eye = [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()];
    let right = normalize(cross([0.0, 1.0, 0.0], eye));
    let up = cross(eye, right);
    // Fit the projected undeformed surface, grown by the largest displacement, to the panel.
    let (mut x0s, mut x1s, mut y0s, mut y1s) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for q in &surf.positions {
        let d = sub(*q, centre);
        let (x, y) = (dot(d, right), dot(d, up));
        x0s = x0s.min(x);
        x1s = x1s.max(x);
        y0s = y0s.min(y);
        y1s = y1s.max(y);
    }
    let grow = 2.0 * p.scale * diag;
    let (ext_x, ext_y) = (x1s - x0s + grow, y1s - y0s + grow);
    let (mid_x, mid_y) = (0.5 * (x0s + x1s), 0.5 * (y0s + y1s));
    let ppm = 0.92 * (pw as f64 / ext_x).min((ph - LABEL_H) as f64 / ext_y);
    let ppm = if ppm.is_finite() && ppm > 0.0 {
        ppm
    } else {
        1.0
    };
    let tris = &surf.triangles;
    let freqs = base.frequencies_hz();
    let ns = surf.len();

    for j in 0..p.modes {
        let (col, row) = (j % cols, j / cols);
        let peak = surf.mode_max_norm(j);
        let a = if peak > 0.0 {
            p.scale * diag / peak
        } else {
            0.0
        };
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
        let (sw, sh) = (pw * SS, (ph - LABEL_H) * SS);
        let mut r = Raster::new(sw, sh, BG);
        let s = ppm * SS as f64;
        let screen = |q: [f64; 3]| -> [f32; 3] {
            let d = sub(q, centre);
            [
                (0.5 * sw as f64 + s * (dot(d, right) - mid_x)) as f32,
                (0.5 * sh as f64 - s * (dot(d, up) - mid_y)) as f32,
                (-dot(d, eye)) as f32,
            ]
        };
        for t in tris {
            let q = [pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]];
            let n = normalize(cross(sub(q[1], q[0]), sub(q[2], q[0])));
            let shade = (0.35 + 0.65 * dot(n, eye).abs()) as f32;
            let c = |i: usize| {
                let cv = col_v[t[i] as usize];
                [cv[0] * shade, cv[1] * shade, cv[2] * shade]
            };
            r.triangle(
                [screen(q[0]), screen(q[1]), screen(q[2])],
                [c(0), c(1), c(2)],
            );
        }
        let r = r.downsample(SS);
        let (x0, y0) = (col * pw, row * ph + LABEL_H);
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
        let label = format!("mode {}  {:.1} Hz", j + 1, freqs[j]);
        draw_text(
            &mut pix,
            &label,
            (x0 + 8) as f32,
            (row * ph + 4) as f32,
            2.0,
        );
    }
    // Thin panel separators.
    let mut paint = Paint::default();
    paint.set_color_rgba8(200, 200, 200, 255);
    for c in 1..cols {
        if let Some(rect) = Rect::from_xywh((c * pw) as f32, 0.0, 1.0, h as f32) {
            pix.fill_rect(rect, &paint, Transform::identity(), None);
        }
    }
    for rr in 1..rows {
        if let Some(rect) = Rect::from_xywh(0.0, (rr * ph) as f32, w as f32, 1.0) {
            pix.fill_rect(rect, &paint, Transform::identity(), None);
        }
    }
    Ok(pix)
}

/// Draws `text` in the 5 × 7 bitmap font, `px` pixels per dot, top-left at (x, y).
fn draw_text(pix: &mut Pixmap, text: &str, x: f32, y: f32, px: f32) {
    let mut paint = Paint::default();
    paint.set_color_rgba8(30, 30, 30, 255);
    paint.anti_alias = false;
    for (k, ch) in text.chars().enumerate() {
        let g = glyph(ch);
        let gx = x + k as f32 * 6.0 * px;
        for (row, bits) in g.iter().enumerate() {
            for colb in 0..5 {
                if bits & (0x10 >> colb) != 0 {
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
