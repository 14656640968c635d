#!/usr/bin/python3
"""view_skeleton.py - draw a sylva skeleton (.skel.json) as a PNG, front and side views.

Optional developer tool: it is not part of the build and no test runs it. It needs
python3-matplotlib (Debian: `apt-get install python3-matplotlib`), and is meant for
/usr/bin/python3.

Usage:
    scripts/view_skeleton.py PLANT.skel.json [-o PLANT.png] [--title TEXT] [--dpi 110]

Reads the skeleton format of /work/shared/spec/skeleton.md (chains of joints
[x, y, z, radius, material], metres, Y up) and writes two orthographic views side by
side: front (X right, Y up, looking along -Z) and side (Z right, Y up, looking along +X).
Each segment is drawn as a line whose width is proportional to its mean radius (true to
the plot's metre scale, with a hairline minimum so thin twigs stay visible) and whose
colour is its material index: 0 bark brown, 1 leaf green, 2 light green, 3 flower/fruit
ochre, further indices cycle through a qualitative palette.
"""
import argparse
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

MATERIAL_COLOURS = ["#6b4423", "#2e8b3a", "#8fcf5a", "#d8a020",
                    "#1f77b4", "#9467bd", "#e377c2", "#17becf"]
MIN_LINE_PT = 0.25  # hairline, points


def load(path):
    with open(path) as f:
        skel = json.load(f)
    if skel.get("format") != "sylva-skeleton" or skel.get("version") != 1:
        sys.exit(f"{path}: not a sylva-skeleton version 1 file")
    return skel


def segments(skel):
    """Yields (p0, p1, mean_radius, material) for every segment of every chain."""
    for chain in skel["chains"]:
        joints = chain["joints"]
        for a, b in zip(joints, joints[1:]):
            yield a[:3], b[:3], 0.5 * (a[3] + b[3]), int(b[4])


def setup_view(ax, hx, title, lo, hi):
    """Limits, labels and a square aspect for one view (hx: 0 = X, 2 = Z; vertical Y)."""
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("X (m)" if hx == 0 else "Z (m)", fontsize=8)
    ax.set_ylabel("Y (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, linewidth=0.3, alpha=0.4)


def draw_view(ax, segs, hx, lo, hi):
    """Draws the segments into a view laid out by setup_view (call after layout)."""
    lines, widths, colours = [], [], []
    # Metre -> point conversion: the axis is square in data units after layout.
    fig = ax.figure
    bbox = ax.get_window_extent()  # pixels
    span = max(hi[0] - lo[0], hi[1] - lo[1])
    pt_per_m = (min(bbox.width, bbox.height) * 72.0 / fig.dpi) / span
    # Far segments first so near ones paint over them (depth = the other horizontal axis).
    depth_axis = 2 if hx == 0 else 0
    sign = 1.0 if hx == 0 else -1.0
    order = sorted(segs, key=lambda s: sign * 0.5 * (s[0][depth_axis] + s[1][depth_axis]))
    for p0, p1, r, m in order:
        lines.append([(p0[hx], p0[1]), (p1[hx], p1[1])])
        widths.append(max(MIN_LINE_PT, 2.0 * r * pt_per_m))
        colours.append(MATERIAL_COLOURS[m % len(MATERIAL_COLOURS)])
    ax.add_collection(LineCollection(lines, linewidths=widths, colors=colours,
                                     capstyle="round"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("skeleton")
    ap.add_argument("-o", "--output", help="PNG path (default: skeleton path + .png)")
    ap.add_argument("--title", help="figure title (default: the grammar named in the file)")
    ap.add_argument("--dpi", type=int, default=110)
    args = ap.parse_args()

    skel = load(args.skeleton)
    segs = list(segments(skel))
    if not segs:
        sys.exit(f"{args.skeleton}: no segments")
    pts = [p for s in segs for p in (s[0], s[1])]
    rmax = max(s[2] for s in segs)
    lo = [min(p[k] for p in pts) - rmax for k in range(3)]
    hi = [max(p[k] for p in pts) + rmax for k in range(3)]
    # One square window shared by both views so they compare at the same scale.
    half = 0.5 * max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) * 1.04
    cy = 0.5 * (lo[1] + hi[1])
    cx, cz = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[2] + hi[2])

    fig, axes = plt.subplots(1, 2, figsize=(12, 6.4), dpi=args.dpi)
    n_chains = len(skel["chains"])
    front = ((cx - half, cy - half), (cx + half, cy + half))
    side = ((cz - half, cy - half), (cz + half, cy + half))
    setup_view(axes[0], 0, "front (X-Y)", *front)
    setup_view(axes[1], 2, "side (Z-Y)", *side)
    title = args.title or skel.get("source", {}).get("grammar", args.skeleton)
    height = max(p[1] for p in pts) - min(p[1] for p in pts)
    fig.suptitle(f"{title}: {len(segs)} segments, {n_chains} chains, "
                 f"height {height:.2f} m", fontsize=10)
    fig.tight_layout()
    fig.canvas.draw()  # fixes the axes' final size, which the line widths depend on
    draw_view(axes[0], segs, 0, *front)
    draw_view(axes[1], segs, 2, *side)
    out = args.output or (args.skeleton.rsplit(".json", 1)[0] + ".png")
    fig.savefig(out)
    print(out)


if __name__ == "__main__":
    main()
