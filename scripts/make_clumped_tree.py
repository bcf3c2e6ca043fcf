#!/usr/bin/env python3
"""Writes the trees of the aerial forest (scenes/aerial-forest.json, the benchmark's V1), whose
foliage is clumped in shoots along branches rather than spread uniformly in an envelope:

- scenes/volumetric/clumped-tree.obj (+ clumped-tree.mtl): a broadleaf tree 9.9 m tall with
  a crown about 4.4 m wide: a tapered trunk, a leader and 7 main branches (limbs), each with
  5 twigs; shoots at the tip of each limb and 2-3 along each twig (its tip included): clusters
  of 20-60 leaves within 22 cm of the shoot's centre, each leaf a quad 6-10 cm long and 2/3 as
  wide (two triangles), facing mostly outward and up: 4,230 leaves in 110 shoots, 9,836
  triangles;
- scenes/volumetric/clumped-conifer.obj (+ clumped-conifer.mtl): a conifer 12 m tall with a
  conical crown about 3.5 m wide at its base: a tapered trunk and 20 whorls of 5 drooping
  branches every 0.5 m, with needle clumps every 0.25 m along each branch (at least one), each
  a brush of 16 needle sprays (thin quads 10-14 cm long and 2.5 cm wide, each standing for a
  tuft of needles) radiating from the shoot: 5,440 sprays in 340 clumps, 13,308 triangles.

Branches and twigs are hexagonal prisms (open ends). Everything is drawn from a
random.Random(seed), so the files are the same bytes on every run. Standard library only.

    /usr/bin/python3 scripts/make_clumped_tree.py          # writes both
    /usr/bin/python3 scripts/make_clumped_tree.py --print  # also prints counts and extents
"""
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(os.path.dirname(HERE), "scenes", "volumetric")


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    n = math.sqrt(dot(a, a))
    return mul(a, 1.0 / n)


def frame(n):
    """Two unit vectors orthogonal to the unit vector n and to each other."""
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    t = norm(cross(a, n))
    return t, cross(n, t)


def unit_sphere(rng):
    z = rng.uniform(-1, 1)
    phi = rng.uniform(0, 2 * math.pi)
    s = math.sqrt(1 - z * z)
    return (s * math.cos(phi), s * math.sin(phi), z)


def in_ball(rng):
    while True:
        p = (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        if dot(p, p) <= 1.0:
            return p


class Mesh:
    def __init__(self):
        self.v = []
        self.faces = []  # (material, (i, j, k)), 1-based

    def vert(self, p):
        self.v.append(p)
        return len(self.v)

    def tri(self, m, a, b, c):
        self.faces.append((m, (a, b, c)))

    def cylinder(self, p0, p1, r0, r1, m="bark", sides=6):
        """An open prism from p0 (radius r0) to p1 (radius r1)."""
        t, b = frame(norm(sub(p1, p0)))
        ring = []
        for p, r in ((p0, r0), (p1, r1)):
            ring.append([self.vert(add(p, add(mul(t, r * math.cos(2 * math.pi * i / sides)),
                                               mul(b, r * math.sin(2 * math.pi * i / sides)))))
                         for i in range(sides)])
        for i in range(sides):
            j = (i + 1) % sides
            self.tri(m, ring[0][i], ring[1][i], ring[1][j])
            self.tri(m, ring[0][i], ring[1][j], ring[0][j])

    def quad(self, m, c, u, w, hu, hw):
        q = [self.vert(add(c, add(mul(u, su * hu), mul(w, sw * hw))))
             for su, sw in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        self.tri(m, q[0], q[1], q[2])
        self.tri(m, q[0], q[2], q[3])

    def count(self, m):
        return sum(1 for mm, _ in self.faces if mm == m)

    def write(self, path, header, materials):
        mtl = os.path.basename(path)[:-4] + ".mtl"
        with open(path[:-4] + ".mtl", "w") as f:
            f.write(f"# {os.path.basename(path)}'s materials (scripts/make_clumped_tree.py)\n")
            f.write("\n".join(f"newmtl {name}\nKd {kd}\n" for name, kd in materials))
        with open(path, "w") as f:
            f.write(f"# {header} (scripts/make_clumped_tree.py)\n")
            f.write(f"mtllib {mtl}\n")
            for p in self.v:
                f.write("v %.4f %.4f %.4f\n" % p)
            current = None
            for m, idx in self.faces:
                if m != current:
                    f.write(f"usemtl {m}\n")
                    current = m
                f.write("f %d %d %d\n" % idx)


def bezier(p0, p1, p2, u):
    a = mul(p0, (1 - u) ** 2)
    b = mul(p1, 2 * u * (1 - u))
    c = mul(p2, u * u)
    return add(a, add(b, c))


def limb(mesh, p0, p1, p2, r0, r1, segments):
    """A curved branch (quadratic Bezier) of `segments` prisms; returns its points."""
    pts = [bezier(p0, p1, p2, s / segments) for s in range(segments + 1)]
    for s in range(segments):
        u0, u1 = s / segments, (s + 1) / segments
        mesh.cylinder(pts[s], pts[s + 1], r0 + (r1 - r0) * u0, r0 + (r1 - r0) * u1)
    return pts


def shoot(mesh, rng, centre, outward, leaves, radius=0.22):
    """A cluster of `leaves` leaves within `radius` of `centre`, facing about `outward`."""
    for _ in range(leaves):
        p = in_ball(rng)
        c = add(centre, mul(p, radius))
        # Normal: the outward direction (and up) perturbed at random, then normalised.
        n = norm(add(add(outward, (0.0, 0.6, 0.0)), mul(unit_sphere(rng), 0.9)))
        t, b = frame(n)
        spin = rng.uniform(0, 2 * math.pi)
        cs, sn = math.cos(spin), math.sin(spin)
        u = add(mul(t, cs), mul(b, sn))
        w = add(mul(t, -sn), mul(b, cs))
        length = rng.uniform(0.06, 0.10)
        mesh.quad("leaf", c, u, w, length / 2, length / 3)


def broadleaf(path, seed=54):
    rng = random.Random(seed)
    mesh = Mesh()
    # Trunk: 0 -> 6.5 m, radius 0.18 -> 0.09; leader on to 9.3 m.
    mesh.cylinder((0.0, 0.0, 0.0), (0.0, 3.5, 0.0), 0.18, 0.14, sides=8)
    mesh.cylinder((0.0, 3.5, 0.0), (0.0, 6.5, 0.0), 0.14, 0.09, sides=8)
    leader = limb(mesh, (0.0, 6.5, 0.0), (0.1, 8.0, 0.05), (0.05, 9.3, 0.0), 0.09, 0.03, 4)
    shoots = 0
    golden = math.pi * (3 - math.sqrt(5))
    branches = []
    for k in range(7):
        h = 3.6 + 2.8 * k / 6 + rng.uniform(-0.2, 0.2)
        az = k * golden + rng.uniform(-0.3, 0.3)
        elev = math.radians(rng.uniform(25, 50) + 12 * k / 6)
        length = rng.uniform(2.2, 2.8) * (1.0 - 0.25 * k / 6)
        d = (math.cos(az) * math.cos(elev), math.sin(elev), math.sin(az) * math.cos(elev))
        p0 = (0.0, h, 0.0)
        p2 = add(p0, add(mul(d, length), (0.0, 0.5, 0.0)))
        p1 = add(p0, mul(d, length * 0.55))
        pts = limb(mesh, p0, p1, p2, 0.08, 0.025, 4)
        branches.append((pts, d))
    branches.append((leader, (0.0, 1.0, 0.0)))
    for pts, d in branches:
        horiz = norm((d[0], 0.0, d[2])) if abs(d[1]) < 0.99 else (1.0, 0.0, 0.0)
        # Twigs from the outer 70 % of the branch, alternating sides, and one at its tip.
        for j in range(5):
            u = 0.3 + 0.7 * (j + 1) / 5
            i = min(int(u * (len(pts) - 1)), len(pts) - 2)
            f = u * (len(pts) - 1) - i
            base = add(pts[i], mul(sub(pts[i + 1], pts[i]), f))
            side = mul(cross(horiz, (0.0, 1.0, 0.0)), 1 if j % 2 else -1)
            if pts is leader:
                a = rng.uniform(0, 2 * math.pi)
                side = (math.cos(a), 0.0, math.sin(a))
            td = norm(add(add(mul(horiz, 0.6), side), (0.0, rng.uniform(0.2, 0.7), 0.0)))
            tl = rng.uniform(0.6, 1.0)
            tip = add(base, mul(td, tl))
            mid = add(base, mul(td, tl * 0.5))
            limb(mesh, base, mid, tip, 0.025, 0.01, 2)
            out = norm(add(td, horiz))
            # Shoots along the twig (from its middle) and at its tip.
            for s in range(rng.randint(2, 3)):
                v = 0.45 + 0.55 * (s + 1) / 3
                c = bezier(base, mid, tip, v)
                shoot(mesh, rng, c, out, rng.randint(20, 60))
                shoots += 1
        # A shoot at the branch's own tip.
        shoot(mesh, rng, pts[-1], horiz if pts is not leader else (0.0, 1.0, 0.0),
              rng.randint(20, 60))
        shoots += 1
    leaves = mesh.count("leaf") // 2
    mesh.write(path, f"A broadleaf tree: trunk, 8 limbs, twigs and {leaves} leaves in "
               f"{shoots} shoots", [("bark", "0.35 0.25 0.15"), ("leaf", "0.18 0.45 0.1")])
    return mesh, leaves, shoots


def conifer(path, seed=55):
    rng = random.Random(seed)
    mesh = Mesh()
    top = 12.0
    mesh.cylinder((0.0, 0.0, 0.0), (0.0, 6.0, 0.0), 0.2, 0.12, sides=8)
    mesh.cylinder((0.0, 6.0, 0.0), (0.0, top, 0.0), 0.12, 0.02, sides=6)
    needles = 0
    clumps = 0
    h = 2.0
    whorl = 0
    while h < top - 0.4:
        length = 0.15 + 1.55 * (top - h) / (top - 2.0)
        az0 = rng.uniform(0, 2 * math.pi)
        for k in range(5):
            az = az0 + 2 * math.pi * k / 5 + rng.uniform(-0.25, 0.25)
            d = (math.cos(az), 0.0, math.sin(az))
            p0 = (0.0, h, 0.0)
            p1 = add(p0, add(mul(d, length * 0.5), (0.0, 0.12 * length, 0.0)))
            p2 = add(p0, add(mul(d, length), (0.0, -0.15 * length, 0.0)))
            limb(mesh, p0, p1, p2, 0.035, 0.008, 2)
            n_clumps = max(1, int(length / 0.25))
            for c_i in range(n_clumps):
                u = (c_i + 1) / n_clumps
                c = bezier(p0, p1, p2, u)
                clumps += 1
                # A brush of 16 needle sprays radiating from the shoot axis (the branch
                # direction), each a thin quad standing for a tuft of needles.
                axis = norm(sub(bezier(p0, p1, p2, min(1.0, u + 0.05)),
                                bezier(p0, p1, p2, max(0.0, u - 0.05))))
                t, b = frame(axis)
                for _ in range(16):
                    a = rng.uniform(0, 2 * math.pi)
                    spread = rng.uniform(0.3, 1.0)
                    nd = norm(add(mul(axis, rng.uniform(0.3, 1.0)),
                                  mul(add(mul(t, math.cos(a)), mul(b, math.sin(a))), spread)))
                    root = add(c, mul(axis, rng.uniform(-0.12, 0.0)))
                    ln = rng.uniform(0.10, 0.14)
                    side = norm(cross(nd, unit_sphere(rng)))
                    mesh.quad("needle", add(root, mul(nd, ln / 2)), nd, side, ln / 2, 0.0125)
                    needles += 1
        h += 0.5
        whorl += 1
    mesh.write(path, f"A conifer: trunk, {whorl} whorls of 5 branches, {needles} needle sprays in "
               f"{clumps} clumps", [("bark", "0.27 0.2 0.13"), ("needle", "0.1 0.3 0.12")])
    return mesh, needles, clumps


def extents(mesh):
    lo = [min(p[k] for p in mesh.v) for k in range(3)]
    hi = [max(p[k] for p in mesh.v) for k in range(3)]
    return lo, hi


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    for fn, name in ((broadleaf, "clumped-tree.obj"), (conifer, "clumped-conifer.obj")):
        path = os.path.join(OUT, name)
        mesh, elements, clusters = fn(path)
        if "--print" in sys.argv[1:]:
            lo, hi = extents(mesh)
            print(f"{name}: {len(mesh.faces)} triangles, {elements} leaves/needles in "
                  f"{clusters} clusters, x {lo[0]:.2f}..{hi[0]:.2f}, y {lo[1]:.2f}..{hi[1]:.2f},"
                  f" z {lo[2]:.2f}..{hi[2]:.2f}, {os.path.getsize(path)} bytes")
