"""Dinner table (paper Fig. 1, Table 1: 966 surface vertices): a 1.6 x 0.9 m top, 4 cm thick,
at 0.75 m, on four 6 cm square legs. Fixed: the feet (leg bottoms, y = 0)."""

import gmsh
from _common import box, fuse_all, surfaces_where, flat_at, physical, uniform_size

NAME = "table"
TARGET_SURFACE_VERTICES = 966
FIXED = ["feet"]
H = 0.080


def build():
    occ = gmsh.model.occ
    parts = [box(-0.8, 0.71, -0.45, 0.8, 0.75, 0.45)]
    for sx in (-1, 1):
        for sz in (-1, 1):
            x = sx * 0.70
            z = sz * 0.35
            parts.append(box(x - 0.03, 0.0, z - 0.03, x + 0.03, 0.71, z + 0.03))
    vols = fuse_all(parts)
    occ.synchronize()
    physical(vols, {
        "feet": surfaces_where(flat_at(1, 0.0)),
        "top": surfaces_where(flat_at(1, 0.75)),
    })
    uniform_size(H)
