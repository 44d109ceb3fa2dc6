#!/usr/bin/env python3
"""How closely a free cubic B-spline with a given number of uniform spans can follow each curve of a network
on its own: the bound on network_max for a surface whose limit curve along a network edge of 2^N pieces is
such a spline (where its base mesh is regular) and whose rows beside each curve are free. Each polyline gets
a clamped cubic with its ends held, fitted by least squares with its control points and its points'
parameters solved together (or the first fit at arc-length parameters, where its largest distance is smaller); the
figure is the largest distance from a polyline point to its curve: a curve with that many spans comes this
close, and one chosen for its largest distance could come somewhat closer.

usage: perf/curve_spans.py NET.fnet [--spans 2,4,8] [--goal G] [--diagonal D] [--edges E,...] [--fitted SPANS OUT.fnet]
  --goal G       count the curves farther than G (a fraction of the diagonal) for each number of spans
  --diagonal D   the length distances are divided by (default: the bounding-box diagonal of the network's
                 polyline points; `fire eval` prints the reference surface's as "diagonal")
  --edges E,...  also report these network edges' distances
  --fitted S O   also write the network with each polyline replaced by its S-span curve, sampled at its
                 points' feet (the polylines a surface with S spans per curve could follow exactly)
Prints one JSON line: diagonal, curves, and per number of spans the curves measured (a polyline needs more
interior points than the spline has free control points), how many are farther than the goal, and the
five farthest (network edge, distance as a fraction of the diagonal), and those of --edges (null where too
few points).
"""
import argparse, json, math, sys

DEGREE = 3


def arc_parameters(points):
    acc = [0.0]
    for a, b in zip(points, points[1:]):
        acc.append(acc[-1] + math.dist(a, b))
    total = acc[-1]
    return [x / total for x in acc] if total > 0 else None


def knots_for(spans):
    return [0.0] * (DEGREE + 1) + [k / spans for k in range(1, spans)] + [1.0] * (DEGREE + 1)


def basis(t, knots, spans):
    """The span index s and the DEGREE + 1 basis values of control points s - DEGREE .. s at t."""
    s = min(DEGREE + int(t * spans), DEGREE + spans - 1)
    left, right, values = [0.0] * (DEGREE + 1), [0.0] * (DEGREE + 1), [1.0] + [0.0] * DEGREE
    for j in range(1, DEGREE + 1):
        left[j] = t - knots[s + 1 - j]
        right[j] = knots[s + j] - t
        saved = 0.0
        for r in range(j):
            term = values[r] / (right[r + 1] + left[j - r])
            values[r] = saved + right[r + 1] * term
            saved = left[j - r] * term
        values[j] = saved
    return s, values


def evaluate(t, knots, spans, controls):
    s, values = basis(t, knots, spans)
    return tuple(sum(values[r] * controls[s - DEGREE + r][d] for r in range(DEGREE + 1)) for d in range(3))


def solve(matrix, rhs):
    """Gaussian elimination with partial pivoting; rhs holds one column per coordinate."""
    n = len(matrix)
    rows = [matrix[i][:] + rhs[i][:] for i in range(n)]
    for c in range(n):
        pivot = max(range(c, n), key=lambda r: abs(rows[r][c]))
        if abs(rows[pivot][c]) < 1e-300:
            return None
        rows[c], rows[pivot] = rows[pivot], rows[c]
        for r in range(n):
            if r != c and rows[r][c] != 0.0:
                f = rows[r][c] / rows[c][c]
                for k in range(c, len(rows[r])):
                    rows[r][k] -= f * rows[c][k]
    return [[rows[i][n + d] / rows[i][i] for d in range(3)] for i in range(n)]


def foot(point, knots, spans, controls, samples):
    """The parameter of the curve point nearest `point`: the nearest of `samples`, then a golden-section
    search between its neighbours."""
    best = min(range(len(samples)), key=lambda i: math.dist(samples[i][1], point))
    lo = samples[max(best - 1, 0)][0]
    hi = samples[min(best + 1, len(samples) - 1)][0]
    g = (math.sqrt(5) - 1) / 2
    for _ in range(40):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        if math.dist(evaluate(a, knots, spans, controls), point) < math.dist(evaluate(b, knots, spans, controls), point):
            hi = b
        else:
            lo = a
    t = (lo + hi) / 2
    return t, math.dist(evaluate(t, knots, spans, controls), point)


def curve_and_tangent(t, knots, spans, controls):
    h = 1e-6
    a, b = max(t - h, 0.0), min(t + h, 1.0)
    pa, pb = evaluate(a, knots, spans, controls), evaluate(b, knots, spans, controls)
    return evaluate(t, knots, spans, controls), [(pb[d] - pa[d]) / (b - a) for d in range(3)]


def least_squares_controls(points, params, knots, spans):
    """The inner control points that fit the points at fixed parameters (the ends held), or None."""
    free = spans + DEGREE - 2
    first, last = points[0], points[-1]
    normal = [[0.0] * free for _ in range(free)]
    rhs = [[0.0] * 3 for _ in range(free)]
    for p, t in zip(points[1:-1], params[1:-1]):
        s, values = basis(t, knots, spans)
        row, target = {}, list(p)
        for r in range(DEGREE + 1):
            i = s - DEGREE + r
            if i == 0:
                target = [target[d] - values[r] * first[d] for d in range(3)]
            elif i == spans + DEGREE - 1:
                target = [target[d] - values[r] * last[d] for d in range(3)]
            else:
                row[i - 1] = values[r]
        for a, va in row.items():
            for b, vb in row.items():
                normal[a][b] += va * vb
            for d in range(3):
                rhs[a][d] += va * target[d]
    inner = solve(normal, rhs)
    return None if inner is None else [tuple(first)] + [tuple(c) for c in inner] + [tuple(last)]


def squared_error(points, params, knots, spans, controls):
    return sum(math.dist(evaluate(t, knots, spans, controls), p) ** 2 for p, t in zip(points[1:-1], params[1:-1]))


def fit_curve(points, spans, start=None, iterations=500):
    """(largest point-to-curve distance, the points' feet on the curve, their parameters) of the
    least-squares cubic, control points and the points' parameters solved together (Levenberg-Marquardt, the
    parameters eliminated from each step), from the parameters `start` (default: by arc length), or None for
    too few points. Of the first least-squares curve (at the starting parameters) and the solved one, the
    one whose largest distance is smaller."""
    params = list(start) if start else arc_parameters(points)
    free = spans + DEGREE - 2  # control points between the two held at the ends
    if params is None or len(points) - 2 < free:
        return None
    knots = knots_for(spans)
    controls = least_squares_controls(points, params, knots, spans)
    if controls is None and start:  # the start leaves a span without points
        params = arc_parameters(points)
        controls = least_squares_controls(points, params, knots, spans)
    if controls is None:
        return None
    first_guess = controls
    cost = squared_error(points, params, knots, spans, controls)
    damping = 1e-3
    n = 3 * free
    for _ in range(iterations):
        if cost == 0.0:
            break
        matrix = [[0.0] * n for _ in range(n)]
        rhs = [0.0] * n
        terms = []
        for p, t in zip(points[1:-1], params[1:-1]):
            c, tangent = curve_and_tangent(t, knots, spans, controls)
            residual = [c[d] - p[d] for d in range(3)]
            q = sum(x * x for x in tangent) * (1 + damping) + 1e-30
            along = sum(tangent[d] * residual[d] for d in range(3)) / q
            s, values = basis(t, knots, spans)
            rows = [(s - DEGREE + r - 1, values[r]) for r in range(DEGREE + 1) if 0 < s - DEGREE + r < spans + DEGREE - 1]
            terms.append((rows, tangent, residual, q))
            for a, va in rows:
                for d in range(3):
                    rhs[3 * a + d] -= va * (residual[d] - tangent[d] * along)
                for b, vb in rows:
                    for d in range(3):
                        for e in range(3):
                            matrix[3 * a + d][3 * b + e] += va * vb * ((d == e) - tangent[d] * tangent[e] / q)
        for i in range(n):
            matrix[i][i] *= 1 + damping
        step = solve(matrix, [[x, 0.0, 0.0] for x in rhs])
        if step is None:
            break
        step = [row[0] for row in step]
        moved_controls = [controls[0]] + [tuple(controls[i + 1][d] + step[3 * i + d] for d in range(3)) for i in range(free)] + [controls[-1]]
        moved_params = [0.0]
        for (rows, tangent, residual, q), t in zip(terms, params[1:-1]):
            change = sum(va * tangent[d] * step[3 * a + d] for a, va in rows for d in range(3))
            moved_params.append(min(max(t - (sum(tangent[d] * residual[d] for d in range(3)) + change) / q, 0.0), 1.0))
        moved_params.append(1.0)
        moved_cost = squared_error(points, moved_params, knots, spans, moved_controls)
        if moved_cost < cost:
            settled = cost - moved_cost <= 1e-14 * cost
            controls, params, cost = moved_controls, moved_params, moved_cost
            damping = max(damping / 3, 1e-12)
            if settled:
                break
        else:
            damping *= 4
            if damping > 1e8:
                break
    # On noisy points a smaller sum of squares can come with a larger largest distance (the parameters let
    # the curve loop): the curve with the smaller largest distance is the one reported.
    best = None
    for candidate in (first_guess,) if controls is first_guess else (first_guess, controls):
        samples = [(i / (200 * spans), evaluate(i / (200 * spans), knots, spans, candidate)) for i in range(200 * spans + 1)]
        feet = [foot(p, knots, spans, candidate, samples) for p in points[1:-1]]
        farthest = max((f[1] for f in feet), default=0.0)
        if best is None or farthest < best[0]:
            curve_points = [tuple(points[0])] + [evaluate(f[0], knots, spans, candidate) for f in feet] + [tuple(points[-1])]
            best = (farthest, curve_points, [0.0] + [f[0] for f in feet] + [1.0])
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("network", help="curve network (.fnet)")
    parser.add_argument("--spans", default="2,4,8", help="numbers of uniform spans to fit, comma-separated (default 2,4,8)")
    parser.add_argument("--goal", type=float, default=1e-4, help="count curves farther than this fraction of the diagonal (default 1e-4)")
    parser.add_argument("--diagonal", type=float, help="length distances are divided by (default: the polylines' bounding-box diagonal)")
    parser.add_argument("--edges", default="", help="also report these network edges, comma-separated")
    parser.add_argument("--fitted", nargs=2, metavar=("SPANS", "OUT"),
                        help="write the network with each polyline replaced by its SPANS-span fit to OUT")
    args = parser.parse_args()
    try:
        with open(args.network) as f:
            net = json.load(f)
        edges = net["edges"]
        polylines = [[tuple(map(float, p)) for p in e["points"]] for e in edges]
    except (OSError, ValueError, KeyError, TypeError) as error:
        sys.exit(f"perf/curve_spans.py: {args.network}: not a readable curve network: {error}")
    try:
        span_counts = [int(s) for s in args.spans.split(",")]
        named = [int(e) for e in args.edges.split(",")] if args.edges else []
    except ValueError:
        sys.exit("perf/curve_spans.py: --spans and --edges take numbers separated by commas")
    if any(not 0 <= e < len(polylines) for e in named):
        sys.exit(f"perf/curve_spans.py: --edges {args.edges}: the network has edges 0 to {len(polylines) - 1}")
    if any(s < 1 for s in span_counts) or not args.goal > 0:
        sys.exit("perf/curve_spans.py: --spans must be 1 or more and --goal positive")
    diagonal = args.diagonal
    if diagonal is None:
        every = [p for line in polylines for p in line]
        diagonal = math.dist([min(p[d] for p in every) for d in range(3)], [max(p[d] for p in every) for d in range(3)])
    if not diagonal > 0:
        sys.exit("perf/curve_spans.py: the diagonal must be positive")

    report = {"network": args.network, "diagonal": diagonal, "goal": args.goal, "curves": len(polylines), "spans": {}}
    counts = sorted(set(span_counts + ([int(args.fitted[0])] if args.fitted else [])))
    results = {spans: {} for spans in counts}  # spans -> edge -> (distance, curve points)
    for e, line in enumerate(polylines):
        previous = None  # (spans, parameters) of this curve's last fit
        for spans in counts:
            start = previous[1] if previous and spans % previous[0] == 0 else None
            fitted = fit_curve(line, spans, start)
            if fitted is not None:
                results[spans][e] = (fitted[0] / diagonal, fitted[1])
                previous = (spans, fitted[2])
        if (e + 1) % 50 == 0:
            print(f"perf/curve_spans.py: {e + 1} of {len(polylines)} curves", file=sys.stderr)
    for spans in span_counts:
        measured = sorted(((d, e) for e, (d, _) in results[spans].items()), reverse=True)
        report["spans"][str(spans)] = {
            "measured": len(measured),
            "over_goal": sum(1 for d, _ in measured if d > args.goal),
            "farthest": [[e, d] for d, e in measured[:5]],
            "edges": {str(e): results[spans][e][0] if e in results[spans] else None for e in named},
        }
    if args.fitted:
        for e, (_, curve_points) in results[int(args.fitted[0])].items():
            edges[e]["points"] = [list(p) for p in curve_points]
        with open(args.fitted[1], "w") as f:
            json.dump(net, f)
    print(json.dumps(report))


if __name__ == "__main__":
    main()
