"""tools/bench --cycles: pyrolume against Blender Cycles at equal error
(issue 23). Optional: runs only where `blender` (Debian's Blender 3.4) is
installed and the Blender 2.79 fire is in --data-dir.

The scene, as the issue gives it: the Blender 2.79 fire at 160×240, density
×5, albedo 0.5, T = 1500·heat, framed from −Y with +Z up (the bench's
frame_camera), black background, 8 bounces.
  Cycles  (tools/cycles/render_vdb_cycles.py): CPU, --threads (default 2),
          Principled Volume with Density 5, Color 0.5 (absorption = scattering
          = 0.5·density), Temperature 1500, Blackbody Intensity 1, volume
          bounces 8; adaptive sampling, denoising and clamping off, a 1-pixel
          box filter, linear interpolation, automatic step size.
  pyrolume: the shortest scene file for it, its defaults otherwise:
          density_scale 5, sigma_a = sigma_s = 0.5, temperature scale 1500.
Each renderer is measured against its own reference (their emission models
differ, docs/benchmarks.md "Against Cycles"): Cycles at 64 spp, and pyrolume
at rising spp until its relMSE is below Cycles'. The time pyrolume needs for
Cycles' 64-spp relMSE is interpolated in log-log between its two bracketing
points; both times are the renderers' own render times (Cycles'
RENDER_TIME_S, pyrolume's --stats seconds), medians of --reps seeds. Three
ways to score, all printed:
  as the issue asks: both references 1024 spp. A reference's own noise is in
          the relMSE measured against it, about spp/1024 of the test image's
          own: 6 % for Cycles at 64 spp, but a quarter for pyrolume at the
          ~200 spp where it matches, which this score counts against it;
  reference noise removed: each relMSE divided by 1 + spp/ref_spp (error
          falling as 1/spp), Cycles' against its 1024-spp reference, pyrolume's
          against a 4096-spp one. For Cycles, whose stratified samples make the
          error fall faster, this removes at most what its reference adds,
          so it never favours pyrolume;
  pyrolume's reference 4096 spp, Cycles' 1024, as measured (the score this
          bench printed before): pyrolume's reference adds 5 % at 200 spp,
          Cycles' 6 %.
"""

import json
import math
import os
import shutil
import statistics
import subprocess

from .common import REPO, log, write_json_if_changed
from .runner import compare, render
from .scenes import frame_camera, vdb_info

W, H = 160, 240
# Cycles' reference has 16× its measured spp, as the issue asks. pyrolume's has
# 4096 spp: it has to reach Cycles' error at several hundred spp, where a
# 1024-spp reference's own noise would be half of the error measured.
CYCLES_SPP, REF_SPP, OUR_REF_SPP = 64, 1024, 4096


def cycles_render(args, vdb, camera, spp, seed, out_exr, out_png=None):
    script = os.path.join(REPO, "tools", "cycles", "render_vdb_cycles.py")
    outs = [out_exr] + ([out_png] if out_png else [])
    cmd = [args.blender, "-b", "--factory-startup", "-P", script, "--", vdb, "--out", *outs,
           "--width", str(W), "--height", str(H), "--spp", str(spp), "--seed", str(seed),
           "--threads", str(args.cycles_threads), "--density-attr", "density", "--temp-attr", "heat",
           "--density", "5", "--color", "0.5", "--temperature", "1500", "--blackbody", "1",
           "--volume-bounces", "8", "--cam-pos", *map(str, camera["position"]),
           "--look-at", *map(str, camera["look_at"]), "--up", "0", "0", "1", "--fov", str(camera["fov_deg"])]
    p = subprocess.run(cmd, capture_output=True, text=True)
    lines = [l for l in p.stdout.splitlines() if l.startswith("RENDER_TIME_S ")]
    if p.returncode != 0 or not lines:
        raise RuntimeError(f"Cycles failed (exit {p.returncode}):\n{(p.stdout + p.stderr)[-2000:]}")
    return float(lines[-1].split()[1])


def log_interp(x0, y0, x1, y1, y):
    """x where the log-log line through (x0, y0), (x1, y1) reaches y."""
    if y0 == y1:
        return x0
    f = (math.log(y) - math.log(y0)) / (math.log(y1) - math.log(y0))
    return math.exp(math.log(x0) + f * (math.log(x1) - math.log(x0)))


def run(args):
    vdb = os.path.join(args.data_dir, "blender279_fire_frame075.vdb")
    args.blender = shutil.which("blender")
    if not args.blender:
        log("bench --cycles: skipped: no `blender` on PATH (apt-get install blender)")
        return 0
    if not os.path.exists(vdb):
        log(f"bench --cycles: skipped: {vdb} absent")
        return 0
    work = os.path.join(os.path.abspath(args.work_dir), "cycles")
    os.makedirs(work, exist_ok=True)
    _, grids = vdb_info(args.pyrolume, vdb)
    lo = [min(grids[g][0][i] for g in ("density", "heat")) for i in range(3)]
    hi = [max(grids[g][1][i] for g in ("density", "heat")) for i in range(3)]
    camera = frame_camera(lo, hi, 2, W / H)
    scene = {"camera": camera, "film": {"width": W, "height": H},
             "media": [{"type": "vdb", "file": os.path.abspath(vdb), "density_scale": 5,
                        "sigma_a": [0.5, 0.5, 0.5], "sigma_s": [0.5, 0.5, 0.5],
                        "temperature": {"scale": 1500, "offset": 0}}]}
    scene_path = os.path.join(work, "blender_fire.json")
    write_json_if_changed(scene_path, scene)
    seeds = list(range(1, args.reps + 1))

    log(f"bench --cycles: references at {W}x{H}: Cycles {REF_SPP} spp, pyrolume {OUR_REF_SPP} spp ...")
    cycles_ref = os.path.join(work, "cycles_ref.exr")
    t_cycles_ref = cycles_render(args, vdb, camera, REF_SPP, 99, cycles_ref)
    ours_ref = os.path.join(work, "pyrolume_ref.exr")
    render(args, scene_path, ours_ref, ours_ref + ".json", "vulkan", OUR_REF_SPP, 99, size=(W, H))
    ours_ref_issue = os.path.join(work, f"pyrolume_ref_{REF_SPP}.exr")
    render(args, scene_path, ours_ref_issue, ours_ref_issue + ".json", "vulkan", REF_SPP, 98, size=(W, H))

    cycles = []
    for seed in seeds:
        exr = os.path.join(work, f"cycles_{CYCLES_SPP}_{seed}.exr")
        png = os.path.join(work, f"cycles_{CYCLES_SPP}.png") if seed == 1 else None
        t = cycles_render(args, vdb, camera, CYCLES_SPP, seed, exr, png)
        cycles.append((t, compare(args, exr, cycles_ref)["rel_mse"]))
        log(f"bench --cycles: Cycles {CYCLES_SPP} spp seed {seed}: {t:.2f} s, relMSE {cycles[-1][1]:.4g}")
    t_c = statistics.median(t for t, _ in cycles)
    e_c = statistics.median(e for _, e in cycles)

    ours = []  # (spp, median seconds, median relMSE, median seconds with loading, median relMSE vs REF_SPP)
    spp = 4
    while True:
        pts = []
        for seed in seeds:
            exr = os.path.join(work, f"pyrolume_{spp}_{seed}.exr")
            st = render(args, scene_path, exr, exr + ".json", "vulkan", spp, seed, size=(W, H))
            pts.append((st["seconds"], compare(args, exr, ours_ref)["rel_mse"], st["seconds"] + st["load_seconds"],
                        compare(args, exr, ours_ref_issue)["rel_mse"]))
        ours.append((spp,) + tuple(statistics.median(p[i] for p in pts) for i in range(4)))
        log(f"bench --cycles: pyrolume {spp} spp: {ours[-1][1]:.2f} s, relMSE {ours[-1][2]:.4g} "
            f"({ours[-1][4]:.4g} against its {REF_SPP}-spp reference)")
        if (ours[-1][2] <= e_c and ours[-1][4] <= e_c) or spp >= 4096:
            break
        spp *= 2

    def time_to(points, target):
        """pyrolume's time to `target` on (spp, seconds, relMSE) points, log-log between the bracketing two."""
        for (s0, t0, e0), (s1, t1, e1) in zip(points, points[1:]):
            if e1 <= target:
                return log_interp(t0, e0, t1, e1, target) if e0 > target else t0
        return points[0][1] if points and points[0][2] <= target else float("nan")

    t_match = time_to([(o[0], o[1], o[2]) for o in ours], e_c)
    t_issue = time_to([(o[0], o[1], o[4]) for o in ours], e_c)
    e_c_clean = e_c / (1 + CYCLES_SPP / REF_SPP)
    t_clean = time_to([(o[0], o[1], o[2] / (1 + o[0] / OUR_REF_SPP)) for o in ours], e_c_clean)
    # pyrolume at the spp closest to Cycles' time, for the side-by-side image.
    near = min(ours, key=lambda o: abs(math.log(o[1] / t_c)))
    png = os.path.join(work, f"pyrolume_{near[0]}.png")
    render(args, scene_path, png, png + ".json", "vulkan", near[0], 1, size=(W, H))

    result = {"cycles_spp": CYCLES_SPP, "cycles_seconds": t_c, "cycles_rel_mse": e_c,
              "cycles_reference_seconds": t_cycles_ref, "pyrolume": ours, "pyrolume_seconds_to_match": t_match,
              "ratio": t_match / t_c, "ratio_both_1024": t_issue / t_c, "ratio_reference_noise_removed": t_clean / t_c,
              "cycles_png": os.path.join(work, f"cycles_{CYCLES_SPP}.png"),
              "pyrolume_png": png, "pyrolume_png_spp": near[0], "threads": args.cycles_threads}
    with open(os.path.join(work, "result.json"), "w") as f:
        json.dump(result, f, indent=1)
    print(f"Cycles {CYCLES_SPP} spp: {t_c:.2f} s, relMSE {e_c:.4g} (against its own {REF_SPP}-spp reference; "
          f"pyrolume's has {OUR_REF_SPP} spp)")
    for s, t, e, tl, e_issue in ours:
        print(f"pyrolume {s} spp: {t:.2f} s ({tl:.2f} s with loading), relMSE {e:.4g} "
              f"({e_issue:.4g} against a {REF_SPP}-spp reference)")
    print(f"pyrolume reaches Cycles' {CYCLES_SPP}-spp relMSE (target ≤ 1× Cycles' time):")
    print(f"  both references {REF_SPP} spp, as the issue asks: {t_issue:.2f} s, {t_issue / t_c:.2f}×")
    print(f"  each reference's noise removed: {t_clean:.2f} s, {t_clean / t_c:.2f}×")
    print(f"  pyrolume's reference {OUR_REF_SPP} spp, Cycles' {REF_SPP}: {t_match:.2f} s, {t_match / t_c:.2f}×")
    print(f"images: {result['cycles_png']} and {png} ({near[0]} spp); numbers: {os.path.join(work, 'result.json')}")
    return 0
