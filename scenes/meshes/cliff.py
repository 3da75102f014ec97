"""Craggy cliff / stone wall for the rockfall (paper Table 1: 7182 surface vertices): an
8 m wide, 5 m tall, 0.9 m thick wall (face at z = 0.4, back at z = -0.5) with crags
(tilted blocks) fused onto its face and a flat top ledge where the rocks sit.
Fixed: the back (z = -0.5) and the bottom (y = 0)."""

import math

import gmsh
from _common import box, fuse_all, surfaces_where, flat_at, physical, graded_size

NAME = "cliff"
TARGET_SURFACE_VERTICES = 7182
FIXED = ["back", "bottom"]
H = 0.095

# (centre x, centre y, half sizes (x, y, z), tilt about z, tilt about x) of each crag.
CRAGS = [
    (-2.6, 1.2, (0.7, 0.5, 0.3), 0.3, 0.2),
    (-0.8, 2.6, (0.9, 0.4, 0.25), -0.2, 0.25),
    (1.5, 1.0, (0.8, 0.6, 0.35), 0.15, -0.2),
    (2.7, 3.2, (0.6, 0.5, 0.3), -0.35, 0.15),
    (0.4, 4.0, (1.0, 0.35, 0.2), 0.1, 0.3),
    (-2.9, 3.7, (0.5, 0.45, 0.25), 0.4, -0.1),
]


def build():
    occ = gmsh.model.occ
    parts = [box(-4.0, 0.0, -0.5, 4.0, 5.0, 0.4)]
    for cx, cy, (hx, hy, hz), rz, rx in CRAGS:
        b = box(cx - hx, cy - hy, 0.4 - hz, cx + hx, cy + hy, 0.4 + hz)
        occ.rotate([(3, b)], cx, cy, 0.4, 0, 0, 1, rz)
        occ.rotate([(3, b)], cx, cy, 0.4, 1, 0, 0, rx)
        parts.append(b)
    vols = fuse_all(parts)
    # Keep the crags inside the wall's footprint (no overhang below y = 0 or above the top).
    clip = box(-4.0, 0.0, -0.5, 4.0, 5.0, 2.0)
    out, _ = occ.intersect([(3, v) for v in vols], [(3, clip)])
    vols = [t for d, t in out if d == 3]
    occ.synchronize()
    physical(vols, {
        "back": surfaces_where(flat_at(2, -0.5)),
        "bottom": surfaces_where(flat_at(1, 0.0)),
        "top": surfaces_where(flat_at(1, 5.0)),
    })
    graded_size(H, 0.35, 0.3)
