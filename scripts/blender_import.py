"""Load a rend mesh sequence into Blender and render one frame with Cycles, headless.

    blender -b --factory-startup -P scripts/blender_import.py -- OUT_DIR \
        [--frame N] [--output PNG] [--samples S] [--width W] [--height H]

OUT_DIR is a `rend run ... --export ply` folder: meshes/frame_%04d.ply (vertex colours) and
run.json, whose resolved scene supplies the camera, the sun and the image size, so Blender
frames the shot as rend does. Every frame is imported and shown only on its own frame, so the
sequence plays on Blender's timeline. Prints `render_seconds=` and `coverage=` (the fraction of
pixels that differ from the background) for the benchmark and the test.
"""
import argparse
import json
import math
import pathlib
import sys
import time

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender_import.py")
    p.add_argument("out_dir", type=pathlib.Path)
    p.add_argument("--frame", type=int, default=1)
    p.add_argument("--output", type=pathlib.Path)
    p.add_argument("--samples", type=int, default=16)
    p.add_argument("--width", type=int)
    p.add_argument("--height", type=int)
    return p.parse_args(argv)


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)


def vertex_colour_material():
    mat = bpy.data.materials.new("rend_membrane")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    colour = nodes.new("ShaderNodeVertexColor")
    links.new(colour.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = 0.5
    return mat


def import_sequence(mesh_dir, material):
    frames = sorted(mesh_dir.glob("frame_*.ply"))
    if not frames:
        sys.exit(f"blender_import: no meshes/frame_*.ply in {mesh_dir}")
    for path in frames:
        number = int(path.stem.split("_")[1])
        bpy.ops.import_mesh.ply(filepath=str(path))
        obj = bpy.context.selected_objects[0]
        obj.data.materials.append(material)
        # Visible on its own frame only: keyframe the visibility around it.
        for frame, hidden in ((number - 1, True), (number, False), (number + 1, True)):
            obj.hide_render = obj.hide_viewport = hidden
            obj.keyframe_insert("hide_render", frame=frame)
            obj.keyframe_insert("hide_viewport", frame=frame)
    return len(frames)


def add_camera(cam):
    position = Vector(cam.get("position", [0.0, -4.0, 3.0]))
    target = Vector(cam.get("look_at", [0.0, 0.0, 0.0]))
    data = bpy.data.cameras.new("rend_camera")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(cam.get("fov", 40.0))
    obj = bpy.data.objects.new("rend_camera", data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = position
    obj.rotation_euler = (target - position).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = obj


def add_lights(light, background):
    data = bpy.data.lights.new("rend_sun", type="SUN")
    data.energy = 3.0 * light.get("intensity", 0.85)
    data.angle = math.radians(4.0)
    obj = bpy.data.objects.new("rend_sun", data)
    bpy.context.scene.collection.objects.link(obj)
    direction = Vector(light.get("direction", [-0.4, -0.5, 1.0])).normalized()
    obj.rotation_euler = direction.to_track_quat("Z", "Y").to_euler()
    world = bpy.data.worlds.new("rend_world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*background, 1.0)
    bpy.context.scene.world = world


def coverage(path, background):
    image = bpy.data.images.load(str(path))
    pixels = image.pixels[:]
    far = sum(1 for k in range(0, len(pixels), 4)
              if abs(pixels[k] - background[0]) + abs(pixels[k + 1] - background[1]) > 0.08)
    return far / (len(pixels) // 4)


def main():
    args = parse_args()
    scene_json = json.loads((args.out_dir / "run.json").read_text())["resolved_scene"]
    render = scene_json.get("render", {})
    background = render.get("background", [0.80, 0.84, 0.90])
    clear_scene()
    count = import_sequence(args.out_dir / "meshes", vertex_colour_material())
    add_camera(scene_json.get("camera", {}))
    add_lights(scene_json.get("light", {}), background)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = False
    scene.render.resolution_x = args.width or render.get("width", 960)
    scene.render.resolution_y = args.height or render.get("height", 540)
    scene.render.resolution_percentage = 100
    scene.frame_set(args.frame)
    output = args.output or args.out_dir / f"blender_{args.frame:04d}.png"
    scene.render.filepath = str(output)
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    print(f"blender_import: {count} meshes, frame {args.frame} -> {output}")
    print(f"render_seconds={seconds:.3f}")
    print(f"coverage={coverage(output, background):.3f}")


main()
