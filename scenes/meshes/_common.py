"""Shared helpers for the scene mesh scripts (gmsh OCC kernel, y-up, metres).

Every scene mesh script defines NAME, TARGET_SURFACE_VERTICES, FIXED (the physical group names
`BakeParams::fixed` takes; empty for a free-free object) and build(), which creates the geometry,
physical groups and mesh size in the current gmsh model. scripts/gen_scene_meshes.py meshes,
counts and writes them.
"""

import gmsh


def start():
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay 2D
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay 3D
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.option.setNumber("Mesh.SaveAll", 0)  # only elements of physical groups
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)


def box(x0, y0, z0, x1, y1, z1):
    """An axis-aligned OCC box from corner (x0, y0, z0) to (x1, y1, z1); returns its volume tag."""
    return gmsh.model.occ.addBox(x0, y0, z0, x1 - x0, y1 - y0, z1 - z0)


def fuse_all(tags):
    """Fuses OCC volumes into one; returns the list of resulting volume tags."""
    first = [(3, tags[0])]
    rest = [(3, t) for t in tags[1:]]
    if not rest:
        return [tags[0]]
    out, _ = gmsh.model.occ.fuse(first, rest)
    return [t for d, t in out if d == 3]


def surfaces_where(pred, eps=1e-6):
    """Tags of boundary surfaces whose bounding box satisfies pred(xmin, ymin, zmin, xmax, ymax, zmax)."""
    out = []
    for dim, tag in gmsh.model.getEntities(2):
        b = gmsh.model.getBoundingBox(dim, tag)
        if pred(*b):
            out.append(tag)
    return sorted(out)


def flat_at(axis, value, eps=1e-5):
    """Predicate: the surface lies in the plane coordinate[axis] == value."""
    return lambda *b: abs(b[axis] - value) < eps and abs(b[axis + 3] - value) < eps


def physical(volumes, groups):
    """Adds the 'volume' 3D group and named 2D groups {name: [surface tags]}."""
    gmsh.model.addPhysicalGroup(3, volumes, name="volume")
    for name, surfs in groups.items():
        if not surfs:
            raise RuntimeError(f"physical group {name!r} is empty")
        gmsh.model.addPhysicalGroup(2, surfs, name=name)


def uniform_size(h):
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)


def graded_size(h, h_inside, ramp):
    """Size h on every boundary surface, growing to h_inside at depth `ramp` (m) inside."""
    surfs = [t for _, t in gmsh.model.getEntities(2)]
    f = gmsh.model.mesh.field
    d = f.add("Distance")
    f.setNumbers(d, "SurfacesList", surfs)
    f.setNumber(d, "Sampling", 20)
    t = f.add("Threshold")
    f.setNumber(t, "InField", d)
    f.setNumber(t, "SizeMin", h)
    f.setNumber(t, "SizeMax", h_inside)
    f.setNumber(t, "DistMin", 0.0)
    f.setNumber(t, "DistMax", ramp)
    f.setAsBackgroundMesh(t)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h_inside)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
