"""tools/bench --sparse: sparse grids against dense textures (issue 26).

1. Speed: the shipped fire and the Houdini plume (read in place from
   --data-dir), each rendered with its grids as dense R16F textures
   ("texture_format": "r16f") and as sparse NanoVDB trees ("sparse"), on both
   backends, --reps times at --resolution and 16 spp; the medians of the
   renders' own samples per second (--stats) and sparse / dense.
2. Memory: a generated 1024³-box explosion shell (gen_fire_vdb --thin-shell
   --resolution 1024, written as .nvdb into the work folder once), in a scene
   that leaves texture_format out ("auto" keeps it sparse), rendered on both
   backends; peak RSS (--stats peak_rss_mb) against the target, twice the
   file's size plus 300 MB.

Medians go into the part of benchmarks.md between <!-- sparse:begin --> and
<!-- sparse:end -->."""

import copy
import json
import os
import statistics
import subprocess
import time

from .common import REPO, log, replace_block
from .runner import machine_info, render
from .scenes import asset_scene, real_vdb_scene

BEGIN, END = "<!-- sparse:begin -->", "<!-- sparse:end -->"
SPP = 16


def with_format(scene, fmt, path):
    data = copy.deepcopy(scene.data)
    for m in data.get("media", []):
        if m.get("type") == "vdb":
            m["texture_format"] = fmt
            if not os.path.isabs(m["file"]):
                m["file"] = os.path.normpath(os.path.join(scene.base_dir, m["file"]))
    with open(path, "w") as fh:
        json.dump(data, fh, indent=1)
    return path


def speed_rows(args, work):
    scenes = [asset_scene("fire")]
    plume = os.path.join(args.data_dir, "openvdb_smoke1_houdini.vdb")
    if os.path.exists(plume):
        scenes.append(real_vdb_scene(args.pyrolume, plume, work, args.width / args.height))
    else:
        log(f"bench: --sparse: {plume} absent, the plume is skipped")
    rows = []
    for scene in scenes:
        for backend in ("vulkan", "cpu"):
            sps = {}
            for fmt in ("r16f", "sparse"):
                path = with_format(scene, fmt, os.path.join(work, f"{scene.name}_{fmt}.json"))
                runs = []
                for rep in range(args.reps):
                    out = os.path.join(work, f"{scene.name}_{fmt}_{backend}.exr")
                    stats = render(args, path, out, out + ".stats.json", backend, SPP, 1 + rep)
                    runs.append(stats["samples_per_second"] / 1e6)
                    log(f"bench: --sparse: {scene.name} {fmt} {backend} {rep + 1}/{args.reps}: "
                        f"{runs[-1]:.3f} M samples/s")
                sps[fmt] = runs
            d, s = statistics.median(sps["r16f"]), statistics.median(sps["sparse"])
            rows.append((scene.name, backend, d, sps["r16f"], s, sps["sparse"], s / d))
    return rows


def shell_rows(args, work):
    nvdb = os.path.join(work, "shell1024.nvdb")
    if not os.path.exists(nvdb):
        if not os.path.exists(args.generator):
            log(f"bench: --sparse: generator {args.generator} not built, the 1024³ shell is skipped")
            return []
        log("bench: --sparse: generating the 1024³ explosion shell (once)")
        t0 = time.monotonic()
        subprocess.run([args.generator, nvdb + ".tmp.nvdb", "--thin-shell", "--resolution", "1024"], check=True,
                       stdout=subprocess.DEVNULL)
        os.replace(nvdb + ".tmp.nvdb", nvdb)
        log(f"bench: --sparse: generated in {time.monotonic() - t0:.0f} s")
    scene = real_vdb_scene(args.pyrolume, nvdb, work, args.width / args.height)
    path = os.path.join(work, "shell1024.json")
    with open(path, "w") as fh:
        json.dump(scene.data, fh, indent=1)
    size_mb = os.path.getsize(nvdb) / 1e6
    target = 2.0 * size_mb + 300.0
    rows = []
    for backend in ("vulkan", "cpu"):
        out = os.path.join(work, f"shell1024_{backend}.exr")
        stats = render(args, path, out, out + ".stats.json", backend, 4, 1, size=(160, 90))
        rows.append((backend, size_mb, stats["peak_rss_mb"] * 1.048576, target, stats.get("load_seconds", 0.0),
                     stats["seconds"]))
        log(f"bench: --sparse: shell {backend}: peak RSS {rows[-1][2]:.0f} MB (target {target:.0f} MB)")
    return rows


def run(args, argv):
    work = os.path.join(os.path.abspath(args.work_dir), "sparse")
    os.makedirs(work, exist_ok=True)
    speed = speed_rows(args, work)
    shell = shell_rows(args, work)
    mi = machine_info(args.pyrolume)
    lines = [BEGIN, "",
             f"`tools/bench {' '.join(argv)}`; {mi['cpu']}, {mi['nproc']} cores, {mi['devices'] or 'device unknown'}; "
             f"load {' / '.join(f'{x:.2f}' for x in os.getloadavg())} at the end.", "",
             f"Speed at {args.width}×{args.height}, {SPP} spp: medians of {args.reps} renders (every run in "
             "brackets), M samples/s from each render's --stats.", "",
             "| scene | backend | dense R16F | sparse | sparse / dense |", "|---|---|---|---|---|"]
    for name, backend, d, ds, s, ss, ratio in speed:
        lines.append(f"| {name} | {backend} | {d:.3f} [{', '.join(f'{x:.3f}' for x in ds)}] | "
                     f"{s:.3f} [{', '.join(f'{x:.3f}' for x in ss)}] | {ratio:.2f}× |")
    if shell:
        lines += ["", "The generated 1024³-box explosion shell (`gen_fire_vdb --thin-shell --resolution 1024`, .nvdb), "
                      "texture_format left out, 160×90, 4 spp: peak RSS (--stats peak_rss_mb, in MB of 10⁶ bytes) "
                      "against twice the file's size plus 300 MB.", "",
                  "| backend | file, MB | peak RSS, MB | target, MB | load, s | render, s |", "|---|---|---|---|---|---|"]
        for backend, size_mb, rss, target, load, secs in shell:
            lines.append(f"| {backend} | {size_mb:.0f} | {rss:.0f} | {target:.0f} | {load:.1f} | {secs:.1f} |")
    lines += ["", END]
    block = "\n".join(lines)
    print(block)
    md = os.path.join(os.path.abspath(args.out_dir), "benchmarks.md")
    replace_block(md, BEGIN, END, block, "Sparse grids")
    log(f"bench: --sparse: {os.path.relpath(md)}")
    return 0
