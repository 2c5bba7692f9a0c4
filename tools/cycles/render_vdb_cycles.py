"""Render a VDB file with Blender Cycles through a Principled Volume, for comparison with pyrolume.

Needs Debian's `blender` package (Blender 3.4); pyrolume itself does not depend on Blender.
Run headless:

  blender -b --factory-startup -P render_vdb_cycles.py -- VDB --out OUT.png [OUT.exr] \
      --cam-pos X Y Z --look-at X Y Z [options]

`... -- --help` lists the options.

Scene, built from empty factory settings: a black world; one Volume object that reads
the VDB file in place (grids in their own transform, object at the origin); a Principled
Volume material with Blender's defaults except for the density attribute, Density,
Color (grey), temperature attribute, Temperature and Blackbody Intensity given here; a pinhole camera with a
vertical field of view. Cycles on the CPU with a fixed seed, adaptive sampling, denoising
and clamping off, a Box pixel filter 1 pixel wide, full-precision volume grids, linear
interpolation, automatic step size.

Cycles' Principled Volume glows, when Blackbody Intensity > 0, with the luminance-
normalised blackbody colour of T = Temperature * max(attribute, 0) times
Blackbody Intensity * 5.670373e-8 * 1e-6 / pi * T^4 per unit length (not multiplied by
density), and absorbs with density * Density.

Outputs: each --out path is written from the same render. ".png" = 8-bit sRGB with the
--view transform (look None, exposure 0, gamma 1); ".exr" = 32-bit float scene-linear
Rec.709 RGBA (no view transform). The last line printed is RENDER_TIME_S <seconds>.
"""

import argparse
import math
import os
import sys
import time

import bpy
import mathutils


def set_display_view(scene, view):
    """Display sRGB through `view`, look None, exposure 0, gamma 1, no curves: how PNGs
    here are written (tools/cycles/view_exr_blender.py shares it)."""
    scene.display_settings.display_device = "sRGB"
    vs = scene.view_settings
    vs.view_transform = view
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    vs.use_curve_mapping = False


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="render_vdb_cycles.py",
                                description="Render a VDB file with Blender Cycles (Principled Volume).")
    p.add_argument("vdb", help="OpenVDB file (read in place)")
    p.add_argument("--out", nargs="+", required=True,
                   help="output path(s): .png = view-transformed 8-bit sRGB, .exr = linear float")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=480)
    p.add_argument("--spp", type=int, default=64, help="samples per pixel")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=0, help="CPU threads (0 = all)")
    p.add_argument("--volume-bounces", type=int, default=0, choices=range(0, 9),
                   help="Cycles light paths: volume bounces")
    p.add_argument("--density-attr", default="density", help="Density Attribute (grid name)")
    p.add_argument("--temp-attr", default="heat", help="Temperature Attribute (grid name)")
    p.add_argument("--density", type=float, default=1.0, help="Density socket (multiplies the attribute)")
    p.add_argument("--color", type=float, default=0.5,
                   help="Color socket, grey: with the default black Absorption Color, scattering = "
                        "density * color and absorption = density * (1 - color), so the albedo is color")
    p.add_argument("--temperature", type=float, default=1000.0, help="Temperature socket, K")
    p.add_argument("--blackbody", type=float, default=1.0, help="Blackbody Intensity")
    p.add_argument("--cam-pos", type=float, nargs=3, required=True, metavar=("X", "Y", "Z"))
    p.add_argument("--look-at", type=float, nargs=3, required=True, metavar=("X", "Y", "Z"))
    p.add_argument("--up", type=float, nargs=3, default=[0.0, 0.0, 1.0], metavar=("X", "Y", "Z"))
    p.add_argument("--fov", type=float, default=40.0, help="vertical field of view, degrees")
    p.add_argument("--view", default="Standard", choices=["Standard", "Filmic"],
                   help="view transform of .png outputs")
    return p.parse_args(argv)


def build_material(a):
    mat = bpy.data.materials.new("PrincipledVolume")
    mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")  # Blender's defaults for every other input
    nt.links.new(pv.outputs["Volume"], out.inputs["Volume"])
    pv.inputs["Density Attribute"].default_value = a.density_attr
    pv.inputs["Temperature Attribute"].default_value = a.temp_attr
    pv.inputs["Density"].default_value = a.density
    pv.inputs["Color"].default_value = (a.color, a.color, a.color, 1.0)
    pv.inputs["Temperature"].default_value = a.temperature
    pv.inputs["Blackbody Intensity"].default_value = a.blackbody
    mat.cycles.volume_interpolation = "LINEAR"
    mat.cycles.homogeneous_volume = False
    return mat


def look_at_matrix(pos, target, up):
    """Camera-to-world matrix: the camera looks down its -Z axis, +Y up, +X = forward x up."""
    pos, target, up = (mathutils.Vector(v) for v in (pos, target, up))
    fwd = (target - pos).normalized()
    right = fwd.cross(up).normalized()
    cam_up = right.cross(fwd).normalized()
    m = mathutils.Matrix((right, cam_up, -fwd)).transposed().to_4x4()
    m.translation = pos
    return m


def main():
    a = parse_args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene

    world = bpy.data.worlds.new("World")
    world.use_nodes = False
    world.color = (0.0, 0.0, 0.0)
    scene.world = world

    vol = bpy.data.volumes.new(os.path.basename(a.vdb))
    vol.filepath = os.path.abspath(a.vdb)
    vol.grids.load()
    if vol.grids.error_message:
        raise SystemExit("VDB load error: " + vol.grids.error_message)
    names = [g.name for g in vol.grids]
    for attr in (a.density_attr, a.temp_attr):
        if attr and attr not in names:
            raise SystemExit("no grid %r in %s (grids: %s)" % (attr, a.vdb, ", ".join(names)))
    vol.render.precision = "FULL"
    vol.render.space = "OBJECT"
    vol.render.step_size = 0.0  # automatic: the voxel size
    ob = bpy.data.objects.new("VDB", vol)
    scene.collection.objects.link(ob)
    vol.materials.append(build_material(a))

    cam_data = bpy.data.cameras.new("Camera")
    cam_data.type = "PERSP"
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(a.fov)
    cam_data.clip_start = 0.01
    cam_data.clip_end = 1.0e6
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.matrix_world = look_at_matrix(a.cam_pos, a.look_at, a.up)

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = a.width, a.height, 100
    r.film_transparent = False
    r.threads_mode = "FIXED" if a.threads > 0 else "AUTO"
    if a.threads > 0:
        r.threads = a.threads
    r.use_motion_blur = False
    r.dither_intensity = 0.0
    c = scene.cycles
    c.device = "CPU"
    c.samples = a.spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.seed = a.seed
    c.use_animated_seed = False
    c.volume_bounces = a.volume_bounces
    c.max_bounces = max(12, a.volume_bounces)
    c.film_exposure = 1.0
    scene.view_layers[0].cycles.use_denoising = False

    set_display_view(scene, a.view)

    t0 = time.time()
    bpy.ops.render.render(write_still=False)
    t_render = time.time() - t0

    res = bpy.data.images["Render Result"]
    ims = r.image_settings
    for path in a.out:
        path = os.path.abspath(path)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        ext = os.path.splitext(path)[1].lower()
        if ext == ".png":
            ims.file_format, ims.color_mode, ims.color_depth = "PNG", "RGB", "8"
        elif ext == ".exr":
            ims.file_format, ims.color_mode, ims.color_depth = "OPEN_EXR", "RGBA", "32"
            ims.exr_codec = "ZIP"
        else:
            raise SystemExit("unsupported output extension (.png or .exr): " + path)
        res.save_render(filepath=path, scene=scene)
        print("wrote", path)
    print("RENDER_TIME_S %.3f" % t_render)


if __name__ == "__main__":
    main()
