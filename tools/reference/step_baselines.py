"""Baselines of `palpate bench`: what a tensor-mass step costs next
to the sparse matrix-vector product and the force evaluations of Python
libraries, on the same mesh.

Mesh: the generated cylinder of `palpate::mesh::generate::cylinder_mesh`
(H = 0.1 m, R = H/5), ported below construction for construction, at
`radial_cells` = 4 and `height_cells` = 16: 1377 vertices, 6144 tets (the
"about 6000 tets" of the speed targets). `--write-mesh PREFIX` writes it as TetGen
`PREFIX.node` / `PREFIX.ele` (0-based), which `palpate bench` reads.
Material: E = 5000 Pa, nu = 0.4 (the St Venant-Kirchhoff benches'), base
z = 0 fixed; the deformed state is the benches' 20 % shear
u_x = 0.2 z.

Timed, each the median of 31 samples (a sample repeats the call until it
lasts 20 ms), with min and max:
- scipy: `K @ u` with the assembled P1 stiffness, CSR, f64 and f32, all
  3N degrees of freedom (the product alone, no integrator);
- pbatoolkit (if installed): the St Venant-Kirchhoff gradient (internal
  forces) of `pbat.fem.hyper_elastic_potential`, one-point quadrature, f64;
- warp.sim (if installed; removed from warp-lang 1.10 on): one
  `SemiImplicitIntegrator` step of the tet mesh on the CPU, f32.

Run: `OMP_NUM_THREADS=1 taskset -c 1 python3 tools/reference/step_baselines.py
--write-mesh target/cylinder` (needs numpy, scipy; pbatoolkit and warp-lang
optional). Prints one JSON object per line.
Reference only: the product and its tests never need Python.
"""

import argparse
import json
import os
import time

import numpy as np
import scipy.sparse as sp

KUHN_PATHS = [
    ((0, 1, 2), True),
    ((0, 2, 1), False),
    ((1, 0, 2), False),
    ((1, 2, 0), True),
    ((2, 0, 1), True),
    ((2, 1, 0), False),
]


def kuhn_cell(cell, flip, vertex):
    start = [cell[a] + int(flip[a]) for a in range(3)]
    odd_flips = sum(flip) % 2 == 1
    tets = []
    for order, even in KUHN_PATHS:
        g = list(start)
        tet = [vertex(g)]
        for axis in order:
            g[axis] += -1 if flip[axis] else 1
            tet.append(vertex(g))
        if even == odd_flips:
            tet[2], tet[3] = tet[3], tet[2]
        tets.append(tet)
    return tets


def cylinder_mesh(height, radial_cells, height_cells):
    """`palpate::mesh::generate::cylinder_mesh`, same vertex and tet order."""
    r, nz = radial_cells, height_cells
    n = 2 * r
    radius = height / 5.0
    square = lambda i: (i - r) / r
    pts = []
    for k in range(nz + 1):
        z = height * (k / nz)
        for j in range(n + 1):
            sy = square(j)
            for i in range(n + 1):
                sx = square(i)
                pts.append((radius * sx * np.sqrt(1 - sy * sy / 2), radius * sy * np.sqrt(1 - sx * sx / 2), z))
    idx = lambda g: g[0] + (n + 1) * (g[1] + (n + 1) * g[2])
    tets = []
    for ck in range(nz):
        for cj in range(n):
            for ci in range(n):
                tets.extend(kuhn_cell((ci, cj, ck), (ci < r, cj < r, False), idx))
    return np.array(pts), np.array(tets, dtype=np.int64)


def write_tetgen(prefix, pts, tets):
    with open(prefix + ".node", "w") as f:
        f.write(f"{len(pts)} 3 0 0\n")
        for i, p in enumerate(pts):
            f.write(f"{i} {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n")
    with open(prefix + ".ele", "w") as f:
        f.write(f"{len(tets)} 4 0\n")
        for i, t in enumerate(tets):
            f.write(f"{i} {t[0]} {t[1]} {t[2]} {t[3]}\n")


def gradients(pts, tets):
    """Rest shape-function gradients a_j (T x 4 x 3) and volumes (T)."""
    p = pts[tets]
    d = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]], axis=2)
    vol = np.linalg.det(d) / 6
    inv = np.linalg.inv(d)
    a = np.concatenate([-inv.sum(axis=1, keepdims=True), inv], axis=1)
    return a, vol


def stiffness(pts, tets, young, nu):
    """The assembled P1 stiffness, 3N x 3N CSR (MODELS.md section 1)."""
    lam = young * nu / ((1 + nu) * (1 - 2 * nu))
    mu = young / (2 * (1 + nu))
    a, vol = gradients(pts, tets)
    eye = np.eye(3)
    # K_jk = V (lam a_j a_k^T + mu a_k a_j^T + mu (a_j . a_k) I)
    blocks = vol[:, None, None, None, None] * (
        lam * np.einsum("tjr,tkc->tjkrc", a, a)
        + mu * np.einsum("tkr,tjc->tjkrc", a, a)
        + mu * np.einsum("tjx,tkx->tjk", a, a)[:, :, :, None, None] * eye
    )
    rows = 3 * tets[:, :, None, None, None] + np.arange(3)[None, None, None, :, None]
    cols = 3 * tets[:, None, :, None, None] + np.arange(3)[None, None, None, None, :]
    rows, cols = np.broadcast_arrays(rows, cols)
    n = 3 * len(pts)
    return sp.coo_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n)).tocsr()


def timed(f, samples=31, sample_s=0.02):
    """Median, min and max seconds per call of f over `samples` samples."""
    f()
    reps = 1
    while True:
        start = time.perf_counter()
        for _ in range(reps):
            f()
        if time.perf_counter() - start >= sample_s / 4:
            break
        reps *= 2
    per_call = []
    for _ in range(samples):
        start = time.perf_counter()
        for _ in range(reps):
            f()
        per_call.append((time.perf_counter() - start) / reps)
    per_call.sort()
    return {"median_s": per_call[samples // 2], "min_s": per_call[0], "max_s": per_call[-1], "samples": samples, "iterations": reps}


def report(what, **fields):
    print(json.dumps({"what": what, **fields}), flush=True)


def pbat_forces(pts, tets, young, nu, x_def):
    import pbatoolkit as pbat

    fem = pbat.pbat.fem
    element = fem.Element.Tetrahedron
    E = np.asfortranarray(tets.T.astype(np.int64))
    X = np.asfortranarray(pts.T)
    wg = fem.mesh_quadrature_weights(E, X, element, order=1, quadrature_order=1)
    eg = fem.mesh_quadrature_elements(E, wg)
    GNeg = fem.shape_function_gradients(E, X, element=element, order=1, dims=3, quadrature_order=1)
    mu, lam = pbat.pypbat.fem.lame_coefficients(young, nu)
    mug = np.full(wg.size, mu)
    lamg = np.full(wg.size, lam)
    x = np.ravel(np.asfortranarray(x_def.T), order="F")
    wg, eg = np.ravel(wg), np.ravel(eg)

    def call():
        return fem.hyper_elastic_potential(
            E=E, n_nodes=X.shape[1], eg=eg, wg=wg, GNeg=GNeg, mug=mug, lambdag=lamg, x=x,
            energy=fem.HyperElasticEnergy.SaintVenantKirchhoff,
            flags=fem.ElementElasticityComputationFlags.Gradient,
            spd_correction=fem.HyperElasticSpdCorrection.NoCorrection,
            element=element, order=1, dims=3,
        )

    return call


def warp_step(pts, tets, young, nu, density, u):
    import warp as wp
    import warp.sim

    wp.config.quiet = True
    wp.init()
    lam = young * nu / ((1 + nu) * (1 - 2 * nu))
    mu = young / (2 * (1 + nu))
    builder = warp.sim.ModelBuilder(gravity=0.0)
    for p, d in zip(pts + u, pts):
        builder.add_particle(wp.vec3(*p), wp.vec3(0.0, 0.0, 0.0), 0.0 if d[2] < 1e-6 else 1.0)
    for t in tets:
        builder.add_tetrahedron(int(t[0]), int(t[1]), int(t[2]), int(t[3]), k_mu=mu, k_lambda=lam, k_damp=0.0)
    model = builder.finalize(device="cpu")
    model.ground = False
    state0, state1 = model.state(), model.state()
    integrator = warp.sim.SemiImplicitIntegrator()

    def call():
        integrator.simulate(model, state0, state1, 1e-6)
        wp.synchronize()

    return call


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--radial-cells", type=int, default=4)
    parser.add_argument("--height-cells", type=int, default=16)
    parser.add_argument("--write-mesh", metavar="PREFIX")
    args = parser.parse_args()
    young, nu, density = 5000.0, 0.4, 1000.0
    pts, tets = cylinder_mesh(0.1, args.radial_cells, args.height_cells)
    report("mesh", vertices=len(pts), tets=len(tets), volume_m3=float(gradients(pts, tets)[1].sum()),
           threads=os.environ.get("OMP_NUM_THREADS"))
    if args.write_mesh:
        write_tetgen(args.write_mesh, pts, tets)
    k = stiffness(pts, tets, young, nu)
    u = np.zeros_like(pts)
    u[:, 0] = 0.2 * pts[:, 2]
    u64 = u.ravel()
    report("scipy K.u f64", nnz=int(k.nnz), bytes=int(k.data.nbytes + k.indices.nbytes + k.indptr.nbytes + 2 * u64.nbytes),
           **timed(lambda: k @ u64))
    k32, u32 = k.astype(np.float32), u64.astype(np.float32)
    report("scipy K.u f32", nnz=int(k32.nnz), bytes=int(k32.data.nbytes + k32.indices.nbytes + k32.indptr.nbytes + 2 * u32.nbytes),
           **timed(lambda: k32 @ u32))
    try:
        call = pbat_forces(pts, tets, young, nu, pts + u)
        report("pbatoolkit StVK forces f64", **timed(call))
    except ImportError as e:
        report("pbatoolkit StVK forces f64", error=str(e))
    try:
        call = warp_step(pts, tets, young, nu, density, u)
        report("warp.sim semi-implicit step f32", **timed(call))
    except ImportError as e:
        report("warp.sim semi-implicit step f32", error=str(e))


if __name__ == "__main__":
    main()
