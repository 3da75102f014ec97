"""Sloped roof (paper Fig. 6, Table 1: 1002 surface vertices), modelled flat in its own frame:
a 4 x 3 m panel, 8 cm thick (y in [-0.08, 0]), on two 10 x 15 cm rafters running along z
under x = +-1.7 m. The scene tilts it about x. Fixed: the rafters' bottoms ("supports")."""

import gmsh
from _common import box, fuse_all, surfaces_where, flat_at, physical, uniform_size

NAME = "roof"
TARGET_SURFACE_VERTICES = 1002
FIXED = ["supports"]
H = 0.20


def build():
    occ = gmsh.model.occ
    parts = [box(-2.0, -0.08, -1.5, 2.0, 0.0, 1.5)]
    for x in (-1.7, 1.7):
        parts.append(box(x - 0.05, -0.23, -1.5, x + 0.05, -0.08, 1.5))
    vols = fuse_all(parts)
    occ.synchronize()
    physical(vols, {
        "supports": surfaces_where(flat_at(1, -0.23)),
        "top": surfaces_where(flat_at(1, 0.0)),
    })
    uniform_size(H)
