"""The plot: relMSE against render seconds, log-log, one panel per scene
(matplotlib; skipped with a warning when it is missing)."""

import os

from .common import log
from .stats import medians, num


def plot(rows, scenes, out_png):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log("bench: matplotlib missing (Debian: python3-matplotlib, run with /usr/bin/python3): no plot")
        return False
    med = medians(rows)
    names = [s for s in scenes if any(r["scene"] == s for r in rows)]
    if not names:
        return False
    all_configs = []
    for r in rows:
        if r["config"] not in all_configs:
            all_configs.append(r["config"])
    # Colour = backend + estimator, line style = majorant (solid grid, dotted
    # global), dashed = CPU reference, dash-dot with triangles = BSDF/phase
    # sampling only (else it would look like the same config with MIS): one
    # config looks the same in every panel.
    palette = {"vulkan/absorption": "tab:blue", "vulkan/collision": "tab:red", "vulkan": "tab:purple",
               "cpu/absorption": "tab:cyan", "cpu/collision": "tab:orange", "cpu": "tab:gray"}

    def color(c):
        return palette.get("/".join(c.split("/")[:2]), "black")

    def style(c):
        if c.endswith("/bsdf-only"):
            return "-."
        return "--" if c.startswith("cpu") else (":" if c.endswith("/global") else "-")
    ncol = min(3, len(names))
    nrow = (len(names) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 3.9 * nrow), squeeze=False)
    for ax, scene in zip(axes.flat, names):
        for c in all_configs:
            pts = sorted((spp, m) for (sc, cn, spp), m in med.items() if sc == scene and cn == c)
            if not pts:
                continue
            marker = "^" if c.endswith("/bsdf-only") else "s" if "global" in c else "o"
            xs = [m["seconds"] for _, m in pts]
            ys = [m["rel_mse"] for _, m in pts]
            ax.plot(xs, ys, style(c), marker=marker, ms=4, color=color(c), label=c)
            # Every repetition as a faint dot: shows the spread behind the median.
            reps = [r for r in rows if r["scene"] == scene and r["config"] == c]
            ax.scatter([num(r["seconds"]) for r in reps], [num(r["rel_mse"]) for r in reps], s=6,
                       color=color(c), alpha=0.3, linewidths=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(scene, fontsize=10)
        ax.set_xlabel("render seconds (median)")
        ax.set_ylabel("relMSE vs reference")
        ax.grid(True, which="both", alpha=0.25)
    for ax in list(axes.flat)[len(names):]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.flat:
        for h, l in zip(*ax.get_legend_handles_labels()):
            if l not in labels:
                handles.append(h)
                labels.append(l)
    fig.legend(handles, labels, loc="lower center", ncol=min(6, len(labels)), fontsize=8, frameon=False)
    fig.suptitle("pyrolume: error against render time (lower left is better; medians, dots = repetitions)",
                 fontsize=11)
    fig.tight_layout(rect=(0, 0.06 if nrow > 1 else 0.1, 1, 0.96))
    os.makedirs(os.path.dirname(out_png), exist_ok=True)
    fig.savefig(out_png + ".tmp.png", dpi=110)
    os.replace(out_png + ".tmp.png", out_png)
    plt.close(fig)
    return True
