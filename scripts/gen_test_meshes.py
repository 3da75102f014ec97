#!/usr/bin/env python3
"""Regenerate the mesh-reader test data: data/meshes/ (gmsh) and data/bad/ (hand-written).

Usage (from the repository root):
    python3 scripts/gen_test_meshes.py          # write data/meshes and data/bad
    python3 scripts/gen_test_meshes.py --check  # regenerate into a temp dir, compare bytes

Deterministic: single-threaded gmsh, fixed random seed, fixed 2D/3D algorithms; every file
is a pure function of this script and the gmsh version (4.15.x).
"""

import json
import os
import sys
import tempfile
import filecmp

import gmsh

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def gmsh_start():
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay 2D
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay 3D
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.option.setNumber("Mesh.SaveAll", 0)  # only elements of physical groups


def surfaces_at(axis, value, eps=1e-5):
    """Tags of the 2D entities lying in the plane coordinate[axis] == value."""
    out = []
    for dim, tag in gmsh.model.getEntities(2):
        box = gmsh.model.getBoundingBox(dim, tag)
        if abs(box[axis] - value) < eps and abs(box[axis + 3] - value) < eps:
            out.append(tag)
    return out


def snap_nodes(digits=12):
    """Rounds every node coordinate to `digits` significant decimal digits (< 1e-12 m shift).

    gmsh prints ASCII MSH coordinates with %.16g, which does not round-trip every double
    (17 digits would), so an ASCII file and a binary file of one mesh can differ by 1 ulp.
    Snapped coordinates print exactly, making all forms carry bit-identical positions.
    """
    tags, coords, _ = gmsh.model.mesh.getNodes()
    for i, tag in enumerate(tags):
        x = [float("%.*g" % (digits, coords[3 * i + k])) for k in range(3)]
        gmsh.model.mesh.setNode(int(tag), x, [])


def write_msh(path, version, binary):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(path)


def mesh_json(variant):
    """The current gmsh model's mesh as meshio-style JSON text.

    Nodes in ascending tag order; one cell block per physical group (by ascending (dim, tag)),
    cells in ascending element tag order. variant: "cell_sets" or "gmsh_physical".
    """
    tags, coords, _ = gmsh.model.mesh.getNodes()
    order = sorted(range(len(tags)), key=lambda i: tags[i])
    index = {int(tags[i]): k for k, i in enumerate(order)}
    points = [[float(coords[3 * i + j]) for j in range(3)] for i in order]
    type_names = {15: "vertex", 1: "line", 2: "triangle", 4: "tetra"}
    blocks = []  # (type name, [cells], dim, physical tag, name)
    for dim, ptag in sorted(gmsh.model.getPhysicalGroups()):
        name = gmsh.model.getPhysicalName(dim, ptag)
        by_type = {}
        for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, ptag):
            etypes, etags, enodes = gmsh.model.mesh.getElements(dim, ent)
            for ety, et, en in zip(etypes, etags, enodes):
                nn = len(en) // len(et)
                for k, t in enumerate(et):
                    by_type.setdefault(int(ety), []).append(
                        (int(t), [index[int(v)] for v in en[nn * k:nn * (k + 1)]]))
        for ety in sorted(by_type):
            cells = [c for _, c in sorted(by_type[ety])]
            blocks.append((type_names[ety], cells, dim, ptag, name))
    doc = {"points": points, "cells": [{"type": b[0], "data": b[1]} for b in blocks]}
    if variant == "cell_sets":
        sets = {}
        for i, b in enumerate(blocks):
            name = b[4] or str(b[3])
            sets.setdefault(name, [[] for _ in blocks])[i] = list(range(len(b[1])))
        doc["cell_sets"] = sets
    else:
        doc["cell_data"] = {"gmsh:physical": [[b[3]] * len(b[1]) for b in blocks]}
        doc["field_data"] = {b[4]: [b[3], b[2]] for b in blocks if b[4]}
    # One point / cell per line keeps the file diffable and small.
    lines = ["{", '"points": [']
    lines.append(",\n".join(json.dumps(p) for p in doc["points"]) + "],")
    lines.append('"cells": [')
    cell_txt = []
    for c in doc["cells"]:
        rows = ",\n".join(json.dumps(r) for r in c["data"])
        cell_txt.append('{"type": %s, "data": [\n%s]}' % (json.dumps(c["type"]), rows))
    lines.append(",\n".join(cell_txt) + "],")
    rest = {k: v for k, v in doc.items() if k not in ("points", "cells")}
    lines.append(",\n".join('"%s": %s' % (k, json.dumps(v, sort_keys=True))
                            for k, v in rest.items()))
    lines.append("}")
    return "\n".join(lines) + "\n"


def gen_cube(out):
    gmsh_start()
    gmsh.model.add("cube")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.22)
    gmsh.model.addPhysicalGroup(2, surfaces_at(2, 0.0), name="bottom")
    gmsh.model.addPhysicalGroup(2, surfaces_at(2, 1.0), name="top")
    gmsh.model.addPhysicalGroup(3, [1], name="volume")
    # Groups of other dimensions: a corner point and an edge (skipped element types whose
    # nodes still form groups), and an unnamed surface group (named "77" by the readers).
    corner = [t for _, t in gmsh.model.getEntitiesInBoundingBox(
        -1e-6, -1e-6, -1e-6, 1e-6, 1e-6, 1e-6, 0)]
    gmsh.model.addPhysicalGroup(0, corner, name="corner")
    edge = [t for _, t in gmsh.model.getEntitiesInBoundingBox(
        -1e-6, -1e-6, -1e-6, 1e-6, 1e-6, 1 + 1e-6, 1)]
    gmsh.model.addPhysicalGroup(1, edge, name="edge")
    gmsh.model.addPhysicalGroup(2, surfaces_at(0, 0.0), tag=77)
    gmsh.model.mesh.generate(3)
    snap_nodes()
    write_msh(os.path.join(out, "cube_v22.msh"), 2.2, False)
    write_msh(os.path.join(out, "cube_v22_bin.msh"), 2.2, True)
    write_msh(os.path.join(out, "cube_v41.msh"), 4.1, False)
    write_msh(os.path.join(out, "cube_v41_bin.msh"), 4.1, True)
    for variant, fname in (("cell_sets", "cube_cell_sets.json"),
                           ("gmsh_physical", "cube_gmsh_physical.json")):
        with open(os.path.join(out, fname), "w", newline="\n") as f:
            f.write(mesh_json(variant))
    # Counts for the tests, straight from gmsh.
    ntet = sum(len(t) for ty, t in zip(*gmsh.model.mesh.getElements(3)[:2]) if ty == 4)
    ntri = sum(len(gmsh.model.mesh.getElements(2, s)[1][0])
               for s in surfaces_at(2, 0.0) + surfaces_at(2, 1.0) + surfaces_at(0, 0.0))
    counts = {
        "nodes": len(gmsh.model.mesh.getNodes()[0]),
        "tets": ntet,
        "triangles_in_groups": ntri,
        "groups": {
            (gmsh.model.getPhysicalName(d, t) or str(t)):
                len(gmsh.model.mesh.getNodesForPhysicalGroup(d, t)[0])
            for d, t in gmsh.model.getPhysicalGroups()},
    }
    with open(os.path.join(out, "cube_counts.json"), "w", newline="\n") as f:
        f.write(json.dumps(counts, sort_keys=True, indent=1) + "\n")
    gmsh.finalize()


def gen_beam(out):
    gmsh_start()
    gmsh.model.add("beam")
    gmsh.model.occ.addBox(0, 0, 0, 1.0, 0.1, 0.1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.05)
    gmsh.model.addPhysicalGroup(2, surfaces_at(0, 0.0), name="clamp")
    gmsh.model.addPhysicalGroup(2, surfaces_at(0, 1.0), name="tip")
    gmsh.model.addPhysicalGroup(3, [1], name="volume")
    gmsh.model.mesh.generate(3)
    snap_nodes()
    write_msh(os.path.join(out, "beam.msh"), 4.1, False)
    gmsh.finalize()


def gen_unsnapped(out):
    """A small cylinder left as gmsh meshes it (coordinates not snapped), written as MSH 4.1
    ASCII and MSH 2.2 binary: gmsh's ASCII `%.16g` moves some coordinates by an ulp, so the two
    files carry different bits for one mesh (what the geometry hash must see through)."""
    gmsh_start()
    gmsh.model.add("cylinder")
    gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 0.3, 0.1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.08)
    gmsh.model.addPhysicalGroup(2, surfaces_at(2, 0.0), name="bottom")
    gmsh.model.addPhysicalGroup(3, [1], name="volume")
    gmsh.model.mesh.generate(3)
    write_msh(os.path.join(out, "cylinder_v41.msh"), 4.1, False)
    write_msh(os.path.join(out, "cylinder_v22_bin.msh"), 2.2, True)
    gmsh.finalize()


# ---------------------------------------------------------------------------------------
# data/bad: small hand-written MSH 2.2 ASCII / JSON files, one defect each.

NODES = [  # tag, x, y, z
    (1, 0.0, 0.0, 0.0), (2, 1.0, 0.0, 0.0), (3, 0.0, 1.0, 0.0), (4, 0.0, 0.0, 1.0),
    (5, 1.0, 1.0, 1.0),
]
TETS = [(5, [1, 2, 3, 4]), (6, [2, 3, 4, 5])]  # element tag, nodes; both positive


def msh22(nodes, elements, version="2.2", names=None, nodes_count=None, sections=None):
    """MSH 2.2 ASCII text. elements: (tag, type, [tags], [nodes]); node coords as text."""
    out = ["$MeshFormat", "%s 0 8" % version, "$EndMeshFormat"]
    if names:
        out += ["$PhysicalNames", str(len(names))]
        out += ['%d %d "%s"' % n for n in names]
        out += ["$EndPhysicalNames"]
    if sections is None or "Nodes" in sections:
        out += ["$Nodes", str(len(nodes) if nodes_count is None else nodes_count)]
        out += [" ".join(str(v) for v in n) for n in nodes]
        out += ["$EndNodes"]
    if sections is None or "Elements" in sections:
        out += ["$Elements", str(len(elements))]
        for tag, ty, tags, ns in elements:
            out.append(" ".join(str(v) for v in [tag, ty, len(tags)] + tags + ns))
        out += ["$EndElements"]
    return "\n".join(out) + "\n"


def tets(tet_list, phys=1):
    return [(t, 4, [phys, 1], ns) for t, ns in tet_list]


def msh41_nodes(nodes):
    """An MSH 4.1 ASCII $Nodes section: one volume block, tags then coordinates."""
    tags = [n[0] for n in nodes]
    out = ["$Nodes", "1 %d %d %d" % (len(nodes), min(tags), max(tags)),
           "3 1 0 %d" % len(nodes)]
    out += [str(t) for t in tags]
    out += [" ".join(str(v) for v in n[1:]) for n in nodes]
    return out + ["$EndNodes"]


def msh41(nodes, tet_list, extra=()):
    """MSH 4.1 ASCII text of tetrahedra (tag, [nodes]) in one volume block; `extra` lines
    are appended after $EndElements."""
    etags = [t for t, _ in tet_list]
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat"] + msh41_nodes(nodes)
    out += ["$Elements", "1 %d %d %d" % (len(tet_list), min(etags), max(etags)),
            "3 1 4 %d" % len(tet_list)]
    out += [" ".join(str(v) for v in [t] + ns) for t, ns in tet_list]
    out += ["$EndElements"] + list(extra)
    return "\n".join(out) + "\n"


def gen_bad(out):
    files = {}
    good = msh22(NODES, tets(TETS), names=[(3, 1, "volume")])
    files["truncated.msh"] = good[: good.index("$EndElements") - 5]
    files["non_numeric.msh"] = good.replace("\n3 0.0 1.0 0.0\n", "\n3 0.0 1.O 0.0\n")
    nan_nodes = [n if n[0] != 5 else (5, 1.0, "nan", 1.0) for n in NODES]
    files["nan_coordinate.msh"] = msh22(nan_nodes, tets(TETS), names=[(3, 1, "volume")])
    files["inf_coordinate.msh"] = msh22(
        [n if n[0] != 2 else (2, "inf", 0.0, 0.0) for n in NODES], tets(TETS))
    files["missing_node.msh"] = msh22(NODES, tets([(5, [1, 2, 3, 4]), (6, [2, 3, 4, 99])]))
    files["inverted_tet.msh"] = msh22(NODES, tets([(5, [1, 2, 3, 4]), (6, [2, 4, 3, 5])]))
    flat = NODES + [(6, 0.5, 0.5, 0.0)]
    files["zero_volume.msh"] = msh22(flat, tets(TETS + [(7, [1, 2, 3, 6])]))
    files["no_tets.msh"] = msh22(NODES, [(1, 2, [1, 1], [1, 2, 3]), (2, 2, [1, 1], [2, 3, 4])])
    files["second_order_only.msh"] = msh22(
        NODES + [(6 + i, 0.1 * i, 0.05, 0.05) for i in range(6)],
        [(1, 11, [1, 1], [1, 2, 3, 4, 6, 7, 8, 9, 10, 11])])
    files["huge_count.msh"] = msh22(NODES, tets(TETS), nodes_count=10**12)
    shifted = [(t + 5, x + 5.0, y, z) for t, x, y, z in NODES[:4]]
    files["two_pieces.msh"] = msh22(
        NODES[:4] + shifted, tets([(1, [1, 2, 3, 4]), (2, [6, 7, 8, 9])]))
    files["bad_version.msh"] = msh22(NODES, tets(TETS), version="3.0")
    files["missing_elements.msh"] = msh22(NODES, tets(TETS), sections=["Nodes"])
    files["duplicate_node.msh"] = msh22(NODES + [(3, 0.0, 2.0, 0.0)], tets(TETS))
    files["not_a_mesh.msh"] = "solid cube\n  facet normal 0 0 1\nendsolid\n"
    # Structure: sections repeated or out of order, tags and records that must not be
    # guessed, elements that overlap.
    again = msh22(NODES[:4], [], sections=["Nodes"]).split("$EndMeshFormat\n")[1]
    files["repeated_nodes.msh"] = good + again
    files["repeated_nodes_v41.msh"] = msh41(NODES, TETS, extra=msh41_nodes(NODES[:4]))
    files["elements_before_nodes.msh"] = msh22(NODES, tets(TETS), sections=["Elements"]) \
        + msh22(NODES, [], sections=["Nodes"]).split("$EndMeshFormat\n")[1]
    files["negative_node_tag.msh"] = msh22(NODES, tets([(5, [1, 2, 3, 4]), (6, [2, 3, 4, -5])]))
    files["zero_node_tag.msh"] = msh22(
        [(t - 1, x, y, z) for t, x, y, z in NODES],
        tets([(5, [0, 1, 2, 3]), (6, [1, 2, 3, 4])]))
    files["extra_value.msh"] = good.replace("\n5 4 2 1 1 1 2 3 4\n", "\n5 4 2 1 1 1 2 3 4 5\n")
    files["short_record.msh"] = good.replace("\n5 4 2 1 1 1 2 3 4\n", "\n5 4 2 1 1 1 2 3\n")
    files["permuted_duplicate_tet.msh"] = msh22(NODES, tets(TETS + [(7, [2, 1, 3, 4])]))
    files["overlapping_tets.msh"] = msh22(
        NODES + [(6, 0.1, 0.1, 0.5)], tets(TETS + [(7, [1, 2, 3, 6])]))
    files["comments_first.msh"] = "$Comments\nwritten by hand; $Nodes here is text\n" \
        "$EndComments\n" + good

    pts = [[n[1], n[2], n[3]] for n in NODES]
    tetra = {"type": "tetra", "data": [[0, 1, 2, 3], [1, 2, 3, 4]]}
    files["bad_shape.json"] = json.dumps(
        {"points": pts[:2] + [[0.0, 1.0]] + pts[3:], "cells": [tetra]})
    files["ragged.json"] = json.dumps(
        {"points": pts, "cells": [{"type": "tetra", "data": [[0, 1, 2, 3], [1, 2, 3]]}]})
    files["wrong_type.json"] = json.dumps(
        {"points": pts[:1] + [["1.0", 0.0, 0.0]] + pts[2:], "cells": [tetra]})
    files["negative_index.json"] = json.dumps(
        {"points": pts, "cells": [{"type": "tetra", "data": [[0, 1, 2, 3], [1, 2, -3, 4]]}]})
    files["missing_node.json"] = json.dumps(
        {"points": pts, "cells": [{"type": "tetra", "data": [[0, 1, 2, 3], [1, 2, 3, 9]]}]})
    files["cells_not_list.json"] = json.dumps({"points": pts, "cells": {"tetra": 5}})
    files["syntax_error.json"] = '{"points": [[0, 0, 0],\n  [1, 0 0]]}\n'
    for name, text in files.items():
        with open(os.path.join(out, name), "w", newline="\n") as f:
            f.write(text if text.endswith("\n") or name == "truncated.msh" else text + "\n")


def generate(root):
    meshes = os.path.join(root, "data", "meshes")
    bad = os.path.join(root, "data", "bad")
    os.makedirs(meshes, exist_ok=True)
    os.makedirs(bad, exist_ok=True)
    gen_cube(meshes)
    gen_beam(meshes)
    gen_unsnapped(meshes)
    gen_bad(bad)


def main():
    if "--check" in sys.argv:
        with tempfile.TemporaryDirectory() as tmp:
            generate(tmp)
            ok = True
            for sub in ("meshes", "bad"):
                a, b = os.path.join(ROOT, "data", sub), os.path.join(tmp, "data", sub)
                for name in sorted(os.listdir(b)):
                    same = os.path.exists(os.path.join(a, name)) and filecmp.cmp(
                        os.path.join(a, name), os.path.join(b, name), shallow=False)
                    print("%-8s data/%s/%s" % ("same" if same else "DIFFERS", sub, name))
                    ok &= same
            sys.exit(0 if ok else 1)
    generate(ROOT)


if __name__ == "__main__":
    main()
