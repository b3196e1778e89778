"""Independent compressible neo-Hookean reference solutions (scikit-fem).

psi(F) = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2   (Bonet & Wood), P1 tets.

Written from the continuum definitions in Python: scikit-fem assembles the
weak residual  r(u) = int P(F) : grad(v)  and its tangent; scipy's sparse LU
solves the Newton steps. P is computed from the Cauchy stress
sigma = mu/J (b - I) + lam/J ln J I  as  P = J sigma F^-T  (a different route
from the first Piola-Kirchhoff form the Rust element uses); the tangent is
checked against a finite difference of the residual and the residual against
a finite difference of the total energy (scikit-fem Functional).

Run from this folder:  python3 make.py   (writes bar.msh and the two JSON files)
"""
import json
import sys

import numpy as np
import scipy
import scipy.sparse.linalg as spla
import skfem
from skfem import Basis, BilinearForm, ElementTetP1, ElementVector, Functional, LinearForm, MeshTet, asm
from skfem.helpers import ddot, det, grad, inv, mul, trace, transpose

E_PA = 5000.0


def lame(nu):
    return E_PA * nu / ((1 + nu) * (1 - 2 * nu)), E_PA / (2 * (1 + nu))


def read_msh(path):
    """MSH 2.2 ASCII, tets only (1-based ids): (points N x 3, tets M x 4), 0-based."""
    lines = open(path).read().split("\n")
    i = lines.index("$Nodes")
    n = int(lines[i + 1])
    p = np.array([[float(x) for x in lines[i + 2 + k].split()[1:4]] for k in range(n)])
    i = lines.index("$Elements")
    m = int(lines[i + 1])
    t = []
    for k in range(m):
        f = [int(x) for x in lines[i + 2 + k].split()]
        assert f[1] == 4
        t.append([x - 1 for x in f[3 + f[2]:]])
    return p, np.array(t)


def kuhn_box(nx, ny, nz, h):
    """The box of nx x ny x nz cubes of side h, each split into 6 Kuhn tets
    (the README's split of `cube`), positively oriented."""
    idx = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
    p = np.array([[i * h, j * h, k * h] for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)])
    t = []
    for ck in range(nz):
        for cj in range(ny):
            for ci in range(nx):
                for a, b, c in [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
                    e = np.eye(3, dtype=int)
                    c0 = np.array([ci, cj, ck])
                    corners = [c0, c0 + e[a], c0 + e[a] + e[b], c0 + e[a] + e[b] + e[c]]
                    tet = [idx(*x) for x in corners]
                    x = p[tet]
                    if np.linalg.det(np.array([x[1] - x[0], x[2] - x[0], x[3] - x[0]])) < 0:
                        tet[2], tet[3] = tet[3], tet[2]
                    t.append(tet)
    return p, np.array(t)


def write_msh(path, p, t):
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(p))
        for k, x in enumerate(p):
            f.write("%d %s %s %s\n" % (k + 1, *(repr(float(c)) for c in x)))
        f.write("$EndNodes\n$Elements\n%d\n" % len(t))
        for k, tet in enumerate(t):
            f.write("%d 4 2 1 1 %d %d %d %d\n" % (k + 1, *(v + 1 for v in tet)))
        f.write("$EndElements\n")


def kinematics(w):
    F = grad(w["u"])
    F = F + np.eye(3)[:, :, None, None]
    J = det(F)
    return F, J, inv(F)


def forms(lam, mu):
    @Functional
    def energy(w):
        F, J, _ = kinematics(w)
        return mu / 2 * (trace(mul(transpose(F), F)) - 3) - mu * np.log(J) + lam / 2 * np.log(J) ** 2

    @LinearForm
    def residual(v, w):
        F, J, Finv = kinematics(w)
        b = mul(F, transpose(F))
        eye = np.eye(3)[:, :, None, None]
        sigma = mu / J * (b - eye) + lam / J * np.log(J) * eye
        P = J * mul(sigma, transpose(Finv))
        return ddot(P, grad(v))

    @BilinearForm
    def tangent(du, v, w):
        F, J, Finv = kinematics(w)
        FinvT = transpose(Finv)
        dF = grad(du)
        dP = (mu * dF + (mu - lam * np.log(J)) * mul(FinvT, mul(transpose(dF), FinvT))
              + lam * trace(mul(Finv, dF)) * FinvT)
        return ddot(dP, grad(v))

    return energy, residual, tangent


class Problem:
    def __init__(self, p, t, nu, fixed, prescribed, loads):
        """fixed: vertex ids with zero displacement; prescribed: {vertex: [dx,dy,dz]};
        loads: {vertex: [fx,fy,fz]} dead loads, N."""
        self.p, self.t = p, t
        self.lam, self.mu = lame(nu)
        self.mesh = MeshTet(p.T.copy(), t.T.copy())
        self.basis = Basis(self.mesh, ElementVector(ElementTetP1()), intorder=1)
        self.energy, self.residual, self.tangent = forms(self.lam, self.mu)
        nd = self.basis.nodal_dofs  # (3, N): dof of (component, vertex)
        self.dof = lambda v, c: nd[c, v]
        self.fixed, self.prescribed = fixed, prescribed
        known = [self.dof(v, c) for v in list(fixed) + list(prescribed) for c in range(3)]
        self.known = np.array(sorted(known))
        self.free = np.setdiff1d(np.arange(self.basis.N), self.known)
        self.f_ext = np.zeros(self.basis.N)
        for v, f in loads.items():
            for c in range(3):
                self.f_ext[self.dof(v, c)] = f[c]

    def J_min(self, u):
        F, J, _ = kinematics({"u": self.basis.interpolate(u)})
        return J.min()

    def r(self, u, s):
        """Out-of-balance force dW/du - s f_ext, N."""
        return asm(self.residual, self.basis, u=self.basis.interpolate(u)) - s * self.f_ext

    def solve(self, steps, tol=1e-11):
        u = np.zeros(self.basis.N)
        iterations = 0
        for k in range(1, steps + 1):
            s = k / steps
            for v, d in self.prescribed.items():
                for c in range(3):
                    u[self.dof(v, c)] = s * d[c]
            assert self.J_min(u) > 0
            r = self.r(u, s)
            scale = max(np.abs(r[self.free]).max(), s * np.abs(self.f_ext).max())
            for it in range(60):
                if np.abs(r[self.free]).max() <= tol * scale:
                    break
                K = asm(self.tangent, self.basis, u=self.basis.interpolate(u))
                du = np.zeros_like(u)
                du[self.free] = spla.spsolve(K[self.free][:, self.free].tocsc(), -r[self.free])
                alpha = 1.0
                while True:
                    trial = u + alpha * du
                    if self.J_min(trial) > 0:
                        rt = self.r(trial, s)
                        if np.linalg.norm(rt[self.free]) < np.linalg.norm(r[self.free]):
                            break
                    alpha /= 2
                    assert alpha > 1e-6, "line search failed"
                u, r = trial, rt
                iterations += 1
            else:
                raise RuntimeError("no convergence")
        return u, iterations, np.abs(r[self.free]).max() / scale

    def checks(self, u):
        """Residual against a central difference of the energy and tangent
        against a central difference of the residual, at the state u, in
        10 random directions each: the largest relative difference."""
        rng = np.random.default_rng(7)
        W = lambda x: self.energy.assemble(self.basis, u=self.basis.interpolate(x))
        r0 = self.r(u, 0.0)
        K = asm(self.tangent, self.basis, u=self.basis.interpolate(u))
        size = np.abs(u).max()
        worst_r = worst_k = 0.0
        for _ in range(10):
            d = rng.standard_normal(u.shape)
            h = 1e-6 * size / np.abs(d).max()
            fd = (W(u + h * d) - W(u - h * d)) / (2 * h)
            worst_r = max(worst_r, abs(fd - r0 @ d) / (np.abs(r0) @ np.abs(d)))
            fdk = (self.r(u + h * d, 0.0) - self.r(u - h * d, 0.0)) / (2 * h)
            worst_k = max(worst_k, np.abs(fdk - K @ d).max() / np.abs(K @ d).max())
        return worst_r, worst_k

    def report(self, u, iterations, residual, vertices, steps):
        U = np.array([[u[self.dof(v, c)] for c in range(3)] for v in range(len(self.p))])
        x = self.p + U
        v0 = sum(abs(np.linalg.det(np.array([self.p[t[1]] - self.p[t[0]], self.p[t[2]] - self.p[t[0]], self.p[t[3]] - self.p[t[0]]]))) / 6 for t in self.t)
        v = sum(np.linalg.det(np.array([x[t[1]] - x[t[0]], x[t[2]] - x[t[0]], x[t[3]] - x[t[0]]])) / 6 for t in self.t)
        r = self.r(u, 1.0)
        reaction = [float(sum(r[self.dof(w, c)] for w in self.prescribed)) for c in range(3)]
        check_r, check_k = self.checks(u)
        return {
            "lam": self.lam,
            "mu": self.mu,
            "young_pa": E_PA,
            "load_steps": steps,
            "newton_iterations": iterations,
            "final_residual_over_scale": residual,
            "fd_check_residual_vs_energy": check_r,
            "fd_check_tangent_vs_residual": check_k,
            "min_J": float(self.J_min(u)),
            "volume_change": float(v / v0 - 1),
            "reaction_n": reaction,
            "vertices": vertices,
            "displacements": [U[w].tolist() for w in vertices],
            "all_displacements": U.tolist(),
        }


def cube_compression():
    p, t = read_msh("../meshes/cube.msh")
    base = [v for v in range(len(p)) if p[v, 2] == 0.0]
    top = [v for v in range(len(p)) if p[v, 2] == 1.0]
    d = [0.0, 0.0, -0.3]
    pr = Problem(p, t, 0.45, base, {v: d for v in top}, {})
    steps = 6
    u, it, res = pr.solve(steps)
    # centre column, mid-height side faces, a corner of the mid plane
    idx = lambda i, j, k: i + 6 * (j + 6 * k)
    chosen = [idx(2, 2, 2), idx(3, 3, 3), idx(0, 2, 2), idx(5, 3, 3), idx(0, 0, 3), idx(2, 5, 1)]
    out = pr.report(u, it, res, chosen, steps)
    out.update({
        "mesh": "../meshes/cube.msh",
        "poisson": 0.45,
        "problem": "cube [0,1]^3; every vertex with z=0 fixed; every vertex with z=1 prescribed "
                   "(0,0,-0.3) m (30 % compression, top clamped); no loads",
        "fixed": base,
        "prescribed": top,
        "prescribed_displacement_m": d,
    })
    return out


def bar_bend():
    p, t = kuhn_box(3, 3, 8, 0.1)
    write_msh("bar.msh", p, t)
    p, t = read_msh("bar.msh")
    base = [v for v in range(len(p)) if p[v, 2] == 0.0]
    top = [v for v in range(len(p)) if abs(p[v, 2] - 0.8) < 1e-12]
    total = [12.0, 0.0, -3.0]
    loads = {v: [c / len(top) for c in total] for v in top}
    pr = Problem(p, t, 0.49, base, {}, loads)
    steps = 15
    u, it, res = pr.solve(steps)
    idx = lambda i, j, k: i + 4 * (j + 4 * k)
    chosen = [idx(0, 0, 8), idx(3, 3, 8), idx(1, 2, 8), idx(0, 3, 4), idx(3, 0, 4), idx(2, 1, 1)]
    out = pr.report(u, it, res, chosen, steps)
    out.update({
        "mesh": "bar.msh",
        "poisson": 0.49,
        "problem": "bar [0,0.3]x[0,0.3]x[0,0.8] m (3x3x8 cubes of 0.1 m, Kuhn split); every vertex with "
                   "z=0 fixed; dead loads (12, 0, -3) N in total in equal shares on the 16 vertices with z=0.8",
        "fixed": base,
        "loaded": top,
        "total_load_n": total,
    })
    return out


def main():
    versions = {
        "python": sys.version.split()[0],
        "scikit-fem": skfem.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
    }
    for name, make in [("cube_compression", cube_compression), ("bar_bend", bar_bend)]:
        out = make()
        out["versions"] = versions
        with open(name + ".json", "w") as f:
            json.dump(out, f, indent=1)
        print(name, {k: out[k] for k in ["newton_iterations", "final_residual_over_scale", "fd_check_residual_vs_energy",
                                         "fd_check_tangent_vs_residual", "min_J", "volume_change", "reaction_n"]},
              "tip", out["displacements"][0])


if __name__ == "__main__":
    main()
