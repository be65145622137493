#!/usr/bin/env python3
"""Writes the interior test scene: a roofed courtyard (an atrium) shaped like an architectural model a
user downloads. A closed building 8 m square and 3 m high whose roof has a 3 m square opening in
the middle, an arcade of faceted octagonal columns and lintels around the opening, a low wall
between two rooms, a faceted ball and a bench in the open part. Most of the floor sees the sky only
through the opening, so a lit frame that lets the sky past walls beyond a screen-space radius is
several times too bright here.

The OBJ is written as downloaded models come: no vertex normals, no smoothing groups (so its faces
are flat, as Blender, Assimp and tinyobjloader read it), every fifth quad wound the other way.

    python3 scenes/make_courtyard.py   # scenes/assets/courtyard.obj, scenes/assets/courtyard_ball.obj
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
HALF = 4.0          # the building spans [-4, 4] in x and z
HEIGHT = 3.0        # floor at y = 0, ceiling at y = 3
WALL = 0.25         # outer walls and roof slab, metres (5 level-0 voxels of the study's 5 cm)
OPENING = 1.5       # the roof opening spans [-1.5, 1.5] in x and z
ARCADE = 2.1        # columns on the square |x| or |z| = 2.1 around the opening
COLUMN_R = 0.18
LINTEL = (2.4, 3.0)  # lintels between the columns, y range


class Mesh:
    def __init__(self):
        self.v, self.f = [], []
        self.index = {}
        self.quads = 0

    def vert(self, p):
        """Vertices are shared between faces, as in most exported models."""
        key = tuple(round(c, 6) for c in p)
        if key not in self.index:
            self.v.append(key)
            self.index[key] = len(self.v)
        return self.index[key]

    def quad(self, a, b, c, d):
        """A quad a, b, c, d counter-clockwise seen from its front; every fifth one is flipped."""
        ids = [self.vert(p) for p in (a, b, c, d)]
        self.quads += 1
        if self.quads % 5 == 0:
            ids.reverse()
        self.f.append(ids)

    def box(self, lo, hi):
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        self.quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))  # +z
        self.quad((x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0))  # -z
        self.quad((x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1))  # +x
        self.quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0))  # -x
        self.quad((x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0))  # +y
        self.quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))  # -y

    def column(self, cx, cz, r, y0, y1, sides=8):
        """A faceted prism (its side faces flat, as the file means them)."""
        ring = [(cx + r * math.cos(2 * math.pi * (i + 0.5) / sides),
                 cz + r * math.sin(2 * math.pi * (i + 0.5) / sides)) for i in range(sides)]
        for i in range(sides):
            (xa, za), (xb, zb) = ring[i], ring[(i + 1) % sides]
            self.quad((xb, y0, zb), (xa, y0, za), (xa, y1, za), (xb, y1, zb))

    def write(self, path, header):
        with open(path, "w") as out:
            out.write(header)
            for p in self.v:
                out.write("v %.6g %.6g %.6g\n" % p)
            for f in self.f:
                out.write("f %s\n" % " ".join(str(i) for i in f))


def building():
    m = Mesh()
    h, t = HALF, WALL
    # Floor slab and four outer walls (boxes, so the walls have an inside and an outside).
    m.box((-h - t, -t, -h - t), (h + t, 0.0, h + t))
    m.box((-h - t, 0.0, -h - t), (h + t, HEIGHT, -h))
    m.box((-h - t, 0.0, h), (h + t, HEIGHT, h + t))
    m.box((-h - t, 0.0, -h), (-h, HEIGHT, h))
    m.box((h, 0.0, -h), (h + t, HEIGHT, h))
    # The roof slab around the opening: four boxes.
    o, y0, y1 = OPENING, HEIGHT, HEIGHT + t
    m.box((-h - t, y0, -h - t), (h + t, y1, -o))
    m.box((-h - t, y0, o), (h + t, y1, h + t))
    m.box((-h - t, y0, -o), (-o, y1, o))
    m.box((o, y0, -o), (h + t, y1, o))
    # The arcade: 4 columns per side on the square |x|, |z| = ARCADE, lintels between them.
    a = ARCADE
    stations = [-a, -a / 3, a / 3, a]
    posts = set()
    for s in stations:
        for p in ((s, -a), (s, a), (-a, s), (a, s)):
            posts.add((round(p[0], 6), round(p[1], 6)))
    for (x, z) in sorted(posts):
        m.column(x, z, COLUMN_R, 0.0, LINTEL[0])
    w = 0.15
    m.box((-a - w, LINTEL[0], -a - w), (a + w, LINTEL[1], -a + w))
    m.box((-a - w, LINTEL[0], a - w), (a + w, LINTEL[1], a + w))
    m.box((-a - w, LINTEL[0], -a + w), (-a + w, LINTEL[1], a - w))
    m.box((a - w, LINTEL[0], -a + w), (a + w, LINTEL[1], a - w))
    # A partition wall with a doorway in the back walkway, and a bench in the open part.
    m.box((-h, 0.0, -3.2), (-2.6, 2.2, -3.0))
    m.box((-1.0, 0.0, 0.6), (0.2, 0.45, 1.0))
    return m


def ball(cx, cy, cz, r, rings=6, segments=10):
    """A low-polygon UV sphere: the facets of a simplified scanned model."""
    m = Mesh()
    def p(i, j):
        th = math.pi * i / rings
        ph = 2 * math.pi * j / segments
        return (cx + r * math.sin(th) * math.cos(ph), cy + r * math.cos(th), cz + r * math.sin(th) * math.sin(ph))
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
            if i == 0:
                m.f.append([m.vert(a), m.vert(c), m.vert(b)])
            elif i == rings - 1:
                m.f.append([m.vert(a), m.vert(d), m.vert(b)])
            else:
                m.quad(a, d, c, b)
    return m


def main():
    header = ("# The courtyard of scenes/courtyard.yaml, written by scenes/make_courtyard.py: no vertex\n"
              "# normals, no smoothing groups, every fifth quad wound the other way.\n")
    building().write(os.path.join(HERE, "assets", "courtyard.obj"), header)
    ball(0.9, 0.55, -0.6, 0.5).write(os.path.join(HERE, "assets", "courtyard_ball.obj"),
                                      "# A faceted ball for scenes/courtyard.yaml (scenes/make_courtyard.py).\n")


if __name__ == "__main__":
    main()
