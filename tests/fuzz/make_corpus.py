#!/usr/bin/env python3
"""Writes the fuzz targets' seed corpora into tests/fuzz/corpus/<target>/: small valid inputs in the
layouts FIRE writes (taken from the demo log, the shared meshes and the formats' writers) and a few broken
ones. Run from the repository root; the output is committed, so rerun only to change the seeds. The
session seeds are real session folders written by `fire replay --session` (FIRE=path/to/fire, default
build/fire)."""
import glob
import json
import math
import os
import struct
import subprocess
import tempfile

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
shared = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "data", "meshes")


def put(target, name, data):
    os.makedirs(os.path.join(root, target), exist_ok=True)
    with open(os.path.join(root, target, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# ---- hid: reports 0x33 (extended IR), 0x36 and 0x37 (basic IR), others
def ext_slot(x, y, size):
    return bytes([x & 0xFF, y & 0xFF, ((y >> 8) & 3) << 6 | ((x >> 8) & 3) << 4 | size])


unseen = b"\xff\xff\xff"
put("hid", "r33_two_blobs", bytes([0x33, 0x00, 0x00, 0x80, 0x80, 0x9A]) + ext_slot(512, 384, 3) + ext_slot(1000, 700, 2) + unseen + unseen)
put("hid", "r33_no_blobs", bytes([0x33, 0x60, 0x20, 0x80, 0x80, 0x9A]) + unseen * 4)
put("hid", "r33_out_of_range", bytes([0x33, 0, 0, 0, 0, 0]) + ext_slot(10, 900, 1) + ext_slot(1023, 767, 15) + unseen + unseen)
put("hid", "r36_basic", bytes([0x36, 0, 0]) + bytes([0x10, 0x20, 0x55, 0x30, 0x40]) + b"\xff" * 5 + bytes(9))
put("hid", "r37_basic", bytes([0x37, 0, 0, 0x80, 0x80, 0x9A]) + bytes([0x10, 0x20, 0x55, 0x30, 0x40]) * 2 + bytes(6))
put("hid", "r33_truncated", bytes([0x33, 0, 0, 0x80]))
put("hid", "r20_status", bytes([0x20, 0, 0, 0x02, 0, 0, 0x55]))
put("hid", "unknown_id", bytes([0x99, 1, 2, 3]))

# ---- input_log: the demo log's beginning, every event kind, and broken logs
with open(os.path.join(os.path.dirname(__file__), "..", "..", "tools", "demo", "sketch.log")) as f:
    demo = f.read().splitlines(keepends=True)
put("input_log", "demo_start.log", "".join(demo[:40]))
put("input_log", "every_kind.log", "FIRE-LOG 1\n# a comment\n0 meta scenario sketch\n1 meta seed 7 rig_seed=3\n"
    "10 truth pen 0.1 -0.2 0.5\n20 hid 0 33000080809a00801003ffffffffffffffffffffffffff\n"
    "20 hid 1 3300\n21 hid 1 zz\n30 down\n31 pen 0 0.05 0.1\n32 pen 1e-3 2.5 -0\n33 up\n"
    "40 cmd undo\n41 cmd redo\n42 cmd close\n43 cmd delete 0.1 0.2 0.3\n44 cmd sharp 0.1 0.2 0.3\n"
    "45 cmd mark 3 0.01 -0.02 0.15\n46 cmd register\n")
put("input_log", "crlf.log", "FIRE-LOG 1\r\n0 down\r\n1 pen 1 2 3\r\n2 up\r\n")
put("input_log", "bad_version.log", "FIRE-LOG 4\n0 down\n")
put("input_log", "version2.log", "FIRE-LOG 2\n30 down\n31 pen 0 0.05 0.1\n33 up\n40 cmd hole 0.1 0.2 0.3\n41 cmd undo\n")
put("input_log", "back_in_time.log", "FIRE-LOG 1\n5 down\n4 up\n")
put("input_log", "truncated.log", "FIRE-LOG 1\n0 down\n1 pen 0 0")

# ---- network: a triangle of curves with one face, and broken networks
def network(points, sharp=False):
    v = [{"p": points[0], "split": False}, {"p": points[1], "split": True}, {"p": points[2], "split": False}]
    mid = lambda a, b: [(a[k] + b[k]) / 2 + 0.125 for k in range(3)]
    e = [{"v": [i, (i + 1) % 3], "sharp": sharp and i == 0,
          "points": [points[i], mid(points[i], points[(i + 1) % 3]), points[(i + 1) % 3]]} for i in range(3)]
    f = [{"edges": [0, 1, 2], "reversed": [False, False, False]}]
    return {"format": "fire-network", "version": 1, "vertices": v, "edges": e, "faces": f}


tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]]
put("network", "triangle.fnet", json.dumps(network(tri, sharp=True), separators=(",", ":")) + "\n")
loose = network(tri)
loose["faces"] = []
put("network", "no_faces.fnet", json.dumps(loose) + "\n")
bridged = network(tri)
bridged["faces"] = []
bridged["edges"][0]["bridge"] = True
put("network", "bridge.fnet", json.dumps(bridged) + "\n")
bad = network(tri)
bad["edges"][1]["points"][0] = [9.0, 9.0, 9.0]
put("network", "polyline_off_vertex.fnet", json.dumps(bad) + "\n")
put("network", "truncated.fnet", json.dumps(network(tri))[:120])
put("network", "wrong_version.fnet", '{"format":"fire-network","version":2,"vertices":[],"edges":[],"faces":[]}\n')

# ---- obj: the small shared control meshes and broken ones
for name in ("cube.obj", "pyramid.obj", "fan.obj"):
    with open(os.path.join(shared, name), "rb") as f:
        put("obj", name, f.read())
put("obj", "slashes_negative.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1 -1\n")
put("obj", "index_out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n")
put("obj", "repeated_vertex.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 1\n")
put("obj", "nan.obj", "v 0 nan 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")


# ---- rig: a rig as rig_to_json writes it, and broken ones
def camera(angle, t, k1=0.0, k2=0.0):
    c, s = math.cos(angle), math.sin(angle)
    return {"intrinsics": {"fx": 1330.0, "fy": 1331.5, "cx": 512.25, "cy": 384.0, "k1": k1, "k2": k2},
            "R": [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]], "t": t}


rig = {"format": "fire-rig", "version": 1, "units": "metres, pixels",
       "cameras": [camera(0.0, [0.0, 0.0, 0.0]), camera(-0.2, [-0.3, 0.001, 0.02], 0.01, 1 / 3)],
       "calibration": {"reprojection_rms_px": 0.1 + 0.2, "reprojection_rms_2d_px": 0.42426406871192857,
                       "wand_length_error_mm": 1e-300, "observations_used": 5999, "observations_rejected": 3,
                       "iterations": 17}}
put("rig", "rig.json", json.dumps(rig, indent=2) + "\n")
skewed = json.loads(json.dumps(rig))
skewed["cameras"][1]["R"][0][0] = 2.0
put("rig", "not_rotation.json", json.dumps(skewed) + "\n")
put("rig", "version2.json", '{"format":"fire-rig","version":2}\n')
put("rig", "truncated.json", json.dumps(rig)[:200])

# ---- ply, stl, glb: a tetrahedron and a quad pyramid in the layouts encode_surface writes
pyramid_v = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0), (0.5, 0.5, 0.75)]
pyramid_f = [(0, 3, 2, 1), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
tetra_v = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
tetra_f = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]


def sub(a, b):
    return [a[k] - b[k] for k in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a] if n > 0 else [0.0, 0.0, 0.0]


def vertex_normals(v, f):
    acc = [[0.0, 0.0, 0.0] for _ in v]
    for face in f:
        for i in range(1, len(face) - 1):
            n = cross(sub(v[face[i]], v[face[0]]), sub(v[face[i + 1]], v[face[0]]))
            for c in face:
                acc[c] = [acc[c][k] + n[k] for k in range(3)]
    return [unit(a) if any(a) else [0.0, 0.0, 1.0] for a in acc]


def ply(v, f):
    head = ("ply\nformat binary_little_endian 1.0\ncomment FIRE surface\nelement vertex %d\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(v), len(f))).encode()
    body = b"".join(struct.pack("<6f", *p, *n) for p, n in zip(v, vertex_normals(v, f)))
    body += b"".join(struct.pack("<B%di" % len(face), len(face), *face) for face in f)
    return head + body


def fan(f):
    return [(face[0], face[i], face[i + 1]) for face in f for i in range(1, len(face) - 1)]


def stl(v, f):
    out = b"FIRE binary STL surface".ljust(80, b" ") + struct.pack("<I", len(fan(f)))
    for a, b, c in fan(f):
        n = unit(cross(sub(v[b], v[a]), sub(v[c], v[a])))
        out += struct.pack("<12fH", *n, *v[a], *v[b], *v[c], 0)
    return out


def glb(v, f):
    tris = [i for t in fan(f) for i in t]
    vb = 12 * len(v)
    bin_ = b"".join(struct.pack("<3f", *p) for p in v)
    bin_ += b"".join(struct.pack("<3f", *n) for n in vertex_normals(v, f))
    bin_ += struct.pack("<%dI" % len(tris), *tris)
    lo = [min(p[k] for p in v) for k in range(3)]
    hi = [max(p[k] for p in v) for k in range(3)]
    doc = {"asset": {"version": "2.0", "generator": "FIRE"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "mode": 4}]}],
           "buffers": [{"byteLength": len(bin_)}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": vb, "target": 34962},
                           {"buffer": 0, "byteOffset": vb, "byteLength": vb, "target": 34962},
                           {"buffer": 0, "byteOffset": 2 * vb, "byteLength": 4 * len(tris), "target": 34963}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3", "min": lo, "max": hi},
                         {"bufferView": 1, "componentType": 5126, "count": len(v), "type": "VEC3"},
                         {"bufferView": 2, "componentType": 5125, "count": len(tris), "type": "SCALAR"}]}
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(bin_)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(text), 0x4E4F534A) + text +
            struct.pack("<II", len(bin_), 0x004E4942) + bin_)


for name, (v, f) in {"tetra": (tetra_v, tetra_f), "pyramid": (pyramid_v, pyramid_f)}.items():
    put("ply", name + ".ply", ply(v, f))
    put("stl", name + ".stl", stl(v, f))
    put("glb", name + ".glb", glb(v, f))
p = ply(tetra_v, tetra_f)
put("ply", "truncated.ply", p[: len(p) - 7])
put("ply", "ascii.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0\n1\n2\n")
s = stl(tetra_v, tetra_f)
put("stl", "truncated.stl", s[:-10])
put("stl", "wrong_count.stl", s[:80] + struct.pack("<I", 7) + s[84:])
g = glb(tetra_v, tetra_f)
put("glb", "truncated.glb", g[: len(g) - 8])
put("glb", "bad_magic.glb", b"gltf" + g[4:])

# ---- session: `settings.json NUL input.log NUL snapshot` from session folders fire writes (the demo's border
# and first split; undone and redone; stopped mid-stroke), seeds with the checksum and log hash zeroed
# (fuzz_session.cpp fills them in, so mutations reach the fields behind them), a torn log, a snapshot of
# another log and a cut snapshot.
fire = os.environ.get("FIRE", "build/fire")
def coarse(lines, every):
    """The log with every `every`-th pen sample of each stroke kept, and its last: small seeds fuzz faster."""
    kept, run = [], []
    for line in lines + ["end\n"]:
        if " pen " in line:
            run.append(line)
            continue
        kept += run[::every] + ([run[-1]] if run and (len(run) - 1) % every else [])
        run = []
        kept.append(line)
    return kept[:-1]


first_split = coarse(demo[: demo.index("# split 2 edge-edge: left edge to the middle of split 1\n")], 8)
t_end = int(first_split[-1].split()[0])
logs = {
    "border_split": first_split,
    "undo_redo": first_split + [f"{t_end + 500000} cmd undo\n", f"{t_end + 1000000} cmd redo\n",
                                f"{t_end + 1500000} cmd undo\n"],
    "mid_stroke": first_split[:-3],
}


def session(lines, options=()):
    """settings, log and newest snapshot of the session fire writes replaying `lines`."""
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "in.log"), "w") as f:
            f.write("".join(lines))
        out = os.path.join(tmp, "session")
        subprocess.run([fire, "replay", os.path.join(tmp, "in.log"), "--session", out, "--snapshot-every", "25",
                        *options], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        read = lambda name: open(os.path.join(out, name), "rb").read()
        return read("settings.json"), read("input.log"), read(sorted(glob.glob(os.path.join(out, "*.fsnap")))[-1])


def zero_sums(snapshot):
    # The header's checksum (bytes 24-31) and the payload's log hash (its bytes 8-15), as fuzz_session.cpp reads them.
    return snapshot[:24] + bytes(8) + snapshot[32:40] + bytes(8) + snapshot[48:]


for name, lines in logs.items():
    settings, log, snap = session(lines, ["--no-surface"] if name == "mid_stroke" else [])
    put("session", name, settings + b"\0" + log + b"\0" + snap)
    put("session", name + "_zero_sums", settings + b"\0" + log + b"\0" + zero_sums(snap))
settings, log, snap = session(logs["border_split"])
put("session", "torn_log", settings + b"\0" + log + b"1 pen 0.1 0.2" + b"\0" + snap)
put("session", "other_log", settings + b"\0" + log.replace(b"scene dome", b"scene bowl", 1) + b"\0" + snap)
put("session", "cut_snapshot", settings + b"\0" + log + b"\0" + snap[: len(snap) // 2])


def tracked_session():
    """settings, log and the older kept snapshot (taken mid-drawing) of a short simulated Wii Remote drawing
    written as a session with its rig: a snapshot holding the triangulation system's state."""
    with tempfile.TemporaryDirectory() as tmp:
        path = lambda name: os.path.join(tmp, name)
        quiet = dict(check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        subprocess.run([fire, "simulate", "wand", "-o", path("w.log"), "--duration-s", "20"], **quiet)
        subprocess.run([fire, "calibrate", path("w.log"), "-o", path("rig.json")], **quiet)
        subprocess.run([fire, "simulate", "sketch", "-o", path("s.log"), "--duration-s", "2.5", "--strokes", "1",
                        "--hold-s", "0.3"], **quiet)
        subprocess.run([fire, "replay", path("s.log"), "--rig", path("rig.json"), "--session", path("session"),
                        "--snapshot-every", "60"], **quiet)
        read = lambda name: open(os.path.join(tmp, "session", name), "rb").read()
        older = sorted(glob.glob(os.path.join(tmp, "session", "*.fsnap")))[-2]
        return read("settings.json"), read("input.log"), open(older, "rb").read()


settings, log, snap = tracked_session()
put("session", "tracked", settings + b"\0" + log + b"\0" + snap)
