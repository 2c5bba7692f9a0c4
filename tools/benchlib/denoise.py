"""tools/bench --denoise: the denoiser's time against the render it cleans
(issue 25: under 20 % of a 16-spp render's time at 1920×1080).

For each scene: render it at --resolution (default 1920x1080 in this mode) and
--denoise-spp (16) with --variance, --render-reps times, with and without
--aovs (the render's own "seconds" from --stats). `render --denoise` renders
with the AOVs, as the guided filter reads them and their guide, so the render
with AOVs is what the denoiser's time is set against, and the one without shows
what the AOVs and the guide cost; the guide's own dispatch ("guide_seconds" in
--stats, part of the render with AOVs) is set against the render without (issue
46: at most 20 %). Then time `pyrolume denoise` on the EXR with AOVs --reps
times (the process's wall time: EXR read and write and the Vulkan device
included; and the filter alone, as the command prints it). Medians go
into the part of benchmarks.md between <!-- denoise:begin --> and
<!-- denoise:end --> (at 1920x1080; other sizes have their own markers,
<!-- denoise 320x180:begin --> and so on).

--scenes takes shipped scene names, or paths to a scene file or a bare .vdb
or .nvdb (rendered as `pyrolume render FILE` renders it)."""

import os
import re
import statistics
import subprocess
import time

from .common import REPO, log, replace_block
from .runner import machine_info, render

def markers(width, height):
    size = "" if (width, height) == (1920, 1080) else f" {width}x{height}"
    return f"<!-- denoise{size}:begin -->", f"<!-- denoise{size}:end -->"


def scene_path(name):
    """A shipped scene's name, or a path to a scene file or volume."""
    if "/" in name or name.endswith((".json", ".vdb", ".nvdb")):
        return os.path.abspath(name), os.path.splitext(os.path.basename(name))[0]
    return os.path.join(REPO, "assets", "scenes", name + ".json"), name
FILTER_RE = re.compile(r"([0-9.]+) s denoising")


def time_denoise(args, exr, out):
    cmd = [args.pyrolume, "denoise", exr, "-o", out] + (["--device", str(args.device)] if args.device is not None else [])
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        raise RuntimeError(f"denoise exit {p.returncode}: {p.stderr.strip()}")
    m = FILTER_RE.search(p.stdout)
    return wall, float(m.group(1)) if m else float("nan")


def shown_argv(argv):
    """argv with volume and scene paths cut to their file names: where the
    files lie on the measuring machine is not the reader's business."""
    def short(a):
        return ",".join(os.path.basename(x) if "/" in x else x for x in a.split(","))
    return [short(a) for a in argv]


def run(args, argv):
    names = [s.strip() for s in (args.scenes or "fire_ground,terrain_explosion").split(",")]
    work = os.path.join(os.path.abspath(args.work_dir), "denoise")
    os.makedirs(work, exist_ok=True)
    rows = []
    for given in names:
        scene, name = scene_path(given)
        if not os.path.exists(scene):
            log(f"bench: --denoise: no scene {scene}")
            return 2
        exr = os.path.join(work, f"{name}_{args.width}x{args.height}_{args.denoise_spp}spp.exr")
        plain = os.path.join(work, f"{name}_{args.width}x{args.height}_{args.denoise_spp}spp_plain.exr")
        render_s, plain_s, guide_s = [], [], []
        for rep in range(args.render_reps):
            stats = render(args, scene, plain, plain + ".stats.json", "vulkan", args.denoise_spp, 1 + rep,
                           variance=True)
            plain_s.append(stats["seconds"])
            stats = render(args, scene, exr, exr + ".stats.json", "vulkan", args.denoise_spp, 1 + rep, variance=True,
                           aovs=True)
            render_s.append(stats["seconds"])
            guide_s.append(stats.get("guide_seconds", 0.0))
            log(f"bench: {name}: render {rep + 1}/{args.render_reps}: {plain_s[-1]:.1f} s, "
                f"{stats['seconds']:.1f} s with --aovs")
        walls, filters = [], []
        for rep in range(args.reps):
            wall, filt = time_denoise(args, exr, os.path.join(work, f"{name}_denoised.exr"))
            walls.append(wall)
            filters.append(filt)
            log(f"bench: {name}: denoise {rep + 1}/{args.reps}: {wall:.2f} s ({filt:.2f} s filtering)")
        r, w, f = statistics.median(render_s), statistics.median(walls), statistics.median(filters)
        p, g = statistics.median(plain_s), statistics.median(guide_s)
        rows.append((name, p, plain_s, r, render_s, w, walls, f, 100.0 * w / r, 100.0 * (r / p - 1.0), g, guide_s))
    mi = machine_info(args.pyrolume)
    BEGIN, END = markers(args.width, args.height)
    lines = [BEGIN, "",
             f"`tools/bench {' '.join(shown_argv(argv))}`, {args.width}×{args.height}, {args.denoise_spp} spp; "
             f"{mi['cpu']}, {mi['nproc']} cores, {mi['devices'] or 'device unknown'}; "
             f"load {' / '.join(f'{x:.2f}' for x in os.getloadavg())} at the end; medians (every run in brackets).", "",
             "| scene | render, s | render with --aovs, s | `pyrolume denoise`, s (wall) | filter alone, s "
             "| denoise / render with --aovs | what the AOVs and guide add to the render "
             "| the guide, s | the guide / render |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, p, ps, r, rs, w, ws, f, pct, extra, g, gs in rows:
        lines.append(f"| {name} | {p:.3g} [{', '.join(f'{x:.3g}' for x in ps)}] | "
                     f"{r:.3g} [{', '.join(f'{x:.3g}' for x in rs)}] | "
                     f"{w:.2f} [{', '.join(f'{x:.2f}' for x in ws)}] | {f:.2f} | {pct:.1f} % | {extra:+.0f} % | "
                     f"{g:.3g} [{', '.join(f'{x:.3g}' for x in gs)}] | {100.0 * g / p:.1f} % |")
    lines += ["", END]
    block = "\n".join(lines)
    print(block)
    md = os.path.join(os.path.abspath(args.out_dir), "benchmarks.md")
    replace_block(md, BEGIN, END, block, f"Denoiser at {args.width}×{args.height}")
    log(f"bench: --denoise: {os.path.relpath(md)}")
    return 0
