//! Closed, outward-oriented test surfaces shared by the sizing and estimate tests (m).

use modal_bake::mesh::surface::SurfaceMesh;

/// A UV sphere of radius `r` (m): `rings` latitude bands, `segments` longitudes, outward.
pub fn uv_sphere(r: f64, rings: usize, segments: usize) -> SurfaceMesh {
    use std::f64::consts::PI;
    let mut v = vec![[0.0, 0.0, r]];
    for i in 1..rings {
        let th = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let ph = 2.0 * PI * j as f64 / segments as f64;
            v.push([
                r * th.sin() * ph.cos(),
                r * th.sin() * ph.sin(),
                r * th.cos(),
            ]);
        }
    }
    v.push([0.0, 0.0, -r]);
    let south = v.len() - 1;
    let at = |i: usize, j: usize| 1 + (i - 1) * segments + j % segments;
    let mut t = Vec::new();
    for j in 0..segments {
        t.push([0, at(1, j), at(1, j + 1)]);
        t.push([south, at(rings - 1, j + 1), at(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    SurfaceMesh {
        vertices: v,
        triangles: t,
    }
}

/// A closed cylinder along x from 0 to `len`, radius `r` (m): `segments` around, `stacks`
/// along, flat caps fanned from their centres; outward.
pub fn cylinder(r: f64, len: f64, segments: usize, stacks: usize) -> SurfaceMesh {
    use std::f64::consts::TAU;
    let mut v = Vec::new();
    for i in 0..=stacks {
        let x = len * i as f64 / stacks as f64;
        for j in 0..segments {
            let ph = TAU * j as f64 / segments as f64;
            v.push([x, r * ph.cos(), r * ph.sin()]);
        }
    }
    let at = |i: usize, j: usize| i * segments + j % segments;
    let mut t = Vec::new();
    for i in 0..stacks {
        for j in 0..segments {
            t.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    let (c0, c1) = (v.len(), v.len() + 1);
    v.push([0.0, 0.0, 0.0]);
    v.push([len, 0.0, 0.0]);
    for j in 0..segments {
        t.push([c0, at(0, j + 1), at(0, j)]);
        t.push([c1, at(stacks, j), at(stacks, j + 1)]);
    }
    SurfaceMesh {
        vertices: v,
        triangles: t,
    }
}
