#!/usr/bin/env python3
"""Reference eigenvalues of second-order (P2) tetrahedra from scikit-fem's ElementTetP2.

Reads the linear mesh data/meshes/beam.msh (cantilever 1.0 x 0.1 x 0.1 m), lets scikit-fem add
its own mid-edge dofs (ElementTetP2 on the same tetrahedra), clamps every dof on the x = 0
face, and solves K u = lambda M u for the lowest modes (linear elasticity, consistent mass).
modal-bake's P2 bake of the same mesh (TetMesh::to_quadratic, --fixed-below x=0) must give the
same eigenvalues to 1e-8 relative (crates/modal-bake/tests/p2.rs).

Writes data/p2_reference.json. Usage: python3 scripts/p2_reference.py [--check]
(--check recomputes and compares with the committed file to 1e-12 relative).
Needs: pip install scikit-fem meshio scipy.
"""
import json
import sys
from pathlib import Path

import meshio
import numpy as np
import scipy.sparse.linalg as sla
import skfem
from skfem import Basis, ElementTetP2, ElementVector, MeshTet, asm, condense
from skfem.models.elasticity import lame_parameters, linear_elasticity
from skfem.helpers import dot

ROOT = Path(__file__).resolve().parent.parent
MESH = ROOT / "data/meshes/beam.msh"
OUT = ROOT / "data/p2_reference.json"
E, NU, RHO = 2.0e9, 0.3, 1200.0
MODES = 10


@skfem.BilinearForm
def vector_mass(u, v, w):
    return RHO * dot(u, v)


def compute():
    m = meshio.read(MESH)
    tets = np.vstack([c.data for c in m.cells if c.type == "tetra"])
    used = np.unique(tets)
    remap = -np.ones(len(m.points), dtype=np.int64)
    remap[used] = np.arange(len(used))
    p = m.points[used].T.astype(np.float64)
    t = remap[tets].T
    mesh = MeshTet(p, t)
    basis = Basis(mesh, ElementVector(ElementTetP2()))
    lam, mu = lame_parameters(E, NU)
    K = asm(linear_elasticity(lam, mu), basis)
    M = asm(vector_mass, basis)
    clamp = basis.get_dofs(lambda x: x[0] <= 0.0).all()
    Kc, Mc = condense(K, M, D=clamp, expand=False)[:2]
    vals = sla.eigsh(Kc.tocsc(), k=MODES, M=Mc.tocsc(), sigma=0.0, which="LM",
                     tol=1e-14, return_eigenvectors=False)
    vals = np.sort(vals)
    return {
        "mesh": "data/meshes/beam.msh",
        "element": "skfem ElementVector(ElementTetP2())",
        "scikit_fem": skfem.__version__ if hasattr(skfem, "__version__") else "unknown",
        "youngs_pa": E,
        "poisson": NU,
        "density_kg_m3": RHO,
        "clamped": "every dof with x <= 0",
        "p1_nodes": int(p.shape[1]),
        "p1_tets": int(t.shape[1]),
        "free_dofs": int(Kc.shape[0]),
        "eigenvalues": [float(v) for v in vals],
    }


def main():
    ref = compute()
    if "--check" in sys.argv:
        old = json.loads(OUT.read_text())
        a, b = np.array(old["eigenvalues"]), np.array(ref["eigenvalues"])
        err = np.max(np.abs(a - b) / b)
        print(f"max relative difference {err:.3e}")
        sys.exit(0 if err < 1e-12 else 1)
    OUT.write_text(json.dumps(ref, indent=1) + "\n")
    print(f"wrote {OUT}: {ref['free_dofs']} free dofs, eigenvalues {ref['eigenvalues'][:3]} ...")


if __name__ == "__main__":
    main()
