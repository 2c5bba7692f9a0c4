"""Running pyrolume: the cached references, each scene's measured renders at
rising spp, `pyrolume compare`, the bare lookup loop (build/bench_lookup) and
the machine's description."""

import hashlib
import json
import os
import re
import shlex
import statistics
import subprocess
import time

from .common import REPO, file_stamp, load_json, log, write_json_if_changed
from .configs import Config
from .scenes import scene_for_config


# lavapipe's bare trilinear-lookup loop on this machine, measured idle: the
# ceiling against which the renderer's lookups/s are judged when
# build/bench_lookup (the same loop, measured in every run) is missing.
MACHINE_LOOKUP_LIMIT = 90e6


def bare_lookup_rate(args):
    """Median M lookups/s of build/bench_lookup (the bare lookup loop), or None."""
    tool = os.path.join(os.path.dirname(args.pyrolume), "bench_lookup")
    if not os.access(tool, os.X_OK):
        return None
    cmd = [tool, "--json", "--reps", "3"] + (["--device", str(args.device)] if args.device is not None else [])
    try:
        out = subprocess.run(cmd, check=True, capture_output=True, text=True, timeout=600).stdout
        return json.loads(out)["lookups_per_second"]
    except (subprocess.SubprocessError, ValueError, KeyError) as e:
        log(f"bench: bench_lookup failed ({e}); using the {MACHINE_LOOKUP_LIMIT / 1e6:.0f} M/s of an idle run")
        return None


def code_stamp(pyrolume):
    """The binary plus the SPIR-V it loads at run time (build/shaders/*.spv)."""
    parts = [file_stamp(pyrolume)]
    spv_dir = os.path.join(os.path.dirname(os.path.abspath(pyrolume)), "shaders")
    if os.path.isdir(spv_dir):
        for fn in sorted(os.listdir(spv_dir)):
            if fn.endswith(".spv"):
                parts.append(file_stamp(os.path.join(spv_dir, fn)))
    return "\n".join(parts)


def render(args, scene_path, out_exr, stats_path, backend, spp, seed, variance=False, size=None, aovs=False):
    width, height = size or (args.width, args.height)
    cmd = [args.pyrolume, "render", scene_path, "-o", out_exr, "--backend", backend, "--spp", str(spp),
           "--width", str(width), "--height", str(height), "--seed", str(seed),
           "--stats", stats_path]
    if variance:
        cmd.append("--variance")
    if aovs:
        cmd.append("--aovs")
    if args.device is not None and backend == "vulkan":
        cmd += ["--device", str(args.device)]
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        raise RuntimeError(f"exit {p.returncode}: {' '.join(map(shlex.quote, cmd))}\n{p.stderr.strip()[-2000:]}")
    with open(stats_path) as f:
        stats = json.load(f)
    stats["wall_seconds"] = wall
    return stats


COMPARE_RE = re.compile(r"^all rmse=(\S+) rel_mse=(\S+) bias=(\S+)(?: bias_se=(\S+))?")


def compare(args, a, ref):
    """`pyrolume compare A REF` → the `all` line's numbers (channels averaged)."""
    p = subprocess.run([args.pyrolume, "compare", a, ref], capture_output=True, text=True)
    if p.returncode not in (0, 3):
        raise RuntimeError(f"compare exit {p.returncode}: {p.stderr.strip()}")
    for line in p.stdout.splitlines():
        m = COMPARE_RE.match(line.strip())
        if m:
            return {"rmse": float(m.group(1)), "rel_mse": float(m.group(2)), "bias": float(m.group(3)),
                    "bias_se": float(m.group(4)) if m.group(4) else ""}
    raise RuntimeError(f"compare printed no 'all' line:\n{p.stdout}")


def reference(args, work, scene, code):
    """The scene's high-spp reference (Vulkan unless --ref-backend cpu), cached by
    content hash. The collision estimator and the majorant grid, the fastest to
    converge; on scenes that bench the line estimator, the scene's default
    ("auto"), which picks it there (a collision reference's own noise would
    floor the line estimator's error)."""
    b = args.ref_backend
    estimator = "auto" if "auto" in scene.estimators else "collision"
    config = Config(b, estimator, "grid" if b == "vulkan" else "global") if scene.has_grid else Config(b)
    data = scene_for_config(scene, config)
    h = hashlib.sha256()
    h.update(json.dumps(data, sort_keys=True).encode())
    for p in scene.referenced_files():
        h.update((file_stamp(p) if os.path.exists(p) else p + ":missing").encode())
    h.update(code.encode())
    h.update(f"{b} {args.width}x{args.height} spp={args.ref_spp} seed={args.ref_seed} device={args.device}".encode())
    key = h.hexdigest()[:16]
    ref_dir = os.path.join(work, "refs")
    os.makedirs(ref_dir, exist_ok=True)
    base = os.path.join(ref_dir, f"{scene.name}-{b}-{args.width}x{args.height}-{args.ref_spp}spp-{key}")
    exr, stats_path = base + ".exr", base + ".json"
    if os.path.exists(exr) and os.path.exists(stats_path):
        return exr, load_json(stats_path), True
    scene_path = base + ".scene.json"
    write_json_if_changed(scene_path, data)
    log(f"bench: reference {scene.name}: {args.ref_spp} spp at {args.width}x{args.height} ({config.name}) ...")
    stats = render(args, scene_path, exr + ".tmp.exr", stats_path + ".tmp", b, args.ref_spp,
                   args.ref_seed, variance=True)
    stats["config"] = config.name
    os.replace(exr + ".tmp.exr", exr)
    with open(stats_path, "w") as f:
        json.dump(stats, f, indent=2)
    os.remove(stats_path + ".tmp")
    return exr, stats, False


def spp_levels(args):
    step = 4 if args.quick else 2
    levels, s = [], 1
    while s < args.spp_max:
        levels.append(s)
        s *= step
    levels.append(args.spp_max)
    return levels


def bench_scene(args, work, scene, configs, ref_exr, writer, rows):
    """Render every config of one scene at rising spp.

    Configs are interleaved inside each (spp, rep) so that a change in the
    machine's background load hits all of them alike: the ratios taken from one
    run stay fair even when absolute times drift. A config stops climbing when
    its next point would take longer than --time-cap (predicted from the median
    of its current point, assuming time ∝ spp)."""
    scene_dir = os.path.join(work, "scenes", scene.name)
    render_dir = os.path.join(work, "renders")
    os.makedirs(scene_dir, exist_ok=True)
    os.makedirs(render_dir, exist_ok=True)
    paths = {}
    for c in configs:
        paths[c.name] = os.path.join(scene_dir, c.slug + ".json")
        write_json_if_changed(paths[c.name], scene_for_config(scene, c))
    # Warm-up: the first render of a new shader variant pays lavapipe's LLVM compile
    # inside its first dispatch (≈ 0.5 s here; Mesa's disk cache serves later
    # processes), which would otherwise land in the first measured point.
    for c in configs:
        try:
            render(args, paths[c.name], os.path.join(render_dir, "warmup.exr"),
                   os.path.join(render_dir, "warmup.json"), c.backend, 1, 1, size=(16, 16))
        except RuntimeError:
            pass   # the measured renders will report it
    active = list(configs)
    levels = spp_levels(args)
    for li, spp in enumerate(levels):
        if not active:
            break
        times = {c.name: [] for c in active}
        for rep in range(args.reps):
            seed = 1000 * (li + 1) + rep + 1   # distinct per point and rep, never the reference's
            for c in list(active):
                out = os.path.join(render_dir, f"{scene.name}-{c.slug}.exr")
                stats_path = out[:-4] + ".json"
                try:
                    st = render(args, paths[c.name], out, stats_path, c.backend, spp, seed)
                    err = compare(args, out, ref_exr)
                except RuntimeError as e:
                    log(f"bench: {scene.name} {c.name} spp={spp}: FAILED, dropping this config:\n  {e}")
                    active.remove(c)
                    continue
                row = {"scene": scene.name, "device": st.get("device", ""), "width": args.width,
                       "height": args.height, "spp": spp, "rep": rep, "seed": seed,
                       "loadavg_1m": round(os.getloadavg()[0], 2)}
                row.update(c.csv_fields())
                row["mis"] = st.get("light_strategy", row["mis"])  # mis, bsdf or light_only
                for k in ("seconds", "load_seconds", "wall_seconds", "samples_per_second",
                          "density_lookups_per_ray", "lookups_per_second", "events_per_path",
                          "peak_rss_mb", "nonfinite_samples"):
                    row[k] = st.get(k, "")
                row.update(err)
                writer.writerow(row)
                rows.append(row)
                times[c.name].append(st["seconds"])
        log(f"bench: {scene.name} spp={spp}: " + ", ".join(
            f"{c.name} {statistics.median(times[c.name]):.3f}s" for c in active if times[c.name]))
        if li + 1 < len(levels):
            nxt = levels[li + 1]
            active = [c for c in active
                      if times[c.name] and statistics.median(times[c.name]) * nxt / spp <= args.time_cap]
    for stem in [f"{scene.name}-{c.slug}" for c in configs] + ["warmup"]:
        for ext in (".exr", ".json"):
            p = os.path.join(render_dir, stem + ext)
            if os.path.exists(p):
                os.remove(p)


def machine_info(pyrolume):
    info = {"cpu": "unknown", "nproc": os.cpu_count(), "devices": ""}
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        m = re.search(r"^Model name:\s*(.+)$", out, re.M)
        if m:
            info["cpu"] = m.group(1).strip()
    except OSError:
        pass
    try:
        info["nproc"] = int(subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip())
    except (OSError, ValueError):
        pass
    try:
        info["devices"] = subprocess.run([pyrolume, "devices"], capture_output=True, text=True).stdout.strip()
    except OSError:
        pass
    try:
        rev = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        info["commit"] = rev + (" + uncommitted changes" if dirty else "")
    except OSError:
        info["commit"] = "unknown"
    return info
