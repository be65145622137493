#!/usr/bin/env python3
"""Writes the leak-test scenes: a closed 2 m room lit only from outside (a sky and a point light),
walls 0.25 to 4 voxels of 5 cm thick (the voxel GI study's level-0 voxel). The truth inside is
zero indirect light; whatever a voxel technique gathers there leaked through the wall.

    python3 scenes/make_leak_rooms.py     # scenes/leak_room_*.yaml and scenes/assets/leak_room_*.obj
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
VOXEL = 0.05
LO, HI = (-1.0, 0.0, -1.0), (1.0, 2.0, 1.0)


def box(lo, hi, inward):
    c = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    quads = [(1, 3, 7, 5), (0, 4, 6, 2), (2, 6, 7, 3), (0, 1, 5, 4), (4, 5, 7, 6), (0, 2, 3, 1)]
    tris = []
    for q in quads:
        for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            tris.append((t[0], t[2], t[1]) if inward else t)
    return c, tris


def write(thickness_voxels):
    t = thickness_voxels * VOXEL
    name = "leak_room_%s" % ("%g" % thickness_voxels).replace(".", "p")
    vertices, faces = [], []
    for lo, hi, inward in (([a - t for a in LO], [a + t for a in HI], False), (LO, HI, True)):
        c, tris = box(lo, hi, inward)
        base = len(vertices)
        vertices += c
        faces += [tuple(base + i for i in tri) for tri in tris]
    with open(os.path.join(HERE, "assets", name + ".obj"), "w") as f:
        f.write("# %s: closed room, walls %g voxels of %g m\n" % (name, thickness_voxels, VOXEL))
        for v in vertices:
            f.write("v %.6f %.6f %.6f\n" % v)
        for tri in faces:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in tri))
    with open(os.path.join(HERE, name + ".yaml"), "w") as f:
        f.write(
            "# Leak test (scenes/make_leak_rooms.py): a closed room, walls %g voxels of %g m thick,\n"
            "# lit only from outside. The indirect light inside is zero; a voxel technique's\n"
            "# indirect irradiance here is light that leaked through the wall.\n"
            "scene: %s\n"
            "materials:\n"
            "  - {name: plaster, albedo: [0.7, 0.7, 0.7]}\n"
            "meshes:\n"
            "  - {file: assets/%s.obj, material: plaster}\n"
            "point_lights:\n"
            "  - {position: [0.0, 1.0, 2.5], intensity: [40, 40, 40]}\n"
            "sky: {kind: constant, radiance: [1.0, 1.0, 1.0]}\n"
            "camera: {position: [0.0, 1.2, 0.8], target: [0.0, 0.6, -1.0], fov: 70, near: 0.02, far: 10}\n"
            "parameters: {wall_voxels: %g}\n"
            % (thickness_voxels, VOXEL, name, name, thickness_voxels))


for k in (0.25, 0.5, 1, 2, 4):
    write(k)
