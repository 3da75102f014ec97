"""Fridge (paper Fig. 8, Table 1: 250 surface vertices): a solid 0.7 x 1.8 x 0.7 m box
(y in [0, 1.8], centred in x and z). Free-free: no fixed group (the bake drops the 6 rigid
modes)."""

import gmsh
from _common import box, surfaces_where, flat_at, physical, uniform_size

NAME = "fridge"
TARGET_SURFACE_VERTICES = 250
FIXED = []
H = 0.19


def build():
    occ = gmsh.model.occ
    v = box(-0.35, 0.0, -0.35, 0.35, 1.8, 0.35)
    occ.synchronize()
    physical([v], {
        "bottom": surfaces_where(flat_at(1, 0.0)),
        "top": surfaces_where(flat_at(1, 1.8)),
    })
    uniform_size(H)
