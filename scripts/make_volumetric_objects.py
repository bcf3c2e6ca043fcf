#!/usr/bin/env python3
"""Writes the objects of the volumetric views (docs/volumetric.md), deterministically:

- scenes/volumetric/tree.obj (+ tree.mtl): a tree of small random leaves: a trunk (an
  octagonal prism, closed) and 4,000 leaves, each a 12 x 8 cm quad (two triangles) at a point
  drawn uniformly in a crown of radius 2 m, oriented at random;
- scenes/volumetric/sphere.obj: a closed smooth mesh, an icosphere of radius 0.5 m (5,120
  triangles, wound outward).

    /usr/bin/python3 scripts/make_volumetric_objects.py
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(os.path.dirname(HERE), "scenes", "volumetric")


def tree(path, leaves=4000, seed=5):
    rng = random.Random(seed)
    v, faces = [], []  # faces: (material, [i, j, k])

    def vert(p):
        v.append(p)
        return len(v)

    # Trunk: octagonal prism from y = 0 to 3.2, radius 0.15, with caps.
    n, r, top = 8, 0.15, 3.2
    ring0 = [vert((r * math.cos(2 * math.pi * i / n), 0.0, r * math.sin(2 * math.pi * i / n)))
             for i in range(n)]
    ring1 = [vert((r * math.cos(2 * math.pi * i / n), top, r * math.sin(2 * math.pi * i / n)))
             for i in range(n)]
    c0, c1 = vert((0.0, 0.0, 0.0)), vert((0.0, top, 0.0))
    for i in range(n):
        j = (i + 1) % n
        faces.append(("bark", [ring0[i], ring1[i], ring1[j]]))
        faces.append(("bark", [ring0[i], ring1[j], ring0[j]]))
        faces.append(("bark", [c0, ring0[i], ring0[j]]))
        faces.append(("bark", [c1, ring1[j], ring1[i]]))
    # Leaves in a ball of radius 2 about (0, 4.5, 0).
    for _ in range(leaves):
        while True:
            p = [rng.uniform(-1, 1) for _ in range(3)]
            if sum(x * x for x in p) <= 1.0:
                break
        c = (2.0 * p[0], 4.5 + 2.0 * p[1], 2.0 * p[2])
        # A random orthonormal frame: normal uniform on the sphere, then a random spin.
        z = rng.uniform(-1, 1)
        phi = rng.uniform(0, 2 * math.pi)
        nrm = (math.sqrt(1 - z * z) * math.cos(phi), math.sqrt(1 - z * z) * math.sin(phi), z)
        a = (1.0, 0.0, 0.0) if abs(nrm[0]) < 0.9 else (0.0, 1.0, 0.0)
        t = [a[1] * nrm[2] - a[2] * nrm[1], a[2] * nrm[0] - a[0] * nrm[2], a[0] * nrm[1] - a[1] * nrm[0]]
        tl = math.sqrt(sum(x * x for x in t))
        t = [x / tl for x in t]
        b = [nrm[1] * t[2] - nrm[2] * t[1], nrm[2] * t[0] - nrm[0] * t[2], nrm[0] * t[1] - nrm[1] * t[0]]
        spin = rng.uniform(0, 2 * math.pi)
        cs, sn = math.cos(spin), math.sin(spin)
        u = [cs * t[k] + sn * b[k] for k in range(3)]
        w = [-sn * t[k] + cs * b[k] for k in range(3)]
        hu, hw = 0.06, 0.04
        q = [vert(tuple(c[k] + su * hu * u[k] + sw * hw * w[k] for k in range(3)))
             for su, sw in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        faces.append(("leaf", [q[0], q[1], q[2]]))
        faces.append(("leaf", [q[0], q[2], q[3]]))
    with open(path[:-4] + ".mtl", "w") as f:
        f.write("# tree.obj's materials (scripts/make_volumetric_objects.py)\n")
        f.write("newmtl bark\nKd 0.35 0.25 0.15\n\nnewmtl leaf\nKd 0.2 0.5 0.12\n")
    with open(path, "w") as f:
        f.write(f"# A tree: trunk and {leaves} random leaves (scripts/make_volumetric_objects.py)\n")
        f.write("mtllib tree.mtl\n")
        for p in v:
            f.write("v %.5f %.5f %.5f\n" % p)
        current = None
        for m, idx in faces:
            if m != current:
                f.write(f"usemtl {m}\n")
                current = m
            f.write("f %d %d %d\n" % tuple(idx))


def icosphere(path, level=4, radius=0.5, centre=(0.0, 0.5, 0.0)):
    t = (1 + math.sqrt(5)) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
             (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(x / math.sqrt(sum(y * y for y in p)) for x in p) for p in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def m(i, j):
            key = (min(i, j), max(i, j))
            if key not in mid:
                p = [(verts[i][k] + verts[j][k]) / 2 for k in range(3)]
                ln = math.sqrt(sum(x * x for x in p))
                verts.append(tuple(x / ln for x in p))
                mid[key] = len(verts) - 1
            return mid[key]

        faces = [f for a, b, c in faces
                 for f in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)), (c, m(c, a), m(b, c)),
                           (m(a, b), m(b, c), m(c, a)))]
    with open(path, "w") as f:
        f.write(f"# An icosphere, {len(faces)} triangles wound outward "
                "(scripts/make_volumetric_objects.py)\n")
        for p in verts:
            f.write("v %.6f %.6f %.6f\n" % tuple(centre[k] + radius * p[k] for k in range(3)))
        for a, b, c in faces:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    tree(os.path.join(OUT, "tree.obj"))
    icosphere(os.path.join(OUT, "sphere.obj"))
