"""Ground slab for the low-rider (paper Fig. 5, Table 1: 1570 surface vertices): 30 x 10 m,
1 m deep (top at y = 0). Used with spatial attenuation, the amplitude averaged over "top".
Fixed: bottom and sides ("bottom", "sides")."""

import gmsh
from _common import box, surfaces_where, flat_at, physical, uniform_size

NAME = "ground"
TARGET_SURFACE_VERTICES = 1570
FIXED = ["bottom", "sides"]
H = 0.73


def build():
    occ = gmsh.model.occ
    v = box(-15.0, -1.0, -5.0, 15.0, 0.0, 5.0)
    occ.synchronize()
    sides = sorted(
        surfaces_where(flat_at(0, -15.0)) + surfaces_where(flat_at(0, 15.0))
        + surfaces_where(flat_at(2, -5.0)) + surfaces_where(flat_at(2, 5.0))
    )
    physical([v], {
        "bottom": surfaces_where(flat_at(1, -1.0)),
        "sides": sides,
        "top": surfaces_where(flat_at(1, 0.0)),
    })
    uniform_size(H)
