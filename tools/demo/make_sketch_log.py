#!/usr/bin/env python3
"""Writes tools/demo/sketch.log: a person drawing on a 20 cm dome with a tracked pen.

The session: a border polygon of four strokes (the last closes by snapping onto the first vertex),
then splitting curves covering every split case (edge-edge, edge-vertex, vertex-edge, vertex-vertex),
one stroke that is rejected (its ends lie on different faces), one undo, one redo, one delete.
Deterministic: pen jitter comes from a fixed linear congruential sequence.
"""
import math, os

SIDE = 0.2
_state = 12345
def jitter():
    global _state
    _state = (_state * 6364136223846793005 + 1442695040888963407) % 2**64
    return ((_state >> 11) / 2**53 - 0.5) * 0.0006  # +-0.3 mm

def surface(x, y):
    r2 = (x - SIDE / 2) ** 2 + (y - SIDE / 2) ** 2
    return 0.04 * math.exp(-r2 / 0.01)

def stroke(a, b, spacing=0.005, bow=0.0):
    """Samples from a to b (2D), lifted onto the dome; `bow` bends the curve sideways."""
    n = max(2, int(math.dist(a, b) / spacing) + 1)
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = math.hypot(dx, dy)
    nx, ny = -dy / length, dx / length
    pts = []
    for i in range(n):
        s = i / (n - 1)
        off = bow * math.sin(math.pi * s)
        x = a[0] + s * dx + off * nx
        y = a[1] + s * dy + off * ny
        j = (0, 0, 0) if i in (0, n - 1) else (jitter(), jitter(), jitter())
        pts.append((x + j[0], y + j[1], surface(x, y) + j[2]))
    return pts

lines = ["FIRE-LOG 1",
         "# demo: drawing on a 20 cm dome; regenerate with tools/demo/make_sketch_log.py",
         "0 meta scene dome 0.2 m"]
t = 1_000_000
def emit(kind_lines):
    global t
    for l in kind_lines:
        lines.append(f"{t} {l}")
        t += 10_000  # the pen reports at 100 Hz

def fmt(v):
    return repr(float(v))

def draw(pts, comment):
    global t
    lines.append(f"# {comment}")
    emit(["down"] + [f"pen {fmt(p[0])} {fmt(p[1])} {fmt(p[2])}" for p in pts] + ["up"])
    t += 500_000  # half a second between strokes

def command(c, comment):
    global t
    lines.append(f"# {comment}")
    emit([f"cmd {c}"])
    t += 500_000

S, H = SIDE, SIDE / 2
# Border polygon, counter-clockwise; the last stroke ends 2 mm from the first vertex and snaps closed.
draw(stroke((0, 0), (S, 0)), "border 1")
draw(stroke((S, 0), (S, S)), "border 2")
draw(stroke((S, S), (0, S)), "border 3")
draw(stroke((0, S), (0.001, 0.002)), "border 4: ends near the first vertex, closes the polygon")
draw(stroke((H, 0), (H, S), bow=0.004), "split 1 edge-edge: bottom to top")
draw(stroke((0, H), (H + 0.0039, H)), "split 2 edge-edge: left edge to the middle of split 1")
draw(stroke((H + 0.0039, H), (S, H)), "split 3 vertex-edge: from the centre vertex to the right edge")
draw(stroke((0, 0), (H + 0.0039, H), bow=0.01), "split 4 vertex-vertex: corner to centre")
draw(stroke((0.05, S), (H + 0.0039, H)), "split 5 edge-vertex: top edge to the centre")
draw(stroke((0.15, H), (0.15, S), bow=-0.003), "split 6 edge-edge in the top right quadrant")
draw(stroke((S, 0), (H + 0.001, 0.05)), "split 7 vertex-edge: bottom right corner to split 1")
draw(stroke((S, 0.05), (0.15, H)), "split 8 edge-edge: right edge to split 3")
draw(stroke((0, 0.15), (0.05, S)), "split 9 edge-vertex: left edge to the end of split 5")
draw(stroke((0.05, 0.0), (0.0984, 0.025)), "split 10 edge-edge: bottom edge to split 1")
draw(stroke((S, S), (0.15, 0.15)), "split 11 vertex-edge: top right corner to split 6")
draw(stroke((0.02, 0.02), (S - 0.01, S - 0.01)), "rejected: its ends lie on different faces")
draw(stroke((S, H), (0.15, 0.15)), "split 12 vertex-vertex: end of split 3 to the end of split 11")
command("undo", "undo split 12")
command("redo", "redo split 12")
draw(stroke((0.0, 0.1), (0.05, 0.2), bow=0.005), "split 13 vertex-vertex: left end of split 2 to the foot of split 5")
command(f"delete {fmt(0.15)} {fmt(0.175)} {fmt(surface(0.15, 0.175))}", "delete split 6")
draw(stroke((S, 0.15), (0.175, 0.175)), "split 14 edge-edge: right edge to split 11, after the delete")

here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "sketch.log"), "w") as f:
    f.write("\n".join(lines) + "\n")
