"""Baseline for the table-build bench (its speed target): scipy's SuperLU computing the
same compliance blocks as `palpate tables build` on the same mesh.

Mesh: the benches' tissue cube (`benches/src/lib.rs`): 12x12x12 Kuhn cells,
0.1 m wide (2197 vertices), E = 3000 Pa, nu = 0.45, base z = 0 fixed.
Computes C = K_ff^-1 restricted to the columns of the touchable (free
surface) vertices, 3 per vertex, with scipy.sparse.linalg.splu.

Run: `python3 tools/reference/scipy_compliance.py [cells]` (needs numpy, scipy;
pin to one core with `taskset -c 1` and OMP_NUM_THREADS=1 to compare with
`taskset -c 1 cargo bench -p palpate-benches --bench table_build`).
Reference only: the product and its tests never need Python.
"""

import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def kuhn_box(n, size):
    idx = lambda i, j, k: i + (n + 1) * (j + (n + 1) * k)
    h = size / n
    pts = np.array([(i * h, j * h, k * h) for k in range(n + 1) for j in range(n + 1) for i in range(n + 1)])
    tets = []
    for ck in range(n):
        for cj in range(n):
            for ci in range(n):
                for perm in [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
                    c = [ci, cj, ck]
                    vs = [idx(*c)]
                    for a in perm:
                        c[a] += 1
                        vs.append(idx(*c))
                    p = pts[vs]
                    if np.linalg.det(np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]])) < 0:
                        vs[2], vs[3] = vs[3], vs[2]
                    tets.append(vs)
    return pts, np.array(tets)


def stiffness(pts, tets, young, nu):
    lam = young * nu / ((1 + nu) * (1 - 2 * nu))
    mu = young / (2 * (1 + nu))
    rows, cols, vals = [], [], []
    for t in tets:
        p = pts[t]
        d = np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]]).T
        vol = abs(np.linalg.det(d)) / 6
        inv = np.linalg.inv(d)
        a = np.vstack([-inv.sum(axis=0), inv])
        for j in range(4):
            for k in range(4):
                blk = vol * (lam * np.outer(a[j], a[k]) + mu * np.outer(a[k], a[j]) + mu * a[j] @ a[k] * np.eye(3))
                for r in range(3):
                    for c in range(3):
                        rows.append(3 * t[j] + r)
                        cols.append(3 * t[k] + c)
                        vals.append(blk[r, c])
    n = 3 * len(pts)
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsc()


def main():
    cells = int(sys.argv[1]) if len(sys.argv) > 1 else 12
    pts, tets = kuhn_box(cells, 0.1)
    k = stiffness(pts, tets, 3000.0, 0.45)
    fixed = pts[:, 2] < 1e-6
    surface = (pts == 0).any(axis=1) | (np.isclose(pts, 0.1)).any(axis=1)
    free = np.flatnonzero(~fixed)
    touchable = np.flatnonzero(~fixed & surface)
    dof = (3 * free[:, None] + np.arange(3)).ravel()
    slot = {v: i for i, v in enumerate(free)}
    start = time.perf_counter()
    lu = spla.splu(k[dof][:, dof].tocsc())
    rhs = np.zeros((len(dof), 3 * len(touchable)))
    for c, v in enumerate(touchable):
        for a in range(3):
            rhs[3 * slot[v] + a, 3 * c + a] = 1.0
    columns = lu.solve(rhs)
    elapsed = time.perf_counter() - start
    print(f"{len(pts)} vertices, {len(free)} free, {len(touchable)} touchable: "
          f"SuperLU factorization + {rhs.shape[1]} solves in {elapsed:.2f} s "
          f"(checksum {np.abs(columns).sum():.6e})")


if __name__ == "__main__":
    main()
