#!/usr/bin/python3
"""Tables (markdown, on stdout) and plots (PNG, next to the data) of the memory-layout study.

usage: report.py RESULTS_DIR   (the folder perf/layouts/run.sh fills)
Uses only the standard library and Debian's python3-matplotlib.
"""
import csv
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

VARIANTS = ["s1", "s2", "s3", "s4", "s5", "s6", "s3_fresh", "s4_fresh", "fire", "openmesh", "openmesh_fresh"]
OPS = ["seq_write", "seq_read", "rand_write", "rand_read"]  # the thesis's panel order
OP_TITLES = {"seq_write": "sequential writes", "seq_read": "sequential reads",
             "rand_write": "random writes", "rand_read": "random reads"}
# The thesis plots s2, s4 and s6 in its sweeps; the peers and the fresh-heap case are added.
LINE_VARIANTS = ["s2", "s4", "s6", "s4_fresh", "fire", "openmesh"]
COLORS = {"s2": "tab:blue", "s4": "tab:red", "s6": "tab:green", "s4_fresh": "tab:orange",
          "fire": "black", "openmesh": "tab:purple"}


def read_times(path):
    times, gaps = {}, {}
    with open(path) as f:
        for row in csv.reader(f):
            if row[0] == "time":
                _, _, v, op, cached, n, iters, ns = row
                times[(v, op, cached != "no", int(n), int(iters))] = float(ns)
            elif row[0] == "gap":
                gaps[(row[2], int(row[5]))] = row[7]
    return times, gaps


def fmt(x):
    return f"{x:.1f}" if x >= 10 else f"{x:.2f}"


def sweep_table(times, level, op, key_axis, values, fixed):
    axis_name = "points" if key_axis == "n" else "iterations"
    head = f"| {level} {OP_TITLES[op]}, ns per point-op (w/o / with caching) | " + " | ".join(
        f"{v:,}" for v in values) + " |"
    lines = [head, "|---" * (len(values) + 1) + "|"]
    for v in VARIANTS:
        cells = []
        for x in values:
            n, it = (x, fixed) if key_axis == "n" else (fixed, x)
            a, b = times.get((v, op, False, n, it)), times.get((v, op, True, n, it))
            cells.append(f"{fmt(a)} / {fmt(b)}" if a is not None and b is not None else "-")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    return f"{axis_name}: " + ", ".join(f"{x:,}" for x in values) + "\n\n" + "\n".join(lines)


def line_figure(times, level, key_axis, values, fixed, path):
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for ax, op in zip(axes.flat, OPS):
        for v in LINE_VARIANTS:
            for cached in (False, True):
                ys = []
                for x in values:
                    n, it = (x, fixed) if key_axis == "n" else (fixed, x)
                    ys.append(times.get((v, op, cached, n, it), float("nan")))
                ax.plot(values, ys, color=COLORS[v], linewidth=2.6 if cached else 1.2,
                        linestyle="-" if cached else "--", marker="o", markersize=3,
                        label=f"{v} {'with' if cached else 'w/o'} caching")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{OP_TITLES[op]} (-{level})")
        ax.set_xlabel("number of points" if key_axis == "n" else "iterations per point")
        ax.set_ylabel("ns per point-operation")
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8)
    what = f"{fixed} iteration" if key_axis == "n" else f"{fixed:,} points"
    fig.suptitle(f"Memory layouts, -{level}, {what}: bold = base pointer cached, dashed = not")
    fig.tight_layout(rect=(0, 0.09, 1, 0.96))
    fig.savefig(path, dpi=72)
    plt.close(fig)


def bar_figure(times_by_level, n, iters, path):
    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    for row, level in enumerate(["O0", "O2"]):
        for col, op in enumerate(["seq_write", "seq_read"]):
            ax = axes[row][col]
            xs = range(len(VARIANTS))
            low = float("inf")
            for k, cached in enumerate((False, True)):
                ys = [times_by_level[level].get((v, op, cached, n, iters), 0) for v in VARIANTS]
                low = min([low] + [y for y in ys if y > 0])
                ax.bar([x + (k - 0.5) * 0.4 for x in xs], ys, width=0.4,
                       label="with caching" if cached else "w/o caching")
            ax.set_ylim(bottom=low / 3)  # bars start well below the shortest, so their heights compare
            ax.set_xticks(list(xs))
            ax.set_xticklabels(VARIANTS, rotation=35, ha="right", fontsize=8)
            ax.set_yscale("log")  # the -O0 peers are tens of times slower than s1..s6
            ax.set_title(f"{OP_TITLES[op]} (-{level})")
            ax.set_ylabel("ns per point-operation")
            ax.legend(fontsize=8)
            ax.grid(True, axis="y", alpha=0.3)
    fig.suptitle(f"Sequential access, {n:,} points, {iters} iterations per point (as thesis figures 33 and 34); "
                 "fire's cached writes are set()")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=72)
    plt.close(fig)


def read_cachegrind(folder):
    """Counts per (variant, op): D refs, D1 misses, LLd misses, from cachegrind's summary on stderr."""
    counts = {}
    pattern = {"refs": r"D\s+refs:\s+([\d,]+)", "d1": r"D1\s+misses:\s+([\d,]+)", "ll": r"LLd misses:\s+([\d,]+)"}
    for name in os.listdir(folder):
        m = re.match(r"(.+)_(none|seq_read|seq_write|rand_read|rand_write)\.log$", name)
        if not m:
            continue
        text = open(os.path.join(folder, name)).read()
        c = {}
        for key, pat in pattern.items():
            found = re.search(pat, text)
            if not found:
                sys.exit(f"report.py: no '{key}' in {name}; did valgrind fail?")
            c[key] = int(found.group(1).replace(",", ""))
        counts[(m.group(1), m.group(2))] = c
    return counts


def cachegrind_rows(counts, points):
    rows = {}
    for v in VARIANTS:
        base = counts.get((v, "none"))
        for op in OPS:
            run = counts.get((v, op))
            if base is None or run is None:
                continue
            refs = run["refs"] - base["refs"]
            d1 = run["d1"] - base["d1"]
            ll = run["ll"] - base["ll"]
            rows[(v, op)] = (100.0 * d1 / refs, 100.0 * ll / refs, d1 / points, ll / points)
    return rows


def cachegrind_table(rows, points):
    lines = [f"cachegrind, -O2, {points:,} points, 1 iteration, base pointer not cached; counts of the operation alone "
             "(setup-only run subtracted). Cells: D1 miss rate % / LL miss rate % (of data references), then "
             "D1 / LL misses per point.", "",
             "| layout | " + " | ".join(OP_TITLES[o] for o in OPS) + " |", "|---" * (len(OPS) + 1) + "|"]
    for v in VARIANTS:
        cells = []
        for op in OPS:
            r = rows.get((v, op))
            cells.append(f"{r[0]:.1f} / {r[1]:.1f} ({r[2]:.2f} / {r[3]:.2f})" if r else "-")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def cachegrind_figure(rows, points, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    xs = range(len(VARIANTS))
    for ax, idx, title in ((axes[0], 2, "D1 misses per point"), (axes[1], 3, "LL misses per point")):
        for k, op in enumerate(OPS):
            ys = [rows.get((v, op), (0, 0, 0, 0))[idx] for v in VARIANTS]
            ax.bar([x + (k - 1.5) * 0.2 for x in xs], ys, width=0.2, label=OP_TITLES[op])
        ax.set_xticks(list(xs))
        ax.set_xticklabels(VARIANTS, rotation=35, ha="right", fontsize=8)
        ax.set_title(title)
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"cachegrind (D1 48 KiB, LL 1 MiB), -O2, {points:,} points, 1 iteration")
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(path, dpi=72)
    plt.close(fig)


def ratio_table(times_by_level):
    """Each layout against s2 (the thesis's dynamic array), w/o caching, at the largest size and 1 iteration."""
    lines = ["| layout | " + " | ".join(f"-{lv} {OP_TITLES[o]}" for lv in ("O0", "O2") for o in OPS) + " |",
             "|---" * 9 + "|"]
    big = max(n for (_, _, _, n, it) in times_by_level["O0"] if it == 1)
    for v in VARIANTS:
        cells = []
        for lv in ("O0", "O2"):
            t = times_by_level[lv]
            for o in OPS:
                a, b = t.get((v, o, False, big, 1)), t.get(("s2", o, False, big, 1))
                cells.append(f"{a / b:.2f}" if a and b else "-")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    return f"time relative to s2 at {big:,} points, 1 iteration, w/o caching\n\n" + "\n".join(lines)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    folder = sys.argv[1]
    points, iters, gaps = {}, {}, {}
    for level in ("O0", "O2"):
        points[level], g = read_times(os.path.join(folder, f"points_{level}.csv"))
        gaps.update(g)
        iters[level], _ = read_times(os.path.join(folder, f"iters_{level}.csv"))
    sizes = sorted({n for (_, _, _, n, _) in points["O0"]})
    its = sorted({it for (_, _, _, _, it) in iters["O0"]})
    iter_points = next(iter(iters["O0"]))[3]

    print("## Memory layouts: tables\n")
    print("Median address gap between consecutive points of the scattered layouts, bytes; and the share of gaps "
          "equal to one point (24 bytes):\n")
    print("| layout | " + " | ".join(f"{n:,}" for n in sizes) + " |\n" + "|---" * (len(sizes) + 1) + "|")
    for v in ("s3", "s4", "s3_fresh", "s4_fresh", "openmesh", "openmesh_fresh"):
        cells = []
        for n in sizes:
            g = gaps.get((v, n))
            cells.append(g.replace(";", " / ") if g else "-")
        print(f"| {v} | " + " | ".join(cells) + " |")
    print()
    print(ratio_table(points) + "\n")
    for level in ("O0", "O2"):
        for op in OPS:
            print(sweep_table(points[level], level, op, "n", sizes, 1) + "\n")
    for level in ("O0", "O2"):
        for op in OPS:
            print(sweep_table(iters[level], level, op, "iters", its, iter_points) + "\n")

    pngs = []
    for level in ("O0", "O2"):
        p = os.path.join(folder, f"layouts_points_{level}.png")
        line_figure(points[level], level, "n", sizes, 1, p)
        pngs.append(p)
        p = os.path.join(folder, f"layouts_iters_{level}.png")
        line_figure(iters[level], level, "iters", its, iter_points, p)
        pngs.append(p)
    p = os.path.join(folder, "layouts_sequential.png")
    bar_figure(iters, iter_points, max(its), p)
    pngs.append(p)

    cg_folder = os.path.join(folder, "cachegrind")
    if os.path.isdir(cg_folder):
        rows = cachegrind_rows(read_cachegrind(cg_folder), iter_points)
        print(cachegrind_table(rows, iter_points) + "\n")
        p = os.path.join(folder, "layouts_cachegrind.png")
        cachegrind_figure(rows, iter_points, p)
        pngs.append(p)
    print("plots: " + " ".join(pngs))


if __name__ == "__main__":
    main()
