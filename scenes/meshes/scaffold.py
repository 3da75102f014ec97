"""Two-level scaffold (paper Fig. 7, Table 1: 5384 surface vertices): four 6 cm square posts
on a 2.4 x 0.8 m footprint, 2.2 m tall, with 4 cm decks at y = 1.0 and y = 2.0 (tops at 1.04
and 2.04) and a toe rail along the back of each deck. Fixed: the feet (post bottoms, y = 0)."""

import gmsh
from _common import box, fuse_all, surfaces_where, flat_at, physical, uniform_size

NAME = "scaffold"
TARGET_SURFACE_VERTICES = 5384
FIXED = ["feet"]
H = 0.058


def build():
    occ = gmsh.model.occ
    parts = []
    for x in (-1.2, 1.2):
        for z in (-0.4, 0.4):
            parts.append(box(x - 0.03, 0.0, z - 0.03, x + 0.03, 2.2, z + 0.03))
    for y in (1.0, 2.0):
        parts.append(box(-1.23, y, -0.43, 1.23, y + 0.04, 0.43))
        parts.append(box(-1.2, y + 0.04, -0.43, 1.2, y + 0.14, -0.40))
    vols = fuse_all(parts)
    occ.synchronize()
    physical(vols, {
        "feet": surfaces_where(flat_at(1, 0.0)),
        "deck_low": surfaces_where(flat_at(1, 1.04)),
        "deck_high": surfaces_where(flat_at(1, 2.04)),
    })
    uniform_size(H)
