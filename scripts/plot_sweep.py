#!/usr/bin/python3
# Figures of saarcor runs, with Debian's matplotlib (python3-matplotlib; scripts/install-deps.sh).
# The shebang names /usr/bin/python3 on purpose: a python3 earlier on PATH (pyenv, a venv) often
# lacks matplotlib.
#
#   plot_sweep.py SWEEP.csv [--out-dir DIR]     one PNG per varied key: sweep_<key>.png
#   plot_sweep.py SWEEP.csv --pareto [--cost C,...]  and frame rate against cost with the Pareto
#                                               front: sweep_pareto.png, one panel per cost column
#   plot_sweep.py PRECISION.json [--out-dir DIR]  the precision study's curve: precision_curve.png
#   plot_sweep.py RUN_FOLDER [--out-dir DIR]    a --out-dir folder (its sweep.csv or report.json)
#
# A sweep figure has four panels against the key's values: frame rate, unit usage, cache hit
# rates and memory bandwidth. With several keys varied, each other combination is one line.
# The Pareto figure (--pareto, or a CSV of `saarcor sweep --pareto`, which has a column
# pareto_<cost>) draws every point's frame rate against a cost column (fp_units, memory_kb, luts,
# block_rams; by default the CSV's pareto cost, else luts) and joins the front: the points no
# other point beats in both (at least as fast and at most as dear, better in one). The front of
# the CSV's own pareto column is the binary's; another cost's is computed here by the same rule.
# Figures go beside the input unless --out-dir says where. Prints the files written.
import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

FIGURE_COLUMNS = "cycles"  # the first figure column of a sweep CSV; the keys come before it
PANELS = [
    ("frame rate (fps)", [("fps", "fps")]),
    ("unit usage (% of cycles)",
     [("usage_traversal", "traversal"), ("usage_list", "list"),
      ("usage_transformation", "transformation"), ("usage_intersection", "intersection")]),
    ("cache hit rate (%)",
     [("cache_hit_traversal", "traversal"), ("cache_hit_list", "list"),
      ("cache_hit_transformation", "transformation")]),
    ("memory bandwidth (MB/s)", [("bandwidth_mb_s_total", "total")]),
]
COST_COLUMNS = {"fp_units": "FP units", "memory_kb": "internal memory (KB)",
                "luts": "Virtex-II LUT estimate (FP operators)",
                "block_rams": "Virtex-II 18-Kbit block RAMs (at least)"}
# What the prototype's XC2V6000 holds (units/cost.h), drawn as a line on those costs' panels.
DEVICE = {"luts": 67584, "block_rams": 144}
# Written with a fixed Software entry and no date, so the same input gives the same bytes.
PNG_METADATA = {"Software": "saarcor plot_sweep.py"}


def fail(message):
    print("plot_sweep.py: error: " + message, file=sys.stderr)
    sys.exit(1)


def as_number(text):
    try:
        return float(text)
    except ValueError:
        return None


def read_sweep(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or FIGURE_COLUMNS not in rows[0]:
        fail(path + ": not a sweep CSV (no '" + FIGURE_COLUMNS + "' column)")
    header = rows[0]
    if header[:2] == ["point", "points"]:
        fail(path + ": a shard CSV: merge the shards first (saarcor sweep-merge)")
    keys = header[:header.index(FIGURE_COLUMNS)]
    if not keys:
        fail(path + ": no varied key before the figures")
    records = [dict(zip(header, r)) for r in rows[1:] if r]
    if not records:
        fail(path + ": no rows")
    return keys, records


def axis_values(records, key):
    """The key's values in sweep order, and whether they are all numbers."""
    seen = []
    for r in records:
        if r[key] not in seen:
            seen.append(r[key])
    numeric = all(as_number(v) is not None for v in seen)
    return seen, numeric


def plot_key(keys, records, key, out_path, title):
    values, numeric = axis_values(records, key)
    others = [k for k in keys if k != key]
    # One line per combination of the other keys' values, in sweep order.
    series = {}
    for r in records:
        label = ", ".join(k + "=" + r[k] for k in others)
        series.setdefault(label, []).append(r)
    if numeric:
        xs_of = lambda rs: [as_number(r[key]) for r in rs]  # noqa: E731
        nums = [as_number(v) for v in values]
        log2 = min(nums) > 0 and max(nums) / min(nums) >= 16
    else:
        position = {v: i for i, v in enumerate(values)}
        xs_of = lambda rs: [position[r[key]] for r in rs]  # noqa: E731
        log2 = False
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = ["-", "--", ":", "-."]
    markers = ["o", "s", "^", "v", "D", "P", "X", "*"]
    for ax, (ylabel, columns) in zip(axes.flat, PANELS):
        # One figure per panel: a colour per series. Several (the units): a colour per unit and a
        # line style and marker per series, each explained once in the legend.
        several = len(columns) > 1
        for s_index, (label, rs) in enumerate(series.items()):
            rs = sorted(rs, key=lambda r: xs_of([r])[0])
            xs = xs_of(rs)
            for c_index, (column, name) in enumerate(columns):
                colour = colours[(c_index if several else s_index) % len(colours)]
                ax.plot(xs, [float(r[column]) for r in rs], color=colour,
                        linestyle=styles[s_index % len(styles)] if several else "-",
                        marker=markers[s_index % len(markers)] if several else "o",
                        label=None if several else (label or None))
        if several:
            handles = [Line2D([], [], color=colours[i % len(colours)], label=name)
                       for i, (_, name) in enumerate(columns)]
            if len(series) > 1:
                handles += [Line2D([], [], color="grey", linestyle=styles[i % len(styles)],
                                   marker=markers[i % len(markers)], label=label)
                            for i, label in enumerate(series)]
            ax.legend(handles=handles, fontsize=7)
        ax.set_xlabel(key)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        if log2:
            ax.set_xscale("log", base=2)
        if numeric:
            ax.set_xticks([as_number(v) for v in values])
            ax.set_xticklabels(values)
        else:
            ax.set_xticks(range(len(values)))
            ax.set_xticklabels(values)
        if not several and ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out_path, dpi=100, metadata=PNG_METADATA)
    plt.close(fig)


def plot_precision(report, out_path, title):
    rows = report.get("rows")
    if not rows:
        fail("the precision report has no rows")
    ms = [r["mantissa"] for r in rows]
    same = [r["same_triangle_pct"] for r in rows]
    # Identical images have no finite PSNR (null): drawn at the top of the axis, marked "inf".
    finite = [r["psnr_db"] for r in rows if r["psnr_db"] is not None]
    top = (max(finite) if finite else 40.0) + 10.0
    psnr = [r["psnr_db"] if r["psnr_db"] is not None else top for r in rows]
    fig, left = plt.subplots(figsize=(8, 5))
    left.plot(ms, same, marker="s", color="tab:blue", label="same triangle (%)")
    left.axhline(99.0, color="tab:blue", linestyle=":", linewidth=1)
    left.set_xlabel("mantissa bits m (Float<7,m>)")
    left.set_ylabel("same triangle as the float reference (%)", color="tab:blue")
    left.axvline(16, color="grey", linestyle="--", linewidth=1)
    left.text(16, left.get_ylim()[1], " fp24", color="grey", va="top")
    right = left.twinx()
    right.plot(ms, psnr, marker="s", color="tab:red", label="PSNR (dB)")
    right.axhline(35.0, color="tab:red", linestyle=":", linewidth=1)
    right.set_ylabel("PSNR against the float reference (dB)", color="tab:red")
    for m, r in zip(ms, rows):
        if r["psnr_db"] is None:
            right.annotate("inf", (m, top), textcoords="offset points", xytext=(0, 6),
                           ha="center", color="tab:red", fontsize=8)
    left.set_xticks(ms)
    left.grid(True, alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out_path, dpi=100, metadata=PNG_METADATA)
    plt.close(fig)


def pareto_front(pairs):
    """For each (fps, cost): no other pair at least as fast and at most as dear, better in one."""
    return [not any(f >= fps and c <= cost and (f > fps or c < cost) for f, c in pairs)
            for fps, cost in pairs]


def pareto_costs(header, requested):
    """The cost columns of the Pareto figure: the requested ones, else the CSV's pareto cost."""
    marked = [h[len("pareto_"):] for h in header if h.startswith("pareto_")]
    costs = [c for c in requested.split(",") if c] if requested else (marked or ["luts"])
    for c in costs:
        if c not in COST_COLUMNS:
            fail("bad --cost '%s': expected cost columns among %s" % (
                c, ", ".join(COST_COLUMNS)))
        if c not in header:
            fail("the CSV has no '%s' column (a sweep CSV from before the cost columns?)" % c)
    return costs


def plot_pareto(keys, records, costs, out_path, title):
    # A colour per value of the first key, a marker per value of the second; the front joined by
    # a line, cheapest first, each of its points labelled with the keys' values.
    firsts, _ = axis_values(records, keys[0])
    seconds, _ = axis_values(records, keys[1]) if len(keys) > 1 else ([""], False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = ["o", "s", "^", "v", "D", "P", "X", "*"]
    fig, axes = plt.subplots(1, len(costs), figsize=(6.5 * len(costs), 5.5), squeeze=False)
    for ax, cost in zip(axes.flat, costs):
        pairs = [(float(r["fps"]), float(r[cost])) for r in records]
        column = "pareto_" + cost
        front = ([r[column] == "1" for r in records] if column in records[0]
                 else pareto_front(pairs))
        for r, (fps, c) in zip(records, pairs):
            second = r[keys[1]] if len(keys) > 1 else ""
            ax.scatter(c, fps, color=colours[firsts.index(r[keys[0]]) % len(colours)],
                       marker=markers[seconds.index(second) % len(markers)], s=36, zorder=3)
        on = sorted((p for p, f in zip(zip(pairs, records), front) if f),
                    key=lambda p: (p[0][1], p[0][0]))
        ax.plot([c for (_, c), _ in on], [f for (f, _), _ in on], color="black", linewidth=1,
                zorder=2, label="Pareto front (%d of %d)" % (len(on), len(records)))
        # Labels to the right and the left in turn: neighbours on the front (points that differ
        # in a key that changes little) do not write over each other.
        for i, ((fps, c), r) in enumerate(on):
            ax.annotate("/".join(r[k] for k in keys), (c, fps), textcoords="offset points",
                        xytext=(6 if i % 2 == 0 else -6, -3), ha="left" if i % 2 == 0 else "right",
                        fontsize=7)
        if cost in DEVICE:
            ax.axvline(DEVICE[cost], color="grey", linestyle="--", linewidth=1,
                       label="XC2V6000 (%d)" % DEVICE[cost])
        ax.set_xlabel(COST_COLUMNS[cost])
        ax.set_ylabel("frame rate (fps)")
        ax.grid(True, alpha=0.3)
        handles = [Line2D([], [], color=colours[i % len(colours)], marker="o", linestyle="",
                          label=keys[0] + "=" + v) for i, v in enumerate(firsts)]
        if len(keys) > 1:
            handles += [Line2D([], [], color="grey", marker=markers[i % len(markers)],
                               linestyle="", label=keys[1] + "=" + v)
                        for i, v in enumerate(seconds)]
        handles += ax.get_legend_handles_labels()[0]
        ax.legend(handles=handles, fontsize=7, title="labels: " + "/".join(keys),
                  title_fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out_path, dpi=100, metadata=PNG_METADATA)
    plt.close(fig)


def slug(text):
    return "".join(c if c.isalnum() or c in "._-" else "_" for c in text)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("input", help="sweep CSV, precision JSON, or a saarcor --out-dir folder")
    parser.add_argument("--out-dir", help="where the PNGs go (default: beside the input)")
    parser.add_argument("--pareto", action="store_true",
                        help="also draw frame rate against cost with the Pareto front "
                             "(sweep_pareto.png)")
    parser.add_argument("--cost", metavar="COST,...",
                        help="the Pareto figure's cost columns, one panel each (implies "
                             "--pareto; default: the CSV's pareto cost, else luts)")
    args = parser.parse_args()
    path = args.input
    if os.path.isdir(path):
        if os.path.exists(os.path.join(path, "sweep.csv")):
            path = os.path.join(path, "sweep.csv")
        elif os.path.exists(os.path.join(path, "report.json")):
            path = os.path.join(path, "report.json")
        else:
            fail(args.input + ": a folder without sweep.csv or report.json")
    if not os.path.exists(path):
        fail(path + ": no such file")
    out_dir = args.out_dir or os.path.dirname(os.path.abspath(path))
    os.makedirs(out_dir, exist_ok=True)
    written = []
    if path.endswith(".json"):
        with open(path) as f:
            report = json.load(f)
        if "rows" not in report or not report["rows"] or "mantissa" not in report["rows"][0]:
            fail(path + ": not a precision report (saarcor precision)")
        out = os.path.join(out_dir, "precision_curve.png")
        res = report.get("resolution", {})
        plot_precision(report, out, "%s  %sx%s: Float<7,m> against the float reference" % (
            report.get("scene", ""), res.get("width", "?"), res.get("height", "?")))
        written.append(out)
    else:
        keys, records = read_sweep(path)
        header = list(records[0].keys())
        pareto = (args.pareto or args.cost is not None or
                  any(h.startswith("pareto_") for h in header))
        costs = pareto_costs(header, args.cost) if pareto else []
        for key in keys:
            out = os.path.join(out_dir, "sweep_" + slug(key) + ".png")
            plot_key(keys, records, key, out,
                     "%s: %d points, varied %s" % (os.path.basename(path), len(records),
                                                   ", ".join(keys)))
            written.append(out)
        if pareto:
            out = os.path.join(out_dir, "sweep_pareto.png")
            plot_pareto(keys, records, costs, out,
                        "%s: %d points, frame rate against %s" % (
                            os.path.basename(path), len(records), " and ".join(costs)))
            written.append(out)
    for w in written:
        print(w)


if __name__ == "__main__":
    main()
