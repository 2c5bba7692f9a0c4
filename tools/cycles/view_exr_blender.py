"""Show a linear EXR through one of Blender's view transforms: what Blender would display
and save for that image. Used by tools/cycles/compare_views.

Needs Debian's `blender` package (Blender 3.4); pyrolume itself does not depend on Blender.
Run headless:

  blender -b --factory-startup -P view_exr_blender.py -- IN.exr [--png OUT.png] \
      [--view Filmic] [--npy OUT.npy]

The image is loaded as scene-linear Rec.709 ("Linear" in Blender 3.4), its alpha kept
apart from the colour ("Channel Packed": no premultiplication either way), and saved with
Image.save_render through the scene's display settings: display sRGB, view --view
(Blender 3.4's factory default is Filmic), look None, exposure 0, gamma 1, no curves,
dither 0, as an 8-bit RGB PNG. --npy also writes the linear pixels as Blender read them
(float32, rows top to bottom, RGBA), for tools without an EXR reader.
"""

import argparse
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from render_vdb_cycles import set_display_view  # noqa: E402  (the same view settings as Cycles' PNGs)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="view_exr_blender.py",
                                description="Save a linear EXR through a Blender view transform as 8-bit PNG.")
    p.add_argument("exr", help="linear EXR (scene-linear Rec.709)")
    p.add_argument("--png", help="the PNG to write through the view")
    p.add_argument("--view", default="Filmic", choices=["Filmic", "Standard"],
                   help="view transform (default Filmic, Blender 3.4's default)")
    p.add_argument("--npy", help="also write the linear RGBA pixels, rows top to bottom, as a .npy file")
    a = p.parse_args(argv)
    if not a.png and not a.npy:
        p.error("nothing to write: give --png and/or --npy")
    return a


def main():
    a = parse_args()
    img = bpy.data.images.load(os.path.abspath(a.exr))
    img.colorspace_settings.name = "Linear"
    img.alpha_mode = "CHANNEL_PACKED"
    w, h = img.size
    if a.npy:
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
        np.save(a.npy, px.reshape(h, w, 4)[::-1].copy())  # Blender's rows run bottom to top
        print("wrote", a.npy)
    if a.png:
        scene = bpy.context.scene
        scene.render.dither_intensity = 0.0
        s = scene.render.image_settings
        s.file_format, s.color_mode, s.color_depth = "PNG", "RGB", "8"
        set_display_view(scene, a.view)
        img.save_render(os.path.abspath(a.png), scene=scene)
        print("wrote", a.png, "through", a.view)


if __name__ == "__main__":
    main()
