//! A z-buffered triangle rasterizer with per-vertex colours (Gouraud) for the contact sheet.
//!
//! tiny-skia (used for the image, the overlay and PNG encoding) fills 2D paths with one paint
//! each; it has no depth buffer and no per-vertex colour interpolation over triangles, which a
//! shaded surface with a colour field needs, so this one is our own: edge functions over each
//! triangle's pixel bounding box, pixel centres at +½, closer = smaller depth.

/// An RGB colour image (linear 0..1 floats) with a depth buffer.
pub(crate) struct Raster {
    pub w: usize,
    pub h: usize,
    pub color: Vec<[f32; 3]>,
    depth: Vec<f32>,
}

impl Raster {
    /// A `w × h` image filled with `bg`, depth at +∞.
    pub fn new(w: usize, h: usize, bg: [f32; 3]) -> Raster {
        Raster {
            w,
            h,
            color: vec![bg; w * h],
            depth: vec![f32::INFINITY; w * h],
        }
    }

    /// Draws a triangle: screen positions (x right, y down, pixels) with depth, and a colour
    /// per corner interpolated barycentrically. Either winding; degenerate triangles draw
    /// nothing.
    pub fn triangle(&mut self, p: [[f32; 3]; 3], c: [[f32; 3]; 3]) {
        let area =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        if !(area.abs() > 1e-12) {
            return;
        }
        let xmin = p
            .iter()
            .map(|q| q[0])
            .fold(f32::INFINITY, f32::min)
            .floor()
            .max(0.0) as usize;
        let ymin = p
            .iter()
            .map(|q| q[1])
            .fold(f32::INFINITY, f32::min)
            .floor()
            .max(0.0) as usize;
        let xmax = (p
            .iter()
            .map(|q| q[0])
            .fold(f32::NEG_INFINITY, f32::max)
            .ceil() as isize)
            .min(self.w as isize - 1);
        let ymax = (p
            .iter()
            .map(|q| q[1])
            .fold(f32::NEG_INFINITY, f32::max)
            .ceil() as isize)
            .min(self.h as isize - 1);
        if xmax < 0 || ymax < 0 {
            return;
        }
        let inv = 1.0 / area;
        for y in ymin..=ymax as usize {
            let py = y as f32 + 0.5;
            for x in xmin..=xmax as usize {
                let px = x as f32 + 0.5;
                let w0 = ((p[1][0] - px) * (p[2][1] - py) - (p[2][0] - px) * (p[1][1] - py)) * inv;
                let w1 = ((p[2][0] - px) * (p[0][1] - py) - (p[0][0] - px) * (p[2][1] - py)) * inv;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * p[0][2] + w1 * p[1][2] + w2 * p[2][2];
                let i = y * self.w + x;
                if z < self.depth[i] {
                    self.depth[i] = z;
                    self.color[i] = [
                        w0 * c[0][0] + w1 * c[1][0] + w2 * c[2][0],
                        w0 * c[0][1] + w1 * c[1][1] + w2 * c[2][1],
                        w0 * c[0][2] + w1 * c[1][2] + w2 * c[2][2],
                    ];
                }
            }
        }
    }

    /// Box-filtered downsampling by an integer factor.
    pub fn downsample(&self, f: usize) -> Raster {
        let (w, h) = (self.w / f, self.h / f);
        let mut out = Raster::new(w, h, [0.0; 3]);
        let norm = 1.0 / (f * f) as f32;
        for y in 0..h {
            for x in 0..w {
                let mut s = [0.0f32; 3];
                for dy in 0..f {
                    for dx in 0..f {
                        let c = self.color[(y * f + dy) * self.w + x * f + dx];
                        s[0] += c[0];
                        s[1] += c[1];
                        s[2] += c[2];
                    }
                }
                out.color[y * w + x] = [s[0] * norm, s[1] * norm, s[2] * norm];
            }
        }
        out
    }
}

/// Viridis colour map (perceptually uniform), t in [0, 1] clamped; sRGB 0..1.
pub(crate) fn viridis(t: f64) -> [f32; 3] {
    const STOPS: [[f32; 3]; 9] = [
        [0.267, 0.005, 0.329],
        [0.283, 0.141, 0.458],
        [0.254, 0.265, 0.530],
        [0.207, 0.372, 0.553],
        [0.164, 0.471, 0.558],
        [0.128, 0.567, 0.551],
        [0.135, 0.659, 0.518],
        [0.478, 0.821, 0.319],
        [0.993, 0.906, 0.144],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t as f32 * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    [
        a[0] + f * (b[0] - a[0]),
        a[1] + f * (b[1] - a[1]),
        a[2] + f * (b[2] - a[2]),
    ]
}

/// The 8 × 8 glyph of `ch` (rows top to bottom, bit k = column k from the left; the
/// public-domain font of the `font8x8` crate); blank outside printable ASCII.
pub(crate) fn glyph(ch: char) -> [u8; 8] {
    let i = ch as usize;
    if (0x20..0x7f).contains(&i) {
        font8x8::legacy::BASIC_LEGACY[i]
    } else {
        [0; 8]
    }
}
