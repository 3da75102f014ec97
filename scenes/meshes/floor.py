"""Floor slab for the washing-machine scene (paper Fig. 8, Table 1: 360 surface vertices):
5 x 4 m, 20 cm thick (top at y = 0). Fixed: "bottom" and "edges"."""

import gmsh
from _common import box, surfaces_where, flat_at, physical, uniform_size

NAME = "floor"
TARGET_SURFACE_VERTICES = 360
FIXED = ["bottom", "edges"]
H = 0.42


def build():
    occ = gmsh.model.occ
    v = box(-2.5, -0.2, -2.0, 2.5, 0.0, 2.0)
    occ.synchronize()
    edges = sorted(
        surfaces_where(flat_at(0, -2.5)) + surfaces_where(flat_at(0, 2.5))
        + surfaces_where(flat_at(2, -2.0)) + surfaces_where(flat_at(2, 2.0))
    )
    physical([v], {
        "bottom": surfaces_where(flat_at(1, -0.2)),
        "edges": edges,
        "top": surfaces_where(flat_at(1, 0.0)),
    })
    uniform_size(H)
