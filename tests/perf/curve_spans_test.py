#!/usr/bin/env python3
"""perf/curve_spans.py on curves whose answers are known: a curve that is itself a 2-span cubic is followed
exactly with 2 spans; a wave of four periods is not, and more spans come closer; --fitted writes
each point's foot on its curve; a malformed network is refused with its name."""
import json, math, os, subprocess, sys, tempfile

script = sys.argv[1]


def run(*args):
    return subprocess.run([sys.executable, script, *args], capture_output=True, text=True)


def report(path, *args):
    result = run(path, *args)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def bezier(p, t):
    """A cubic Bezier curve: one span, so also a 2-span cubic B-spline (a knot at 0.5 costs nothing)."""
    s = 1 - t
    return [s**3 * p[0][d] + 3 * s * s * t * p[1][d] + 3 * s * t * t * p[2][d] + t**3 * p[3][d] for d in range(3)]


with tempfile.TemporaryDirectory() as tmp:
    cubic = [bezier([(0, 0, 0), (0.3, 0.4, 0), (0.7, -0.2, 0.1), (1, 0, 0)], i / 16) for i in range(17)]
    wave = [[i / 32, 0.1 * math.sin(8 * math.pi * i / 32), 0] for i in range(33)]
    net = os.path.join(tmp, "net.fnet")
    with open(net, "w") as f:
        json.dump({"edges": [{"points": cubic}, {"points": wave}]}, f)

    r = report(net, "--spans", "2,8", "--edges", "0,1", "--goal", "1e-3")
    two, eight = r["spans"]["2"], r["spans"]["8"]
    assert abs(r["diagonal"] - math.dist((0, -0.1, 0), (1, 0.1, 0.1))) < 1e-2, r
    assert two["edges"]["0"] < 1e-9, f"a 2-span cubic is followed exactly with 2 spans: {two}"
    assert two["edges"]["1"] > 1e-2, f"a wave of four periods is not: {two}"
    assert eight["edges"]["1"] < two["edges"]["1"] / 2, f"8 spans come closer to the wave: {eight} {two}"
    assert two["over_goal"] == 1 and two["farthest"][0][0] == 1, two
    assert two["measured"] == 2 and eight["measured"] == 2, r

    fitted = os.path.join(tmp, "fitted.fnet")
    r = report(net, "--spans", "2", "--edges", "1", "--fitted", "2", fitted)
    with open(fitted) as f:
        feet = json.load(f)["edges"][1]["points"]
    farthest = max(math.dist(p, q) for p, q in zip(wave, feet)) / r["diagonal"]
    assert len(feet) == len(wave) and feet[0] == wave[0] and feet[-1] == wave[-1], feet
    assert abs(farthest - r["spans"]["2"]["edges"]["1"]) < 1e-9, f"--fitted writes the feet: {farthest} {r}"

    bad = os.path.join(tmp, "bad.fnet")
    with open(bad, "w") as f:
        f.write("{ not json")
    result = run(bad)
    assert result.returncode != 0 and "bad.fnet" in result.stderr, result
    result = run(net, "--edges", "7")
    assert result.returncode != 0 and "edges 0 to 1" in result.stderr, result
print("perf/curve_spans.py: all checks passed")
