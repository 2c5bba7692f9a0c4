"""tools/bench: speed against error (issue 8).

For each benchmark scene and each configuration (backend × emission estimator ×
majorant), render at increasing spp (1, 2 or 4×, … up to a per-point time cap),
several repetitions with different seeds, and measure

  * the render's own wall time (`--stats` "seconds": first dispatch → readback),
  * its error against a high-spp reference of the same scene (`pyrolume compare`:
    relMSE, RMSE, bias),
  * samples/s, density lookups per camera ray, lookups/s.

Outputs (default --out-dir docs/):
  benchmarks.csv                   one row per render
  images/bench_error_vs_time.png   log-log relMSE vs seconds, one panel per scene
  benchmarks.md                    tables; only the part between
                                   <!-- bench:begin --> and <!-- bench:end --> is
                                   regenerated, the rest is hand-written.

Everything else (scene copies, generated VDBs, references, renders) lives under
--work-dir (default: <folder of the pyrolume binary>/bench). References are
cached there, keyed by a hash of the scene JSON, the files it references
(mtime/size), the pyrolume binary and its SPIR-V (mtime/size), the resolution,
spp and seed: a new build or an edited scene regenerates them.

Typical use:
  tools/bench --quick                       # < 10 min on 2 cores with lavapipe
  tools/bench                               # full mode, much longer
  tools/bench --scenes fire,explosion --configs 'vulkan/*' --reps 5
  tools/bench --resolution 1920x1080 --spp-max 64 --scenes terrain_explosion \
              --configs 'vulkan/*' --device 1 --out-dir docs/gpu   # on a real GPU
  tools/bench --list                        # scenes and configs, render nothing
  tools/bench --cycles                      # against Blender Cycles at equal error (needs `blender`)
  tools/bench --sparse                      # sparse grids against dense textures, and a 1024³ shell's memory

Only the Python standard library is used, plus matplotlib for the plot (the
plot is skipped with a warning when matplotlib is missing).
"""

import argparse
import csv
import datetime
import fnmatch
import os
import re
import shlex
import shutil
import statistics
import time

from . import cycles, denoise, sparse
from .common import REPO, log
from .configs import configs_for
from .plot import plot
from .report import CSV_COLUMNS, report, write_markdown
from .runner import bare_lookup_rate, bench_scene, code_stamp, machine_info, reference, spp_levels
from .scenes import collect_scenes


def parse_args(argv):
    ap = argparse.ArgumentParser(prog="tools/bench", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true",
                    help="small resolution, spp 1,4,16,64, CPU with one estimator (< 10 min on 2 cores)")
    ap.add_argument("--pyrolume", default=os.path.join(REPO, "build", "pyrolume"), help="the pyrolume binary")
    ap.add_argument("--generator", default=None, help="gen_fire_vdb (default: beside --pyrolume)")
    ap.add_argument("--out-dir", default=os.path.join(REPO, "docs"),
                    help="where benchmarks.md/.csv and images/bench_*.png go (default docs/)")
    ap.add_argument("--work-dir", default=None, help="scene copies, references, renders "
                                                     "(default: <binary's folder>/bench)")
    ap.add_argument("--data-dir", default=os.path.join(os.path.dirname(REPO), "shared", "data", "vdb"),
                    help="real VDB files, read in place (default ../shared/data/vdb)")
    ap.add_argument("--scenes", default=None, help="comma-separated names or globs (e.g. fire,explosion,blender*)")
    ap.add_argument("--configs", default=None,
                    help="comma-separated globs on config names (e.g. 'vulkan/*', 'cpu*', '*/collision/*')")
    ap.add_argument("--reps", type=int, default=3, help="repetitions per point (≥ 3 for medians; default 3)")
    ap.add_argument("--resolution", default=None, help="WxH (quick 160x90, full 320x180)")
    ap.add_argument("--spp-max", type=int, default=None, help="highest spp level (quick 64, full 256)")
    ap.add_argument("--time-cap", type=float, default=None,
                    help="seconds a point may take; a config stops climbing past it (quick 2, full 30)")
    ap.add_argument("--ref-spp", type=int, default=None, help="reference spp (default 16 × --spp-max)")
    ap.add_argument("--ref-seed", type=int, default=987654321)
    ap.add_argument("--ref-backend", choices=("vulkan", "cpu"), default="vulkan",
                    help="backend of the references (default vulkan; cpu for machines without Vulkan)")
    ap.add_argument("--explosion-resolution", type=int, default=128, help="gen_fire_vdb --resolution")
    ap.add_argument("--device", type=int, default=None, help="Vulkan device index, passed to pyrolume")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--list", action="store_true", help="print scenes and configs, render nothing")
    ap.add_argument("--denoise", action="store_true",
                    help="time `pyrolume denoise` against the render it cleans (default scenes "
                         "fire_ground,terrain_explosion at 1920x1080; benchlib/denoise.py)")
    ap.add_argument("--denoise-spp", type=int, default=16, help="with --denoise: spp of the render (default 16)")
    ap.add_argument("--cycles", action="store_true",
                    help="pyrolume against Blender Cycles at equal error on the Blender 2.79 fire "
                         "(needs `blender` and --data-dir; benchlib/cycles.py)")
    ap.add_argument("--cycles-threads", type=int, default=2, help="with --cycles: Cycles' CPU threads (default 2)")
    ap.add_argument("--sparse", action="store_true",
                    help="sparse NanoVDB grids against dense textures (fire and the Houdini plume, both backends), "
                         "and the peak RSS of a generated 1024³-box shell (benchlib/sparse.py)")
    ap.add_argument("--render-reps", type=int, default=1,
                    help="with --denoise: renders per scene (default 1; the denoise runs --reps times)")
    args = ap.parse_args(argv)
    args.overrides = any(getattr(args, k) is not None for k in ("resolution", "spp_max", "time_cap", "ref_spp"))

    args.pyrolume = os.path.abspath(args.pyrolume)
    if args.generator is None:
        args.generator = os.path.join(os.path.dirname(args.pyrolume), "gen_fire_vdb")
    if args.work_dir is None:
        args.work_dir = os.path.join(os.path.dirname(args.pyrolume), "bench")
    res = args.resolution or ("1920x1080" if args.denoise else "160x90" if args.quick else "320x180")
    m = re.fullmatch(r"(\d+)[x×](\d+)", res)
    if not m:
        ap.error(f"--resolution {res}: expected WxH")
    args.width, args.height = int(m.group(1)), int(m.group(2))
    if args.spp_max is None:
        args.spp_max = 64 if args.quick else 256
    if args.time_cap is None:
        args.time_cap = 2.0 if args.quick else 30.0
    if args.ref_spp is None:
        args.ref_spp = 16 * args.spp_max
    if args.reps < 1 or args.spp_max < 1 or args.ref_spp < 1:
        ap.error("--reps, --spp-max and --ref-spp must be ≥ 1")
    if args.reps < 3:
        log("bench: warning: fewer than 3 repetitions; medians are not robust")
    return args


def main(argv):
    args = parse_args(argv)
    if not os.access(args.pyrolume, os.X_OK):
        log(f"bench: {args.pyrolume} not found; build it (ninja -C build pyrolume gen_fire_vdb) "
            f"or pass --pyrolume PATH")
        return 2
    work = os.path.abspath(args.work_dir)
    # Both folders are made now, so a path that cannot be one fails before
    # the runs, not after them when the report is written.
    for what, folder in (("--work-dir", work), ("--out-dir", os.path.abspath(args.out_dir))):
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError as e:
            log(f"bench: {what} {folder}: cannot make the folder: {e.strerror}")
            return 2
    if args.denoise:
        return denoise.run(args, argv)
    if args.cycles:
        return cycles.run(args)
    if args.sparse:
        return sparse.run(args, argv)

    scenes, skipped = collect_scenes(args, work)
    cfg_filter = [c.strip() for c in args.configs.split(",")] if args.configs else None
    plan = []
    for s in scenes:
        cs = [c for c in configs_for(s, args.quick)
              if cfg_filter is None or any(fnmatch.fnmatch(c.name, f) for f in cfg_filter)]
        if cs:
            plan.append((s, cs))
    if args.list:
        for s, cs in plan:
            print(f"{s.name}: {', '.join(c.name for c in cs)}    [{s.source}]")
        for name, why in skipped:
            print(f"{name}: skipped: {why}")
        print(f"resolution {args.width}x{args.height}, spp {spp_levels(args)}, reps {args.reps}, "
              f"reference {args.ref_spp} spp, time cap {args.time_cap:g} s")
        return 0
    if not plan:
        log("bench: nothing to run (check --scenes / --configs)")
        return 2

    t_start = time.monotonic()
    run = {"date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M"),
           "command": "tools/bench " + " ".join(shlex.quote(a) for a in argv),
           "load_start": " / ".join(f"{x:.2f}" for x in os.getloadavg()),
           "machine": machine_info(args.pyrolume), "overrides": args.overrides}
    log(f"bench: {len(plan)} scenes, {sum(len(cs) for _, cs in plan)} configs, "
        f"{args.width}x{args.height}, spp {spp_levels(args)}, {args.reps} reps; load {run['load_start']}")
    code = code_stamp(args.pyrolume)
    # The bare lookup loop, measured before and after the renders (issue 21):
    # the lookups/s table divides by the median of both. Its verdicts are for
    # Vulkan configs only, so a CPU-only run skips the loop (~9 s a measurement).
    vulkan_in_plan = any(c.name.startswith("vulkan") for _, cs in plan for c in cs)
    bare = [r for r in [bare_lookup_rate(args)] if r] if vulkan_in_plan else []

    # Rows go to a partial CSV in the work dir as they come, so an interrupted
    # run keeps what it measured; the final CSV replaces docs/ only at the end.
    partial = os.path.join(work, "benchmarks.partial.csv")
    rows, refs = [], {}
    with open(partial, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
        writer.writeheader()
        for s, cs in plan:
            try:
                ref_exr, ref_stats, cached = reference(args, work, s, code)
            except RuntimeError as e:
                log(f"bench: {s.name}: reference failed, skipping the scene:\n  {e}")
                skipped.append((s.name, "reference render failed"))
                continue
            refs[s.name] = ref_stats
            log(f"bench: {s.name}: reference {'cached' if cached else 'rendered'} "
                f"({ref_stats['seconds']:.1f} s at {ref_stats['spp']} spp)")
            bench_scene(args, work, s, cs, ref_exr, writer, rows)
            f.flush()

    if vulkan_in_plan:
        bare += [r for r in [bare_lookup_rate(args)] if r]
    run["lookup_limit"] = statistics.median(bare) if bare else None
    run["lookup_limit_runs"] = bare
    run["load_end"] = " / ".join(f"{x:.2f}" for x in os.getloadavg())
    out_dir = os.path.abspath(args.out_dir)
    os.makedirs(os.path.join(out_dir, "images"), exist_ok=True)
    csv_path = os.path.join(out_dir, "benchmarks.csv")
    shutil.copyfile(partial, csv_path + ".tmp")
    os.replace(csv_path + ".tmp", csv_path)
    run["plot"] = os.path.join(out_dir, "images", "bench_error_vs_time.png")
    run["md"] = os.path.join(out_dir, "benchmarks.md")
    plotted = False if args.no_plot else plot(rows, [s.name for s, _ in plan], run["plot"])
    run["wall"] = time.monotonic() - t_start
    write_markdown(run["md"], report(args, run, rows, [s for s, _ in plan], skipped, refs, plotted))
    log(f"bench: done in {run['wall']:.0f} s: {os.path.relpath(csv_path)}, {os.path.relpath(run['md'])}"
        + (f", {os.path.relpath(run['plot'])}" if plotted else ""))
    return 0
