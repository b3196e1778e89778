#!/usr/bin/env python3
"""The built-in organ's tet mesh: host-harness/assets/organ.msh (made once, committed).

Run (from the repository root; gmsh 4.15, `pip install gmsh==4.15.*`; numpy not needed):

    python3 tools/meshes/organ.py [OUT]          # default OUT: host-harness/assets/organ.msh

The harness embeds the file it writes (palpate::mesh::organ); no test and no build runs this script.
It is deterministic for a given gmsh version (one thread, fixed seeds), so rerunning it rewrites the
same mesh.

Shape (metres; x from the left lobe's tip to the right lobe, y front to back, z up): a unit sphere,
triangulated as a subdivided icosahedron, mapped point by point to a smooth closed liver-like
surface. A sphere point (u, v, w) goes to

    x = HALF_LENGTH * u
    y = half_width(u) * v
    z = top(u) * w**EXPONENT                        for w >= 0 (the upper, diaphragmatic face)
    z = smooth_max(-bottom(u) * |w|**EXPONENT, FLOOR) for w < 0 (the underside)

where s(u) = (1 + tanh((u - LOBE_JOIN_U) / LOBE_JOIN_WIDTH)) / 2 goes from the thin left lobe (0) to
the thick right lobe (1) and half_width, top and bottom blend linearly between the lobes' values.
EXPONENT < 1 blunts the lobes' rims. The underside of the right lobe is cut exactly flat at
z = FLOOR by a polynomial smooth maximum (blend FLOOR_BLEND): that flat face is where the built-in
hybrid scene fixes the organ. About 0.17 m x 0.13 m x 0.07 m.

Mesh: gmsh remeshes the surface (classifySurfaces + createGeometry, as gmsh's tutorial t13) and
fills it with tets (Delaunay, then Netgen optimization), sized by x: FINE_M over the left lobe (the
built-in hybrid scene cuts and resects it), growing linearly to COARSE_M over the right lobe between
x = FINE_UNTIL_X_M and COARSE_FROM_X_M. Written as Gmsh MSH 2.2 ASCII: only the tets (physical
volume 1), the nodes renumbered densely, coordinates rounded to 0.1 micrometre, the flat underside's
nodes set exactly to z = FLOOR.
"""

import math
import sys

import gmsh

HALF_LENGTH = 0.085
# (left lobe, right lobe) values, m.
HALF_WIDTH = (0.042, 0.065)
TOP = (0.008, 0.045)
BOTTOM = (0.006, 0.035)
LOBE_JOIN_U = 0.05
LOBE_JOIN_WIDTH = 0.22
EXPONENT = 0.7
FLOOR = -0.02
FLOOR_BLEND = 0.006
SPHERE_SUBDIVISIONS = 5
FINE_M = 0.005
COARSE_M = 0.013
FINE_UNTIL_X_M = -0.02
COARSE_FROM_X_M = 0.03


def smooth_max(a, b, k):
    """Polynomial smooth maximum: max(a, b) wherever |a - b| >= k, C1 everywhere."""
    h = max(k - abs(a - b), 0.0) / k
    return max(a, b) + h * h * k / 4.0


def organ_point(p):
    """The organ's surface point of the unit-sphere point p."""
    u, v, w = p
    s = 0.5 * (1.0 + math.tanh((u - LOBE_JOIN_U) / LOBE_JOIN_WIDTH))
    blend = lambda pair: pair[0] + (pair[1] - pair[0]) * s
    x = HALF_LENGTH * u
    y = blend(HALF_WIDTH) * v
    if w >= 0.0:
        z = blend(TOP) * w**EXPONENT
    else:
        z = smooth_max(-blend(BOTTOM) * (-w) ** EXPONENT, FLOOR, FLOOR_BLEND)
    return (x, y, z)


def icosphere(subdivisions):
    """Unit-sphere vertices and outward triangles of a subdivided icosahedron."""
    t = (1.0 + 5.0**0.5) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in q)) for c in q) for q in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                q = [(verts[a][i] + verts[b][i]) / 2.0 for i in range(3)]
                n = math.sqrt(sum(c * c for c in q))
                verts.append(tuple(c / n for c in q))
                middle[key] = len(verts) - 1
            return middle[key]

        faces = [f for a, b, c in faces
                 for f in ((a, mid(a, b), mid(c, a)), (b, mid(b, c), mid(a, b)),
                           (c, mid(c, a), mid(b, c)), (mid(a, b), mid(b, c), mid(c, a)))]
    return verts, faces


def mesh(out):
    verts, faces = icosphere(SPHERE_SUBDIVISIONS)
    points = [organ_point(p) for p in verts]
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.model.add("organ")
    gmsh.model.addDiscreteEntity(2, 1)
    gmsh.model.mesh.addNodes(2, 1, list(range(1, len(points) + 1)),
                             [c for p in points for c in p])
    gmsh.model.mesh.addElementsByType(1, 2, [], [i + 1 for f in faces for i in f])
    # One smooth surface: no feature angle splits it; patches only for the parametrization.
    gmsh.model.mesh.classifySurfaces(math.pi, True, True, math.pi)
    gmsh.model.mesh.createGeometry()
    surfaces = [s for _, s in gmsh.model.getEntities(2)]
    loop = gmsh.model.geo.addSurfaceLoop(surfaces)
    volume = gmsh.model.geo.addVolume([loop])
    gmsh.model.geo.synchronize()
    gmsh.model.addPhysicalGroup(3, [volume], 1)
    size = gmsh.model.mesh.field.add("MathEval")
    ramp = f"Min(1, Max(0, (x - ({FINE_UNTIL_X_M})) / {COARSE_FROM_X_M - FINE_UNTIL_X_M}))"
    gmsh.model.mesh.field.setString(size, "F", f"{FINE_M} + {COARSE_M - FINE_M} * {ramp}")
    gmsh.model.mesh.field.setAsBackgroundMesh(size)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.option.setNumber("Mesh.OptimizeNetgen", 1)
    gmsh.model.mesh.generate(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    position = {int(t): coords[3 * i:3 * i + 3] for i, t in enumerate(tags)}
    _, tet_nodes = gmsh.model.mesh.getElementsByType(4)
    gmsh.finalize()

    number = {}
    tets = []
    for i in range(0, len(tet_nodes), 4):
        tets.append([number.setdefault(int(t), len(number) + 1) for t in tet_nodes[i:i + 4]])
    nodes = sorted(number.items(), key=lambda kv: kv[1])
    with open(out, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        f.write(f"$Nodes\n{len(nodes)}\n")
        for tag, n in nodes:
            x, y, z = position[tag]
            if abs(z - FLOOR) < 5e-6:
                z = FLOOR
            f.write(f"{n} {x:.7f} {y:.7f} {z:.7f}\n".replace("-0.0000000", "0.0000000"))
        f.write(f"$EndNodes\n$Elements\n{len(tets)}\n")
        for e, t in enumerate(tets, 1):
            f.write(f"{e} 4 2 1 1 {t[0]} {t[1]} {t[2]} {t[3]}\n")
        f.write("$EndElements\n")
    print(f"{out}: {len(nodes)} vertices, {len(tets)} tets")


if __name__ == "__main__":
    mesh(sys.argv[1] if len(sys.argv) > 1 else "host-harness/assets/organ.msh")
