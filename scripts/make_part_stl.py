#!/usr/bin/python3
"""Writes config/meshes/part.stl, the example mesh collider: an L-shaped bracket, closed and not convex,
centred on its bounding box. Its profile in the x-z plane, (0, 0), (0.1, 0), (0.1, 0.02), (0.02, 0.02),
(0.02, 0.08), (0, 0.08) [m] (a 10 cm foot and an 8 cm upright, both 2 cm thick), is extruded 6 cm along y.
Binary STL: 80-byte header, triangle count, per triangle a normal, three corners, a 2-byte attribute."""
import os
import struct
import sys

PROFILE = [(0.0, 0.0), (0.1, 0.0), (0.1, 0.02), (0.02, 0.02), (0.02, 0.08), (0.0, 0.08)]
DEPTH = 0.06
CENTRE = (0.05, 0.03, 0.04)


def triangles():
    corners = [(x, y, z) for y in (0.0, DEPTH) for (x, z) in PROFILE]
    corners = [tuple(c - o for c, o in zip(corner, CENTRE)) for corner in corners]
    # The profile runs counter-clockwise seen from -y; the caps fan out from the concave corner 3.
    faces = []
    for a, b, c in [(3, 4, 5), (3, 5, 0), (3, 0, 1), (3, 1, 2)]:
        faces.append((a, b, c))
        faces.append((6 + a, 6 + c, 6 + b))
    for k in range(6):
        a, b = k, (k + 1) % 6
        faces.append((a, 6 + b, b))
        faces.append((a, 6 + a, 6 + b))
    return [tuple(corners[i] for i in face) for face in faces]


def normal(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    length = sum(x * x for x in n) ** 0.5
    return [x / length for x in n]


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "config", "meshes", "part.stl")
    faces = triangles()
    with open(path, "wb") as out:
        out.write(b"soft_body_sim example part: L-shaped bracket, metres".ljust(80, b" "))
        out.write(struct.pack("<I", len(faces)))
        for a, b, c in faces:
            out.write(struct.pack("<12fH", *normal(a, b, c), *a, *b, *c, 0))
    print("%s: %d triangles" % (path, len(faces)))


if __name__ == "__main__":
    main()
