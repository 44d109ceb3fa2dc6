#!/usr/bin/env python3
"""Counts folds in a reconstructed surface: pairs of faces sharing an edge whose normals differ by more
than 30 and 60 degrees (a smooth surface meshed at level 3 stays under about 15 degrees; a fold, where
the surface doubles back on itself, approaches 180), where the largest angle is (the middle of the edge the
two faces share), and faces whose normal points down (-z) for a
surface drawn over a height field such as the demo dome.

usage: perf/folds.py SURFACE.obj      prints one JSON line
"""
import json, math, sys


def read_obj(path):
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vertices.append(tuple(map(float, line.split()[1:4])))
            elif line.startswith("f "):
                faces.append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return vertices, faces


def normal(vertices, face):
    # Newell's method: the area-weighted normal of a polygon
    n = [0.0, 0.0, 0.0]
    for i, a in enumerate(face):
        p, q = vertices[a], vertices[face[(i + 1) % len(face)]]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    length = math.sqrt(sum(x * x for x in n))
    return [x / length for x in n] if length > 0 else n


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    vertices, faces = read_obj(sys.argv[1])
    normals = [normal(vertices, f) for f in faces]
    sides = {}
    for i, f in enumerate(faces):
        for k, a in enumerate(f):
            b = f[(k + 1) % len(f)]
            sides.setdefault((min(a, b), max(a, b)), []).append(i)
    angles, worst_at = [], None
    for (a, b), pair in sides.items():
        if len(pair) == 2:
            c = sum(normals[pair[0]][i] * normals[pair[1]][i] for i in range(3))
            angles.append(math.degrees(math.acos(max(-1.0, min(1.0, c)))))
            if worst_at is None or angles[-1] > worst:
                worst = angles[-1]
                worst_at = [round((vertices[a][i] + vertices[b][i]) / 2, 6) for i in range(3)]
    print(json.dumps({"faces": len(faces), "face_pairs": len(angles),
                      "max_angle_deg": round(max(angles, default=0.0), 1), "max_angle_at": worst_at,
                      "pairs_over_30_deg": sum(a > 30 for a in angles),
                      "pairs_over_60_deg": sum(a > 60 for a in angles),
                      "faces_facing_down": sum(n[2] < 0 for n in normals)}))


main()
