"""Bake a small Mantaflow fire with Blender and leave its OpenVDB cache on disk.

Written for Blender 3.4 (Debian's `blender` package, 3.4.1); pyrolume itself does not
depend on Blender. Run headless:

  blender -b --factory-startup -P tools/cycles/bake_fire.py -- \
      --out /tmp/fire34 [--frames 40] [--resolution 48] [--flow-type BOTH] [--noise]

`... -- --help` lists the options. The last line printed is `VDB <path>`, the .vdb file
of the last baked frame.

Scene, built from empty factory settings (the default cube, camera and light removed),
the way Object > Quick Effects > Quick Smoke with a fire style sets it up:

  * Emitter: a cube 0.5 units on a side at the origin (--emitter ico: an icosphere of
    radius 0.25 instead), with a Fluid modifier of type Flow: flow type Fire + Smoke
    ('BOTH', the default here; --flow-type FIRE gives Quick Fire's "Fire" only, where the
    smoke comes from the burnt fuel alone), behaviour Inflow, source Mesh, surface
    emission distance 1.5 (as Quick Smoke sets); other flow settings at Blender's
    defaults (fuel 1.0, temperature 1.0, density 1.0).
  * Domain: a cube placed as Quick Smoke places it, around the emitter's bounding box
    with 1 unit of room at the sides and below and 3 above (location (0, 0, 1),
    scale (1.25, 1.25, 2.25): 2.5 x 2.5 x 4.5 units, z from -1.25 to 3.25), with a Fluid
    modifier of type Domain, domain type Gas, --resolution divisions along its longest
    side (48 by default: 27 x 27 x 48 cells), cache type All (Blender's default is
    Replay, which bakes nothing ahead; All bakes every frame), data format OpenVDB at
    --precision (Blender's default half floats unless told), cache frames 1..--frames,
    adaptive domain off. Quick Smoke switches noise (high-resolution turbulence) on for
    fire; that is off here unless --noise, to keep the bake short; the base-resolution
    grids written without it are the ones pyrolume reads. All other domain settings
    (time scale, vorticity, flame/fire parameters, dissolve off, ...) are Blender's.
  * The scene runs frames 1..--frames at 24 fps.

The bake runs bpy.ops.fluid.bake_all() with a context override that makes the domain
the active and only selected object; executed (not invoked), the operator bakes in the
foreground, which is what background mode needs. Files are written by Mantaflow under
OUT: OUT/data/fluid_data_NNNN.vdb, one per frame (Blender 3.4 writes the grids density,
flame, shadow, temperature and velocity, as half floats by default, in the domain's
local cell space: index (0,0,0) at the origin, voxel size = domain size / divisions;
Blender adds the domain object's transform when it loads them), plus OUT/config/ (and
OUT/noise/ with --noise; mesh/, particles/ and guiding/ stay empty). These sub-folders
are deleted first if they exist; nothing else in OUT is touched. The script checks
that every frame's .vdb file exists and is not empty, and exits with an error
otherwise.

At 48 divisions, 40 frames bake in about 6 s (10 s for the whole run) on 2 CPU cores.
"""

import argparse
import glob
import os
import shutil
import sys
import time

import bpy

# Sub-folders Mantaflow writes under the cache directory.
MANTAFLOW_CACHE_DIRS = ("config", "data", "noise", "mesh", "particles", "guiding")


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="bake_fire.py",
                                description="Bake a Mantaflow fire (Quick Fire-like) to OpenVDB with Blender 3.4.")
    p.add_argument("--out", required=True, help="cache directory (created; an existing cache in it is replaced)")
    p.add_argument("--frames", type=int, default=40, help="bake frames 1..FRAMES (default 40)")
    p.add_argument("--resolution", type=int, default=48,
                   help="domain resolution divisions along the longest side (default 48)")
    p.add_argument("--flow-type", choices=("FIRE", "BOTH"), default="BOTH",
                   help="BOTH = Fire + Smoke (default), FIRE = fire only (Quick Fire's style)")
    p.add_argument("--emitter", choices=("cube", "ico"), default="cube",
                   help="cube: 0.5-unit cube (default); ico: icosphere of radius 0.25")
    p.add_argument("--precision", choices=("default", "FULL", "HALF", "MINI"), default="default",
                   help="OpenVDB float depth (default: Blender's own default)")
    p.add_argument("--noise", action="store_true", help="also bake Quick Smoke's noise (much slower)")
    a = p.parse_args(argv)
    if a.frames < 1:
        p.error("--frames must be >= 1")
    if a.resolution < 8:
        p.error("--resolution must be >= 8")
    return a


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)


def add_emitter(kind, flow_type):
    if kind == "cube":
        bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.0, 0.0, 0.0))
    else:
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.25, location=(0.0, 0.0, 0.0))
    emitter = bpy.context.active_object
    emitter.name = "Fire Emitter"
    mod = emitter.modifiers.new("Fluid", 'FLUID')
    mod.fluid_type = 'FLOW'
    fs = mod.flow_settings
    fs.flow_type = flow_type
    fs.flow_behavior = 'INFLOW'
    fs.flow_source = 'MESH'
    fs.surface_distance = 1.5
    emitter.display_type = 'WIRE'
    emitter.hide_render = True
    return emitter


def add_domain(emitter, args, cache_dir):
    # Bounding box of the emitter in world space, as Quick Smoke computes it.
    corners = [emitter.matrix_world @ v.co for v in emitter.data.vertices]
    lo = [min(c[i] for c in corners) for i in range(3)]
    hi = [max(c[i] for c in corners) for i in range(3)]
    loc = tuple(0.5 * (lo[i] + hi[i]) + (1.0 if i == 2 else 0.0) for i in range(3))
    scale = tuple(0.5 * (hi[i] - lo[i]) + (2.0 if i == 2 else 1.0) for i in range(3))

    bpy.ops.mesh.primitive_cube_add(size=2.0, location=loc)
    domain = bpy.context.active_object
    domain.name = "Fire Domain"
    domain.scale = scale
    mod = domain.modifiers.new("Fluid", 'FLUID')
    mod.fluid_type = 'DOMAIN'
    ds = mod.domain_settings
    ds.domain_type = 'GAS'
    ds.resolution_max = args.resolution
    ds.use_adaptive_domain = False
    ds.use_noise = bool(args.noise)
    ds.cache_type = 'ALL'
    ds.cache_data_format = 'OPENVDB'
    if args.noise:
        ds.cache_noise_format = 'OPENVDB'
    if args.precision != "default":
        ds.openvdb_data_depth = args.precision
    ds.cache_directory = cache_dir
    ds.cache_frame_start = 1
    ds.cache_frame_end = args.frames
    domain.display_type = 'WIRE'
    return domain, ds


def main():
    args = parse_args()
    if not bpy.app.build_options.fluid or not bpy.app.build_options.openvdb:
        sys.exit("bake_fire.py: this Blender was built without fluid or OpenVDB support")
    cache_dir = os.path.abspath(args.out)
    os.makedirs(cache_dir, exist_ok=True)

    clear_scene()
    scene = bpy.context.scene
    scene.frame_start = 1
    scene.frame_end = args.frames
    scene.render.fps = 24
    scene.frame_set(1)

    emitter = add_emitter(args.emitter, args.flow_type)
    domain, ds = add_domain(emitter, args, cache_dir)

    print(f"bake_fire: Blender {bpy.app.version_string}, flow {args.flow_type}, emitter {args.emitter}, "
          f"resolution {args.resolution}, frames 1..{args.frames}, noise {'on' if args.noise else 'off'}, "
          f"vdb depth {ds.openvdb_data_depth}, cache {cache_dir}", flush=True)

    # Remove an earlier bake's files (only Mantaflow's own cache folders) so that no stale
    # frames remain; bpy.ops.fluid.free_all() is not used: on a domain that has not been
    # simulated in this session, Blender 3.4 aborts in it ("can't clean grid cache").
    for sub in MANTAFLOW_CACHE_DIRS:
        path = os.path.join(cache_dir, sub)
        if os.path.isdir(path):
            shutil.rmtree(path)

    view_layer = bpy.context.view_layer
    for obj in view_layer.objects:
        obj.select_set(obj is domain)
    view_layer.objects.active = domain
    with bpy.context.temp_override(object=domain, active_object=domain,
                                   selected_objects=[domain], selected_editable_objects=[domain]):
        t0 = time.time()
        result = bpy.ops.fluid.bake_all()
        wall = time.time() - t0
    print(f"bake_fire: bake_all -> {result} in {wall:.1f} s", flush=True)

    data_dir = os.path.join(cache_dir, "data")
    missing = []
    paths = []
    for f in range(1, args.frames + 1):
        path = os.path.join(data_dir, f"fluid_data_{f:04d}.vdb")
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            missing.append(f)
        else:
            paths.append(path)
    found = sorted(glob.glob(os.path.join(data_dir, "*.vdb")))
    print(f"bake_fire: {len(found)} .vdb files in {data_dir}", flush=True)
    if missing:
        sys.exit(f"bake_fire.py: no .vdb file for frame(s) {missing} in {data_dir}")
    print(f"VDB {paths[-1]}", flush=True)


if __name__ == "__main__":
    main()
