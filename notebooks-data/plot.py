#!/usr/bin/python3
"""Figures from the study CSVs in this folder (see README.md for the commands that make them).

Run: /usr/bin/python3 notebooks-data/plot.py   (needs Debian's python3-matplotlib)
Writes next to this script: sj-histogram-geode3d.png, shape-height.png, shape-distorted.png,
interleave-geode3d.png, interleave-geode4tri.png, interleave-geode4tri-domes.png, transition-corners.png. Reads only CSVs
written by `geode study`.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
PAPER_SJ_RANGE = (0.26, 0.53)  # the paper's Section 3.2 / Table 1, 24 x 14 x 24, for reference


def rows(name):
    path = os.path.join(HERE, name)
    if not os.path.exists(path):
        sys.exit(f"plot.py: {path} is missing; see README.md for the command that writes it")
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def save(fig, name):
    out = os.path.join(HERE, name)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, out)  # never leave a half-written figure
    plt.close(fig)
    print("wrote", out)


def histogram():
    data = rows("sj-geode3d.csv")
    fig, ax = plt.subplots(figsize=(7, 4.2))
    bins = [0.38 + 0.005 * i for i in range(25)]
    for mode, colour in (("fixed", "tab:blue"), ("slide", "tab:orange")):
        v = [float(r["scaled_jacobian"]) for r in data if r["mode"] == mode]
        label = f"{mode} (min {min(v):.3f}, max {max(v):.3f}, {len(v)} hexes)"
        ax.hist(v, bins=bins, alpha=0.6, color=colour, label=label, edgecolor="black", linewidth=0.4)
    ax.axvline(PAPER_SJ_RANGE[0], color="grey", ls="--", lw=1)
    ax.text(PAPER_SJ_RANGE[0], ax.get_ylim()[1] * 0.9, " paper min 0.26\n (max 0.53)", fontsize=8, color="grey")
    ax.set_xlim(0.25, max(0.55, max(bins)))
    ax.set_xlabel("hex scaled Jacobian (Verdict: min over 8 corners and centre)")
    ax.set_ylabel("hexes")
    ax.set_title("Geode 24x14x24, smooth_template: tet/hex-side nodes fixed vs sliding\n"
                 "(geode study shape --sj-csv sj-geode3d.csv)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, "sj-histogram-geode3d.png")


def height():
    data = [r for r in rows("shape-height.csv") if r["cell"] == "box"]
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for mode, marker in (("fixed", "o"), ("slide", "s")):
        d = [r for r in data if r["mode"] == mode]
        ax.plot([float(r["parameter"]) for r in d], [float(r["final_min_sj"]) for r in d], marker=marker,
                label=f"{mode}: tet/hex-side nodes {'fixed' if mode == 'fixed' else 'slide in their planes'}")
    ax.plot([14], [PAPER_SJ_RANGE[0]], "k*", ms=10, label="paper (CUBIT smoothing), 24x14x24: 0.26")
    ax.set_xlabel("box height h (base 24 x 24)")
    ax.set_ylabel("min scaled Jacobian after smoothing")
    ax.set_ylim(0, 0.55)
    ax.grid(alpha=0.3)
    ax.set_title("Geode in a 24 x h x 24 box: build_geode3d + smooth_template\n"
                 "(geode study shape -o shape-height.csv)", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    save(fig, "shape-height.png")


def distorted():
    data = rows("shape-distorted.csv")
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    for ax, cell, xlabel in ((axes[0], "shear", "shear angle (degrees): top face moved by h tan(angle) along x"),
                             (axes[1], "taper", "taper ratio: top face / bottom face (side length)")):
        for mode, marker in (("fixed", "o"), ("slide", "s")):
            d = [r for r in data if r["cell"] == cell and r["mode"] == mode]
            ax.plot([float(r["parameter"]) for r in d], [float(r["final_min_sj"]) for r in d], marker=marker,
                    label=mode)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.set_ylabel("min scaled Jacobian")
        ax.set_ylim(0, 0.55)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Geode mapped trilinearly into a sheared / tapered 24x14x24 cell, then smoothed\n"
                 "(side nodes slide on the face planes; tet/hex side fixed or sliding; "
                 "geode study shape --distorted-csv)", fontsize=9)
    fig.tight_layout()
    save(fig, "shape-distorted.png")


def interleave(name):
    data = rows(f"interleave-{name}.csv")
    summary = {r["class"]: r for r in rows(f"interleave-{name}-summary.csv")}
    highs = sorted({float(r["high_roof"]) for r in data})
    radii = sorted({float(r["dome_radius"]) for r in data})
    labels = list(summary)  # summary order: valid classes by count, then errors
    cmap = plt.get_cmap("tab20")
    colour = {c: cmap(i % 20) for i, c in enumerate(l for l in labels if l.startswith("V"))}
    greys = ["0.55", "0.75", "0.35", "0.9", "0.2"]
    for i, c in enumerate(l for l in labels if l.startswith("E")):
        colour[c] = greys[i % len(greys)]
    n_legend_rows = (len(labels) + 2) // 2
    legend_in = 0.16 * n_legend_rows + 0.2
    height_in = 3.6 + legend_in
    fig, axes = plt.subplots(1, len(highs), figsize=(3.1 * len(highs), height_in), sharey=True, squeeze=False)
    axes = axes[0]
    default = (0.85, 0.6, 0.9, 0.6)
    for ax, h in zip(axes, highs):
        for r in data:
            if float(r["high_roof"]) != h:
                continue
            k = radii.index(float(r["dome_radius"]))
            x = float(r["dome_depth"]) + 0.012 * (k - (len(radii) - 1) / 2)  # radius as a small x offset
            y = float(r["low_roof"])
            valid = r["outcome"] == "valid"
            usable = valid and summary[r["class"]]["usable"] == "1"
            marker = ("*" if usable else "o" if r["conditions_ok"] == "1" else "^") if valid else "x"
            ax.scatter([x], [y], color=colour[r["class"]], marker=marker, s=90 if usable else 28,
                       edgecolors="black" if usable else None, linewidths=0.6)
            p = tuple(float(r[c]) for c in ("high_roof", "low_roof", "dome_depth", "dome_radius"))
            if name == "geode3d" and p == default:
                ax.scatter([x], [y], facecolors="none", edgecolors="red", s=140, lw=1.5)
        ax.set_title(f"high roof {h:g}", fontsize=9)
        ax.set_xlabel("dome depth (+ radius offset)", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("low roof")
    handles = []
    for c in labels:
        s = summary[c]
        if s["outcome"] == "valid":
            text = f"{c}: {s['hexes']} hexes, {s['count']} runs, conditions ok {s['conditions_ok']}, "
            if s["usable"] == "1":
                text += f"USABLE, min SJ {float(s['min_sj_fixed']):.2f} fixed / {float(s['min_sj_slide']):.2f} sliding"
            else:
                text += "not usable: " + (s["obstructions"].replace(";", ", ") or "smoothing fails")
        else:
            key = s["key"]
            text = f"{c}: {s['count']} runs, " + (key[:60] + "..." if len(key) > 60 else key)
        mark = ("*" if s["usable"] == "1" else "o") if c.startswith("V") else "x"
        handles.append(plt.Line2D([], [], color=colour[c], marker=mark, ls="", label=text))
    if name == "geode3d":
        handles.append(plt.Line2D([], [], color="red", marker="o", mfc="none", ls="", label="paper's push (0.85, 0.6, 0.9, 0.6)"))
    fig.legend(handles=handles, loc="lower center", ncol=2, fontsize=6.5, frameon=False)
    fig.suptitle(f"{name}: outcome class of each push (*: usable template: no obstruction, untangled; "
                 f"o: valid complex, paper's conditions hold; ^: valid, they fail; x: TopologyError)\nwithin a panel, the 4 dome-radius values are small x offsets, left to right "
                 f"{', '.join(f'{r:g}' for r in radii)}  (geode study interleave --template {name})", fontsize=9)
    fig.subplots_adjust(left=0.7 / (3.1 * len(highs)), right=0.99, wspace=0.08, top=1 - 0.75 / height_in,
                        bottom=(legend_in + 0.55) / height_in)
    save(fig, f"interleave-{name}.png")


def domes():
    """The four-triangle cell over the wider dome family (specs/geode4tri-domes.json's sweep)."""
    name = "geode4tri-domes"
    data = rows(f"interleave-{name}.csv")
    summary = {r["class"]: r for r in rows(f"interleave-{name}-summary.csv")}
    usable = [c for c, s in summary.items() if s["usable"] == "1"]
    dome_p = sorted({float(r["push.dome_exponent"]) for r in data})
    centre_p = sorted({float(r["push.centre_exponent"]) for r in data})
    depths = sorted({float(r["push.centre_depth"]) for r in data})
    fig, axes = plt.subplots(1, len(depths), figsize=(4.2 * len(depths) + 3.6, 4.4), squeeze=False)
    axes = axes[0]
    for ax, depth in zip(axes, depths):
        grid = [[0] * len(dome_p) for _ in centre_p]
        for i, cp in enumerate(centre_p):
            for k, dp in enumerate(dome_p):
                cell = [r for r in data if float(r["push.centre_depth"]) == depth
                        and float(r["push.centre_exponent"]) == cp and float(r["push.dome_exponent"]) == dp]
                good = sum(r["class"] in usable for r in cell)
                valid = sum(r["outcome"] == "valid" for r in cell)
                grid[i][k] = good / max(1, len(cell))
                ax.text(k, i, f"{good}\n{valid}/{len(cell)}", ha="center", va="center", fontsize=8)
        ax.imshow(grid, origin="lower", cmap="Greens", vmin=0, vmax=1, aspect="auto")
        ax.set_xticks(range(len(dome_p)), [f"{p:g}" for p in dome_p])
        ax.set_yticks(range(len(centre_p)), [f"{p:g}" for p in centre_p])
        ax.set_xlabel("corner dome exponent p")
        ax.set_title(f"centre dome depth {depth:g}", fontsize=9)
    axes[0].set_ylabel("centre dome exponent")
    lines = ["obstruction-free classes (all usable):"]
    for c in usable:
        s = summary[c]
        lines.append(f"{c}: {s['hexes']} hexes, {s['count']} runs,\n    min SJ {float(s['min_sj_fixed']):.2f} fixed"
                     f" / {float(s['min_sj_slide']):.2f} sliding")
    valid = [s for s in summary.values() if s["outcome"] == "valid"]
    lines.append(f"\n{len(valid)} valid classes, {len(summary) - len(valid)} diagnoses,\n{len(data)} pushes")
    fig.text(1 - 3.5 / (4.2 * len(depths) + 3.6), 0.5, "\n".join(lines), fontsize=8, va="center")
    fig.suptitle(f"{name}: pushes giving an obstruction-free (usable) template per cell: count, then valid/all "
                 "(over dome offset,\ncentre offset, corner depth, radius blend; geode study interleave --spec "
                 "specs/geode4tri-domes.json)", fontsize=9)
    fig.subplots_adjust(left=0.07, right=1 - 3.7 / (4.2 * len(depths) + 3.6), wspace=0.25, top=0.84, bottom=0.12)
    save(fig, f"interleave-{name}.png")


def corners():
    """Geode hexes at hex-part edges and corners, per dihedral angle and kind (geode study corners)."""
    data = rows("transition-corners.csv")
    kinds = ["flat", "convex edge", "concave edge", "convex corner", "concave corner", "saddle corner"]
    colours = dict(zip(kinds, ["0.6", "tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple"]))
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    for kind in kinds:
        sel = [r for r in data if r["kind"] == kind]
        if not sel:
            continue
        x = [float(r["angle"]) for r in sel]
        ax.scatter(x, [float(r["min_sj_none"]) for r in sel], facecolors="none", edgecolors=colours[kind], s=28)
        ax.scatter(x, [float(r["min_sj_default"]) for r in sel], color=colours[kind], s=18, label=kind)
        ax.scatter(x, [float(r["min_sj_global"]) for r in sel], color=colours[kind], marker="+", s=30)
    ax.axhline(0.25, color="k", lw=0.6, ls="--")
    ax.text(62, 0.255, "target 0.25", fontsize=7)
    ax.set_xlabel("dihedral angle inside the hex part (degrees; 180 flat)")
    ax.set_ylabel("min scaled Jacobian of the geode hexes")
    ax.set_title("Transition at hex-part edges and corners (open: --smooth none, filled: defaults,\n"
                 "+: --smooth global; nugget, lshape, potting, cylinder, demo_wedge at n = 3; geode study corners)",
                 fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    ax.set_ylim(0, 0.5)
    save(fig, "transition-corners.png")


if __name__ == "__main__":
    histogram()
    height()
    distorted()
    interleave("geode3d")
    interleave("geode4tri")
    domes()
    corners()
