"""Statistics over the CSV rows: medians over repetitions, efficiency, the CPU
configuration a configuration is compared with, and equal-time relMSE."""

import math
import statistics


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def medians(rows):
    """(scene, config, spp) → medians over repetitions of the numeric columns."""
    groups = {}
    for r in rows:
        groups.setdefault((r["scene"], r["config"], int(r["spp"])), []).append(r)
    out = {}
    for key, rs in groups.items():
        m = {"n": len(rs), "backend": rs[0]["backend"], "estimator": rs[0]["estimator"],
             "majorant": rs[0]["majorant"], "device": rs[0]["device"]}
        for k in ("seconds", "rel_mse", "rmse", "bias", "samples_per_second", "density_lookups_per_ray",
                  "lookups_per_second", "events_per_path", "wall_seconds"):
            vals = [num(r[k]) for r in rs if not math.isnan(num(r[k]))]
            m[k] = statistics.median(vals) if vals else float("nan")
        out[key] = m
    return out


def eff_spp(med, scene, configs):
    """The efficiency table's fixed spp: the highest level every config reached."""
    per_config = []
    for c in configs:
        s = [spp for (sc, cn, spp) in med if sc == scene and cn == c]
        if s:
            per_config.append(set(s))
    common = set.intersection(*per_config) if per_config else set()
    return max(common) if common else None


def efficiency(m):
    if m is None or not (m["rel_mse"] > 0) or not (m["seconds"] > 0):
        return float("nan")
    return 1.0 / (m["rel_mse"] * m["seconds"])


def cpu_partner(config_name, config_names):
    """The CPU config a config's efficiency is divided by: same estimator if run."""
    parts = config_name.split("/")
    if len(parts) >= 2 and f"cpu/{parts[1]}" in config_names:
        return f"cpu/{parts[1]}"
    cpus = [c for c in config_names if c == "cpu" or c.startswith("cpu/")]
    return cpus[-1] if cpus else None


def equal_time_relmse(med, scene, config, t):
    """relMSE of a config at time t: log-log interpolation of its median curve;
    outside the measured range, extrapolate with slope −1 (relMSE ∝ 1/time for
    an unbiased estimator) from the nearest point."""
    pts = sorted((m["seconds"], m["rel_mse"]) for (sc, cn, _), m in med.items()
                 if sc == scene and cn == config and m["seconds"] > 0 and m["rel_mse"] > 0)
    if not pts:
        return float("nan")
    if t <= pts[0][0]:
        return pts[0][1] * pts[0][0] / t
    if t >= pts[-1][0]:
        return pts[-1][1] * pts[-1][0] / t
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if t0 <= t <= t1:
            if t1 == t0:
                return e0
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + a * (math.log(e1) - math.log(e0)))
    return float("nan")
