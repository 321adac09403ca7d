"""Load a rend mesh sequence into Blender and render one frame with Cycles, headless.

    blender -b --factory-startup -P scripts/blender_import.py -- OUT_DIR \
        [--frame N] [--output PNG] [--samples S] [--width W] [--height H] \
        [--exr-dir DIR] [--reference]

OUT_DIR is a `rend run ... --export ply` folder: meshes/frame_%04d.ply (vertex colours) and
run.json, whose resolved scene supplies the camera, the sun and the image size, so Blender
frames the shot as rend does. Every frame is imported and shown only on its own frame, so the
sequence plays on Blender's timeline. Prints `render_seconds=` and `coverage=` (the fraction of
pixels that differ from the background) for the benchmark and the test.

The shot is rend's path-traced one as closely as Cycles allows: the material (conductor, film,
translucent or diffuse, as a Principled BSDF with rend's roughness, GGX alpha = roughness^2 in
both), the sun (strength pi * intensity, so a white Lambert sheet facing it has radiance
intensity, as in rend; angle = twice rend's sun_radius), the zenith-to-horizon sky gradient, the
ground plane, rend's max_depth as the bounce limit and its indirect clamp (4). No denoiser.

With --exr-dir, --samples takes a comma-separated list: each count is rendered in turn into
DIR/cycles_S.exr (linear RGB, before any view transform) and printed as
`cycles spp=S seconds=T`, T being bpy.ops.render.render alone (scene sync, BVH build and path
tracing; not Blender's start-up, the import or the file write). --reference turns Cycles'
adaptive sampling off (every pixel gets all samples) and uses another seed; otherwise Cycles
keeps its default adaptive sampling.
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
    p.add_argument("--samples", default="16", help="a count, or a comma list with --exr-dir")
    p.add_argument("--width", type=int)
    p.add_argument("--height", type=int)
    p.add_argument("--exr-dir", type=pathlib.Path)
    p.add_argument("--reference", action="store_true")
    return p.parse_args(argv)


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)


def vertex_colour_material(render):
    """rend's membrane material (render/EmbreeRenderer: Bsdf) as a Principled BSDF."""
    mat = bpy.data.materials.new("rend_membrane")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    colour = nodes.new("ShaderNodeVertexColor")
    links.new(colour.outputs["Color"], bsdf.inputs["Base Color"])
    kind = render.get("material", "diffuse")
    inputs = bsdf.inputs
    inputs["Roughness"].default_value = render.get("roughness", 0.35)
    transmission = render.get("transmission", 0.0)
    if kind == "conductor":
        inputs["Metallic"].default_value = 1.0
    elif kind == "film":
        inputs["IOR"].default_value = 1.5
        inputs["Transmission"].default_value = transmission
    elif kind == "translucent":
        inputs["Specular"].default_value = 0.0
        inputs["Roughness"].default_value = 1.0
        translucent = nodes.new("ShaderNodeBsdfTranslucent")
        links.new(colour.outputs["Color"], translucent.inputs["Color"])
        mix = nodes.new("ShaderNodeMixShader")
        mix.inputs["Fac"].default_value = transmission
        links.new(bsdf.outputs["BSDF"], mix.inputs[1])
        links.new(translucent.outputs["BSDF"], mix.inputs[2])
        links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])
    else:
        inputs["Specular"].default_value = 0.0
        inputs["Roughness"].default_value = 1.0
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
        # rend interpolates the exported vertex normals (a crack's two lips have their own
        # vertices, so this does not smooth across it).
        obj.data.polygons.foreach_set("use_smooth", [True] * len(obj.data.polygons))
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


def add_lights(light, render, background):
    data = bpy.data.lights.new("rend_sun", type="SUN")
    # Cycles' sun strength is irradiance; rend's is pi * colour * intensity.
    data.energy = math.pi * light.get("intensity", 0.85)
    data.color = light.get("color", [1.0, 1.0, 1.0])
    data.angle = math.radians(2.0 * render.get("sun_radius", 2.0))
    obj = bpy.data.objects.new("rend_sun", data)
    bpy.context.scene.collection.objects.link(obj)
    direction = Vector(light.get("direction", [-0.4, -0.5, 1.0])).normalized()
    obj.rotation_euler = direction.to_track_quat("Z", "Y").to_euler()
    world = bpy.data.worlds.new("rend_world")
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes["Background"].inputs["Color"].default_value = (*background, 1.0)
    if render.get("sky", True):
        # rend's sky: horizon + (zenith - horizon) * clamp(direction.z, 0, 1).
        coords = nodes.new("ShaderNodeTexCoord")
        split = nodes.new("ShaderNodeSeparateXYZ")
        mix = nodes.new("ShaderNodeMixRGB")
        mix.use_clamp = True
        mix.inputs["Color1"].default_value = (*render.get("sky_horizon", [0.85, 0.88, 0.92]), 1)
        mix.inputs["Color2"].default_value = (*render.get("sky_zenith", [0.35, 0.50, 0.80]), 1)
        clamp = nodes.new("ShaderNodeClamp")
        links.new(coords.outputs["Generated"], split.inputs["Vector"])
        links.new(split.outputs["Z"], clamp.inputs["Value"])
        links.new(clamp.outputs["Result"], mix.inputs["Fac"])
        links.new(mix.outputs["Color"], nodes["Background"].inputs["Color"])
        # Like rend, the smooth sky is found by BSDF sampling only: Cycles' default importance
        # map (1024 x 512, rebuilt per render) and its light samples cost 3x its render time
        # here and buy nothing on a gradient.
        world.cycles.sampling_method = "NONE"
    bpy.context.scene.world = world


def add_ground(render, sheet):
    """rend's analytic ground plane: a diffuse plane far larger than the shot."""
    if not render.get("ground", True):
        return
    height = render.get("ground_height", -0.5 * max(sheet.get("size", [1.0, 1.0])))
    bpy.ops.mesh.primitive_plane_add(size=2000.0, location=(0.0, 0.0, height))
    plane = bpy.context.active_object
    mat = bpy.data.materials.new("rend_ground")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*render.get("ground_color", [0.55, 0.55, 0.52]), 1)
    bsdf.inputs["Specular"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    plane.data.materials.append(mat)


def coverage(path, background):
    image = bpy.data.images.load(str(path))
    pixels = image.pixels[:]
    far = sum(1 for k in range(0, len(pixels), 4)
              if abs(pixels[k] - background[0]) + abs(pixels[k + 1] - background[1]) > 0.08)
    return far / (len(pixels) // 4)


def render_exr_series(scene, counts, exr_dir):
    """Renders each sample count into exr_dir/cycles_S.exr, printing the render time alone."""
    exr_dir.mkdir(parents=True, exist_ok=True)
    settings = scene.render.image_settings
    settings.color_mode = "RGB"
    for count in counts:
        scene.cycles.samples = count
        best, best_cpu = math.inf, math.inf
        # Short renders are repeated: on a shared machine the minimum is the honest figure.
        # CPU seconds (all threads) are printed too: robust when other jobs share the cores.
        for _ in range(3 if count <= 16 else 1):
            start, start_cpu = time.perf_counter(), time.process_time()
            bpy.ops.render.render()
            best = min(best, time.perf_counter() - start)
            best_cpu = min(best_cpu, time.process_time() - start_cpu)
        result = bpy.data.images["Render Result"]
        settings.file_format = "OPEN_EXR"
        result.save_render(str(exr_dir / f"cycles_{count}.exr"))
        settings.file_format = "PNG"
        result.save_render(str(exr_dir / f"cycles_{count}.png"))
        print(f"cycles spp={count} seconds={best:.4f} cpu={best_cpu:.4f}", flush=True)


def main():
    args = parse_args()
    run = json.loads((args.out_dir / "run.json").read_text())
    scene_json = run["resolved_scene"]
    render = scene_json.get("render", {})
    background = render.get("background", [0.80, 0.84, 0.90])
    clear_scene()
    # "shading" is the material as rend resolved it (the look's preset under the scene's keys);
    # the resolved scene alone lacks the look's defaults.
    count = import_sequence(args.out_dir / "meshes",
                            vertex_colour_material(run.get("shading", render)))
    add_camera(scene_json.get("camera", {}))
    add_lights(scene_json.get("light", {}), render, background)
    add_ground(render, scene_json.get("sheet", {}))
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = not args.reference
    # The reference's noise must be independent of the measured images': with one seed, Cycles'
    # first N samples of the reference would be those of the N-sample image.
    scene.cycles.seed = 1 if args.reference else 0
    depth = render.get("max_depth", 4)
    for bounces in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces"):
        setattr(scene.cycles, bounces, depth)
    scene.cycles.sample_clamp_indirect = 4.0  # rend's kIndirectClamp
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x = args.width or render.get("width", 960)
    scene.render.resolution_y = args.height or render.get("height", 540)
    scene.render.resolution_percentage = 100
    scene.frame_set(args.frame)
    counts = [int(c) for c in args.samples.split(",")]
    if args.exr_dir:
        render_exr_series(scene, counts, args.exr_dir)
        return
    scene.cycles.samples = counts[0]
    output = args.output or args.out_dir / f"blender_{args.frame:04d}.png"
    scene.render.filepath = str(output)
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    print(f"blender_import: {count} meshes, frame {args.frame} -> {output}")
    print(f"render_seconds={seconds:.3f}")
    print(f"coverage={coverage(output, background):.3f}")


main()
