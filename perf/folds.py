#!/usr/bin/env python3
"""Counts folds in a reconstructed surface: pairs of faces sharing an edge whose normals differ by more
than 30 and 60 degrees (a smooth surface meshed at level 3 stays under about 15 degrees; a fold, where
the surface doubles back on itself, approaches 180), where the largest angle is (the middle of the edge the
two faces share), and faces whose normal points down (-z) for a
surface drawn over a height field such as the demo dome.

With the network it was made from, a pair whose shared edge lies along a curve marked sharp is a crease the
person asked for, not a fold: such pairs are counted apart (crease_pairs) and left out of the rest. "Along"
is within 1 % of the surface's bounding-box diagonal of the curve's polyline points.

usage: perf/folds.py SURFACE.obj [NETWORK.fnet]      prints one JSON line
"""
import json, math, sys
from collections import defaultdict


UNIT_M = {"mm": 0.001, "cm": 0.01, "m": 1.0}


def read_obj(path):
    """Vertices in metres where FIRE's `# units:` comment names the unit (fire writes mm unless told)."""
    vertices, faces, scale = [], [], 1.0
    with open(path) as f:
        for line in f:
            if line.startswith("# units:"):
                scale = UNIT_M.get(line.split()[2].rstrip(","), 1.0)
            elif line.startswith("v "):
                vertices.append(tuple(scale * float(c) for c in line.split()[1:4]))
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


def sharp_points(path):
    with open(path) as f:
        network = json.load(f)
    return [tuple(p) for e in network["edges"] if e.get("sharp") for p in e["points"]]


def near_any(points, radius):
    """A test of whether a point lies within radius of any of points (a grid of cells of that size)."""
    cells = defaultdict(list)
    key = lambda p: tuple(int(math.floor(c / radius)) for c in p)
    for p in points:
        cells[key(p)].append(p)
    def test(q):
        k = key(q)
        return any(math.dist(p, q) <= radius for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
                   for p in cells.get((k[0] + dx, k[1] + dy, k[2] + dz), ()))
    return test


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    vertices, faces = read_obj(sys.argv[1])
    creases = sharp_points(sys.argv[2]) if len(sys.argv) == 3 else []
    diagonal = math.dist([min(v[i] for v in vertices) for i in range(3)], [max(v[i] for v in vertices) for i in range(3)])
    on_crease = near_any(creases, 0.01 * diagonal) if creases else (lambda q: False)
    crease_pairs = 0
    normals = [normal(vertices, f) for f in faces]
    sides = {}
    for i, f in enumerate(faces):
        for k, a in enumerate(f):
            b = f[(k + 1) % len(f)]
            sides.setdefault((min(a, b), max(a, b)), []).append(i)
    angles, worst_at = [], None
    for (a, b), pair in sides.items():
        if len(pair) == 2:
            if on_crease([(vertices[a][i] + vertices[b][i]) / 2 for i in range(3)]):
                crease_pairs += 1
                continue
            c = sum(normals[pair[0]][i] * normals[pair[1]][i] for i in range(3))
            angles.append(math.degrees(math.acos(max(-1.0, min(1.0, c)))))
            if worst_at is None or angles[-1] > worst:
                worst = angles[-1]
                worst_at = [round((vertices[a][i] + vertices[b][i]) / 2, 6) for i in range(3)]
    print(json.dumps({"faces": len(faces), "face_pairs": len(angles),
                      "max_angle_deg": round(max(angles, default=0.0), 1), "max_angle_at": worst_at,
                      "pairs_over_30_deg": sum(a > 30 for a in angles),
                      "pairs_over_60_deg": sum(a > 60 for a in angles),
                      "faces_facing_down": sum(n[2] < 0 for n in normals), "crease_pairs": crease_pairs}))


main()
