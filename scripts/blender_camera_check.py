#!/usr/bin/env python3
"""Checks the guide's Blender script against the renderer, in Blender itself.

For each camera below it renders a frame with `fractal-sdf render -o
x.exr --aov position --camera-json x.json`, builds a camera from the JSON
file with the script in docs/guide/outputs.md (run as it is printed
there), and projects the world position of every pixel the renderer drew
through Blender's own camera (`world_to_camera_view`). Each must land in
the pixel it was drawn at. Prints the largest distance, in pixels, per
camera; exits 1 if any is half a pixel or more.

Then it meshes a sphere away from the origin as OBJ, imports it with
Blender's OBJ importer as it comes, and checks that the sphere's centre
lands where the script's quarter turn puts it.

Not part of `make test`: it needs Blender as a Python module
(`pip install bpy`, about 400 MB) and OpenImageIO's `oiiotool`.

    python3 scripts/blender_camera_check.py [path/to/fractal-sdf]
"""

import json
import os
import re
import subprocess
import sys
import tempfile

import bpy
import mathutils
from bpy_extras.object_utils import world_to_camera_view

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BINARY = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "target/release/fractal-sdf")

# A scene file per camera: a floor, a sphere and a box, as in the tests.
SCENE = """(
    version: 1,
    geometry: Union([
        Plane(normal: (0.0, 1.0, 0.0), offset: 0.0),
        Translate(offset: (-0.6, 0.5, 0.0), child: Sphere(radius: 0.5)),
        Translate(offset: (0.6, 0.35, 0.1), child: Cuboid(half_extents: (0.35, 0.35, 0.35))),
    ]),
    camera: (%s),
)"""

CAMERAS = {
    "perspective": "position: (0.0, 1.4, 3.2), target: (0.0, 0.35, 0.0), projection: Perspective(fov_y_degrees: 40.0)",
    "wide portrait": "position: (2.0, 2.5, 2.5), target: (0.0, 0.2, 0.0), projection: Perspective(fov_y_degrees: 70.0)",
    "shifted": "position: (-1.0, 1.0, 3.0), target: (0.0, 0.3, 0.0), projection: Perspective(fov_y_degrees: 50.0), shift: (0.3, -0.2)",
    "orthographic": "position: (1.5, 2.0, 3.0), target: (0.0, 0.3, 0.0), projection: Orthographic(height: 2.5)",
}
SIZES = {"wide portrait": (48, 80)}


def guide_script():
    """The Python block of docs/guide/outputs.md, as printed."""
    text = open(os.path.join(ROOT, "docs/guide/outputs.md")).read()
    return re.search(r"```python\n(.*?)```", text, re.S).group(1)


def drawn_points(exr, width, height):
    """(pixel x, pixel y, world point) of every pixel whose ray hit."""
    info = subprocess.run(["oiiotool", "--info", "-v", exr], capture_output=True, text=True, check=True).stdout
    channels = [c.strip() for c in re.search(r"channel list: (.*)", info).group(1).split(",")]
    at = [channels.index(f"position.{c}") for c in "XYZ"]
    depth = channels.index("depth.Z")
    dump = subprocess.run(["oiiotool", "--dumpdata", exr], capture_output=True, text=True, check=True).stdout
    points = []
    for line in dump.splitlines():
        m = re.match(r"\s*Pixel \((\d+), (\d+)\): (.*)", line)
        if not m:
            continue
        values = [float(v) for v in m.group(3).split()]
        if values[depth] == float("inf"):
            continue
        points.append((int(m.group(1)), int(m.group(2)), [values[i] for i in at]))
    return points


def main():
    namespace = {}
    exec(guide_script(), namespace)
    worst_overall = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for name, camera in CAMERAS.items():
            width, height = SIZES.get(name, (96, 64))
            scene = os.path.join(tmp, "scene.ron")
            open(scene, "w").write(SCENE % camera)
            exr, cam_json = os.path.join(tmp, "frame.exr"), os.path.join(tmp, "camera.json")
            subprocess.run(
                [BINARY, "render", scene, "--preset", "preview", "--size", f"{width}x{height}",
                 "-o", exr, "--aov", "position,depth", "--camera-json", cam_json],
                check=True, capture_output=True)
            bpy.ops.wm.read_factory_settings(use_empty=True)
            obj = namespace["fractal_sdf_camera"](cam_json)
            blender_scene = bpy.context.scene
            blender_scene.camera = obj
            y_up_to_z_up = mathutils.Matrix.Rotation(1.5707963267948966, 4, "X")
            worst = 0.0
            points = drawn_points(exr, width, height)
            for x, y, p in points:
                v = world_to_camera_view(blender_scene, obj, y_up_to_z_up @ mathutils.Vector(p))
                px, py = v.x * width, (1.0 - v.y) * height
                worst = max(worst, abs(px - (x + 0.5)), abs(py - (y + 0.5)))
            print(f"{name:14} {width}x{height}: {len(points)} drawn pixels, largest distance {worst:.2e} px")
            worst_overall = max(worst_overall, worst)
    mesh_ok = check_mesh()
    sys.exit(0 if worst_overall < 0.5 and mesh_ok else 1)


def check_mesh():
    """A sphere at (1, 2, -0.5) meshed as OBJ and imported as it comes."""
    centre = mathutils.Vector((1.0, 2.0, -0.5))
    with tempfile.TemporaryDirectory() as tmp:
        obj_path = os.path.join(tmp, "sphere.obj")
        subprocess.run(
            [BINARY, "mesh", "--formula", "length(p - vec3(1, 2, -0.5)) - 0.5",
             "--resolution", "48", "--cpu", "-o", obj_path],
            check=True, capture_output=True)
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.wm.obj_import(filepath=obj_path)
        mesh = bpy.context.selected_objects[0]
        points = [mesh.matrix_world @ v.co for v in mesh.data.vertices]
        found = sum(points, mathutils.Vector()) / len(points)
    want = mathutils.Matrix.Rotation(1.5707963267948966, 4, "X") @ centre
    error = (found - want).length
    print(f"mesh: sphere centre at {tuple(round(c, 4) for c in found)}, "
          f"the script's frame puts it at {tuple(round(c, 4) for c in want)} ({error:.4f} apart)")
    return error < 0.01


if __name__ == "__main__":
    main()
