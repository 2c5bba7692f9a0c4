"""The benchmark scenes: the shipped, generated and real-data scenes in their
order (collect_scenes), and the scene copies that renders read (paths made
absolute, a configuration's integrator keys)."""

import copy
import fnmatch
import math
import os
import re
import subprocess

from .common import REPO, file_stamp, load_json, log, write_json_if_changed


class Scene:
    def __init__(self, name, data, base_dir, source, note="", estimators=("absorption", "collision")):
        self.name = name
        self.data = data            # scene JSON as a dict
        self.base_dir = base_dir    # folder its relative paths resolve against
        self.source = source        # where it came from, for the markdown
        self.note = note
        # The emission estimators its grid configs render with ("auto": the
        # scene's default, the key left out).
        self.estimators = estimators

    @property
    def has_grid(self):
        return any(m.get("type") == "vdb" for m in self.data.get("media", []))

    @property
    def uses_mis(self):
        """The collision configs sample lights (host/light/LightSelection,
        light_candidates): "mis" false samples nothing; "mis" true (or
        "light_only") an environment map or an emissive grid wherever surfaces or
        scattering media are; "mis" absent the environment map there too, but the
        emissive grids only where there are surfaces."""
        integ = self.data.get("integrator", {})
        mis = integ.get("mis")
        if mis is False:
            return False
        media = self.data.get("media", [])
        surfaces = bool(self.data.get("shapes"))
        scatters = surfaces or any(max(m.get("sigma_s", [0, 0, 0])) > 0 for m in media)
        grids = any(m.get("type") == "vdb" and m.get("emission", {}).get("scale", 1.0) > 0 for m in media)
        asked = mis is True or integ.get("light_only", False)
        return scatters and ("environment" in self.data or (grids and (asked or surfaces)))

    def referenced_files(self):
        return sorted(set(_walk_paths(self.data, self.base_dir)))


PATH_KEYS = {"file", "mesh", "texture"}


def _walk_paths(node, base_dir):
    """Absolute paths of every file a scene references (keys file/mesh/texture)."""
    if isinstance(node, dict):
        for k, v in node.items():
            if k in PATH_KEYS and isinstance(v, str):
                yield os.path.normpath(os.path.join(base_dir, v))
            else:
                yield from _walk_paths(v, base_dir)
    elif isinstance(node, list):
        for v in node:
            yield from _walk_paths(v, base_dir)


def _absolutise(node, base_dir):
    """Rewrite relative file/mesh/texture paths to absolute ones, in place, so a
    scene copy written anywhere still finds its data (paths resolve against the
    scene file's folder)."""
    if isinstance(node, dict):
        for k, v in node.items():
            if k in PATH_KEYS and isinstance(v, str):
                node[k] = os.path.normpath(os.path.join(base_dir, v))
            else:
                _absolutise(v, base_dir)
    elif isinstance(node, list):
        for v in node:
            _absolutise(v, base_dir)


def asset_scene(name, note=""):
    path = os.path.join(REPO, "assets", "scenes", name + ".json")
    return Scene(name, load_json(path), os.path.dirname(path), os.path.relpath(path, REPO), note)


def vdb_info(pyrolume, path):
    """Parse `pyrolume info FILE`: creator and, per grid, its world bbox."""
    out = subprocess.run([pyrolume, "info", path], capture_output=True, text=True, check=True).stdout
    creator = ""
    m = re.search(r'creator "([^"]*)"', out)
    if m:
        creator = m.group(1)
    grids, current = {}, None
    for line in out.splitlines():
        m = re.match(r'grid "(.*)"$', line)
        if m:
            current = m.group(1)
            grids[current] = None
            continue
        m = re.match(r"\s*world bbox: \[([^\]]*)\]-\[([^\]]*)\]", line)
        if m and current is not None:
            grids[current] = ([float(x) for x in m.group(1).split()], [float(x) for x in m.group(2).split()])
    return creator, grids


def frame_camera(lo, hi, up_axis, aspect, fov_deg=40.0, margin=1.15):
    """A pinhole camera that looks at the bbox centre along a horizontal axis and
    fits the whole box: distance from the box's near face so that both its
    height (vertical fov) and its width (fov × aspect) fit, with a margin."""
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    ext = [(b - a) / 2 for a, b in zip(lo, hi)]
    t = math.tan(math.radians(fov_deg) / 2)
    if up_axis == 2:     # Blender: +Z up, look along +Y, image x along +X
        forward, up, half_w, half_h, half_d = 1, [0, 0, 1], ext[0], ext[2], ext[1]
    else:                # Houdini / OpenVDB convention: +Y up, look along +Z
        forward, up, half_w, half_h, half_d = 2, [0, 1, 0], ext[0], ext[1], ext[2]
    dist = half_d + margin * max(half_h / t, half_w / (t * aspect))
    pos = list(c)
    pos[forward] -= dist
    return {"position": [round(v, 4) for v in pos], "look_at": [round(v, 4) for v in c],
            "up": up, "fov_deg": fov_deg}


# Per-file looks for the real VDBs (--vdb-dir; other people's data, read in
# place and never copied). Chosen so each is neither transparent nor opaque:
# optical depth of a few across the plume. Unknown files get the generic
# smoke preset.
REAL_VDB_PRESETS = {
    # Blender 2.79 fire: `heat` is dimensionless (0..1.57) → ~1900 K at the top.
    "blender279_fire_frame075": {
        "background": [0.02, 0.022, 0.03],
        "medium": {"density_scale": 1.0, "sigma_a": [0.3, 0.3, 0.3], "sigma_s": [0.2, 0.2, 0.2], "g": 0.2,
                   "temperature_grid": "heat",
                   "temperature": {"scale": 1200.0, "offset": 0.0, "cutoff_k": 500.0},
                   "emission": {"scale": 4.0, "blackbody": "seed"}},
    },
    # Mantaflow first frame: temperature constant 1.97 over the density's voxels.
    "blender50_mantaflow_smoke_frame0001": {
        "background": [0.02, 0.022, 0.03],
        "medium": {"density_scale": 1.0, "sigma_a": [1.5, 1.5, 1.5], "sigma_s": [0.5, 0.5, 0.5], "g": 0.0,
                   "temperature_grid": "temperature",
                   "temperature": {"scale": 1000.0, "offset": 0.0, "cutoff_k": 500.0},
                   "emission": {"scale": 2.0, "blackbody": "seed"}},
    },
    # Houdini smoke plume, density only (up to 5.7): smoke lit by a white background.
    "openvdb_smoke1_houdini": {
        "background": [1.0, 1.0, 1.0],
        "medium": {"density_scale": 1.0, "sigma_a": [0.1, 0.1, 0.1], "sigma_s": [0.5, 0.5, 0.5],
                   "g": 0.3},
    },
}


def real_vdb_scene(pyrolume, path, work, aspect):
    name = os.path.splitext(os.path.basename(path))[0]
    creator, grids = vdb_info(pyrolume, path)
    preset = copy.deepcopy(REAL_VDB_PRESETS.get(name))
    if preset is None:
        preset = {"background": [1, 1, 1], "medium": {"sigma_a": [0.5, 0.5, 0.5], "sigma_s": [2, 2, 2]}}
    bbox = grids.get(preset["medium"].get("density_grid", "density"))
    if not bbox:
        raise RuntimeError(f"{path}: no non-empty density grid")
    lo, hi = bbox
    if name not in REAL_VDB_PRESETS:   # generic: optical depth ~2 across at density 1
        size = max(b - a for a, b in zip(lo, hi))
        preset["medium"]["density_scale"] = 1.0 / size
    # Blender caches (creator "Blender/…", or Mantaflow's `shadow` grid) are +Z up.
    up_axis = 2 if ("Blender" in creator or "shadow" in grids) else 1
    medium = {"name": name, "type": "vdb", "file": os.path.abspath(path), "density_grid": "density"}
    medium.update(preset["medium"])
    data = {
        "camera": frame_camera(lo, hi, up_axis, aspect),
        "film": {"width": 160, "height": 90, "spp": 16, "exposure": 0.0, "seed": 1},
        "integrator": {"max_depth": 8, "mis": False, "emission_estimator": "collision", "majorant": "grid"},
        "background": {"rgb": preset["background"]},
        "media": [medium],
    }
    scene_dir = os.path.join(work, "scenes")
    os.makedirs(scene_dir, exist_ok=True)
    scene_path = os.path.join(scene_dir, name + ".json")
    write_json_if_changed(scene_path, data)
    up = "+Z" if up_axis == 2 else "+Y"
    # Named by file only: the data lives outside the repository.
    return Scene(name, data, scene_dir, os.path.basename(path) + " (real data, read in place; scene generated)",
                 f"read in place; camera frames the density grid's world bbox, {up} up")


def thin_fire_scene(path, work):
    """Issue 23's thin, hot flame: the Blender 2.79 fire as a user writes it,
    density ×0.02 and emission ×100, everything else the defaults (camera
    framed automatically, integrator "auto")."""
    data = {"media": [{"type": "vdb", "file": os.path.abspath(path), "density_scale": 0.02,
                       "emission": {"scale": 100}}]}
    scene_dir = os.path.join(work, "scenes")
    os.makedirs(scene_dir, exist_ok=True)
    write_json_if_changed(os.path.join(scene_dir, "blender_thin_fire.json"), data)
    return Scene("blender_thin_fire", data, scene_dir,
                 os.path.basename(path) + " (real data, read in place), density ×0.02, emission ×100",
                 "the shortest scene file: camera framed automatically, integrator \"auto\"",
                 estimators=("absorption", "collision", "line", "auto"))


def explosion_scene(generator, work, resolution):
    """The procedural explosion: gen_fire_vdb --sparse (a thin noisy shell with
    large empty regions, the majorant grid's showcase), rendered with fire.json's
    camera and medium parameters. Regenerated when the generator changes."""
    out_dir = os.path.join(work, "scenes")
    os.makedirs(out_dir, exist_ok=True)
    vdb = os.path.join(out_dir, f"explosion_r{resolution}.vdb")
    stamp = vdb + ".stamp"
    want = file_stamp(generator) + f" resolution={resolution}"
    have = open(stamp).read() if os.path.exists(stamp) and os.path.exists(vdb) else None
    if have != want:
        log(f"bench: generating {os.path.relpath(vdb, REPO)}")
        subprocess.run([generator, vdb, "--sparse", "--resolution", str(resolution)], check=True,
                       capture_output=True, text=True)
        with open(stamp, "w") as f:
            f.write(want)
    fire = asset_scene("fire")
    data = copy.deepcopy(fire.data)
    _absolutise(data, fire.base_dir)
    data["media"][0]["file"] = vdb
    data["media"][0]["name"] = "explosion"
    write_json_if_changed(os.path.join(out_dir, "explosion.json"), data)
    return Scene("explosion", data, out_dir,
                 f"gen_fire_vdb --sparse --resolution {resolution} (fire.json's camera and medium)",
                 "generated into the work dir")


def lookup_bound_scene(work):
    """Issue 21's lookup-bound scene: the shipped fire made dense and
    scattering (density ×8, σa 0.5, σs 4, max_depth 16); ~12 density lookups
    per camera ray, so its lookups/s measure tracking, not per-sample work."""
    fire = asset_scene("fire")
    data = copy.deepcopy(fire.data)
    _absolutise(data, fire.base_dir)
    m = data["media"][0]
    m.update(density_scale=8.0, sigma_a=[0.5, 0.5, 0.5], sigma_s=[4.0, 4.0, 4.0])
    data["integrator"]["max_depth"] = 16
    out_dir = os.path.join(work, "scenes")
    os.makedirs(out_dir, exist_ok=True)
    write_json_if_changed(os.path.join(out_dir, "lookup_bound.json"), data)
    return Scene("lookup_bound", data, out_dir, "fire.json, density ×8, σa 0.5, σs 4, max_depth 16 (generated)",
                 "generated into the work dir; a rate, so rendered at the bench's resolution")


def collect_scenes(args, work):
    """All benchmark scenes, in order, and notes for those skipped."""
    aspect = args.width / args.height
    scenes, skipped = [], []
    wanted = [s.strip() for s in args.scenes.split(",")] if args.scenes else None

    def want(name):
        return wanted is None or any(fnmatch.fnmatch(name, w) or w == name for w in wanted)

    for name in ("homogeneous_spheres", "spheres_temperatures", "fire"):
        if want(name):
            scenes.append(asset_scene(name))
    if want("explosion"):
        if os.path.exists(args.generator):
            scenes.append(explosion_scene(args.generator, work, args.explosion_resolution))
        else:
            skipped.append(("explosion", f"generator {args.generator} not built"))
    if want("terrain_explosion"):
        p = os.path.join(REPO, "assets", "scenes", "terrain_explosion.json")
        if os.path.exists(p):
            scenes.append(asset_scene("terrain_explosion"))
        else:
            skipped.append(("terrain_explosion", "assets/scenes/terrain_explosion.json does not exist yet "
                                                 "(needs surfaces + MIS)"))
    # A ground plane lit by a scattering fire (issue 21): what MIS is for, with the scene's defaults.
    if want("fire_ground"):
        scenes.append(asset_scene("fire_ground"))
    if want("lookup_bound"):
        scenes.append(lookup_bound_scene(work))
    data_dir = args.data_dir
    if os.path.isdir(data_dir):
        for fn in sorted(os.listdir(data_dir)):
            if not fn.endswith(".vdb") or not want(os.path.splitext(fn)[0]):
                continue
            try:
                scenes.append(real_vdb_scene(args.pyrolume, os.path.join(data_dir, fn), work, aspect))
            except (RuntimeError, subprocess.CalledProcessError) as e:
                skipped.append((fn, f"could not make a scene: {e}"))
        fire = os.path.join(data_dir, "blender279_fire_frame075.vdb")
        if want("blender_thin_fire") and os.path.exists(fire):
            scenes.append(thin_fire_scene(fire, work))
    elif want("real"):
        skipped.append(("real VDBs", f"{data_dir} absent"))
    return scenes, skipped


def scene_for_config(scene, config):
    """A copy of the scene with the config's integrator keys, paths made absolute."""
    data = copy.deepcopy(scene.data)
    _absolutise(data, scene.base_dir)
    if config.estimator is not None:
        integ = data.setdefault("integrator", {})
        if config.estimator == "auto":
            integ.pop("emission_estimator", None)
        else:
            integ["emission_estimator"] = config.estimator
        integ["majorant"] = config.majorant
        if config.mis is not None:
            integ["mis"] = config.mis
        if config.estimator == "absorption" and integ.get("mis") is True:
            # A scene that writes "mis": true with the absorption estimator is
            # refused (light sampling needs the collision estimator); the
            # absorption configs render with BSDF/phase sampling, as they did.
            integ["mis"] = False
            integ.pop("light_only", None)
    return data


def scenes_by_name(scenes, name):
    return next(s for s in scenes if s.name == name)
