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
    p.add_argument("--save", type=pathlib.Path, help="write the shot to this .blend")
    p.add_argument("--volume", action="store_true",
                   help="render the vdb/ sequence (its density grid) instead of the meshes")
    p.add_argument("--motion-blur", action="store_true",
                   help="Cycles' motion blur from the velocity attribute")
    p.add_argument("--no-render", action="store_true", help="import (and save) only")
    return p.parse_args(argv)
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
    colour.layer_name = "Col"
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


PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4",
             "uint": "<u4", "float": "<f4", "double": "<f8"}


def read_ply(path):
    """rend's binary little-endian PLY: the vertex table as a numpy record array, and the
    triangles as an (M, 3) index array. rend writes triangles only."""
    import numpy
    with open(path, "rb") as f:
        lines = []
        while not lines or lines[-1] != "end_header":
            line = f.readline()
            if not line:
                sys.exit(f"blender_import: {path}: no end_header")
            lines.append(line.decode("ascii").strip())
        body = f.read()
    if "format binary_little_endian 1.0" not in lines:
        sys.exit(f"blender_import: {path}: not a binary little-endian PLY written by rend")
    fields, counts, element = [], {}, None
    for line in lines:
        words = line.split()
        if words[0] == "element":
            element = words[1]
            counts[element] = int(words[2])
        elif words[0] == "property" and element == "vertex":
            fields.append((words[2], PLY_TYPES[words[1]]))
    vertices = numpy.frombuffer(body, numpy.dtype(fields), count=counts["vertex"])
    faces = numpy.frombuffer(body, numpy.dtype([("n", "u1"), ("v", "<u4", 3)]),
                             count=counts.get("face", 0), offset=vertices.nbytes)
    if len(faces) and (faces["n"] != 3).any():
        sys.exit(f"blender_import: {path}: a face that is not a triangle")
    return vertices, faces["v"].astype(numpy.int64)


def add_point_attribute(mesh, name, kind, values):
    attribute = mesh.attributes.new(name, kind, "POINT")
    attribute.data.foreach_set("vector" if kind == "FLOAT_VECTOR" else "value",
                               values.ravel())


def frame_mesh(path, number):
    """One frame as a mesh: rend's normals as custom split normals, the colour, the rest UV,
    and every per-point value of the PLY as a named attribute (id, velocity in m/s for
    Cycles' motion blur, theta, damage, rest)."""
    import numpy
    vertices, triangles = read_ply(path)
    names = vertices.dtype.names
    column = lambda *keys: numpy.stack([vertices[k] for k in keys], axis=1).astype(numpy.float32)
    mesh = bpy.data.meshes.new(f"rend_frame_{number:04d}")
    mesh.use_fake_user = True  # kept in a saved .blend while another frame is shown
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", column("x", "y", "z").ravel())
    mesh.loops.add(3 * len(triangles))
    mesh.loops.foreach_set("vertex_index", triangles.ravel())
    mesh.polygons.add(len(triangles))
    mesh.polygons.foreach_set("loop_start", numpy.arange(0, 3 * len(triangles), 3))
    mesh.polygons.foreach_set("loop_total", numpy.full(len(triangles), 3))
    mesh.polygons.foreach_set("use_smooth", numpy.ones(len(triangles), dtype=bool))
    mesh.update(calc_edges=True)
    if "nx" in names:
        mesh.use_auto_smooth = True
        mesh.normals_split_custom_set_from_vertices(column("nx", "ny", "nz"))
    if "red" in names:
        rgba = numpy.ones((len(vertices), 4), numpy.float32)
        rgba[:, :3] = column("red", "green", "blue") / 255.0
        colours = mesh.color_attributes.new("Col", "BYTE_COLOR", "POINT")
        colours.data.foreach_set("color_srgb", rgba.ravel())
    if "s" in names:
        uv = mesh.uv_layers.new(name="rest_uv")
        uv.data.foreach_set("uv", column("s", "t")[triangles.ravel()].ravel())
    if "id" in names:
        add_point_attribute(mesh, "id", "INT", vertices["id"].astype(numpy.int32))
    if "vx" in names:
        add_point_attribute(mesh, "velocity", "FLOAT_VECTOR", column("vx", "vy", "vz"))
    for name in ("theta", "damage"):
        if name in names:
            add_point_attribute(mesh, name, "FLOAT", vertices[name].astype(numpy.float32))
    if "rest_x" in names:
        add_point_attribute(mesh, "rest", "FLOAT_VECTOR", column("rest_x", "rest_y", "rest_z"))
    return mesh


# Saved into the .blend as a registered text block, so that the sheet follows the timeline
# there too (Blender runs it on load when the file's scripts are trusted).
FRAME_HANDLER = '''
import bpy


def rend_show_frame(scene, depsgraph=None):
    """Puts the mesh of the latest rend frame at or before the current frame on the sheet."""
    sheet = bpy.data.objects.get("rend_sheet")
    if sheet is None:
        return
    frames = list(sheet["rend_frames"])
    shown = frames[0]
    for number in frames:
        if number <= scene.frame_current:
            shown = number
    mesh = bpy.data.meshes.get("rend_frame_%04d" % shown)
    if mesh is not None and sheet.data != mesh:
        sheet.data = mesh


for handler in list(bpy.app.handlers.frame_change_pre):
    if getattr(handler, "__name__", "") == "rend_show_frame":
        bpy.app.handlers.frame_change_pre.remove(handler)
bpy.app.handlers.frame_change_pre.append(rend_show_frame)
'''


def import_sequence(mesh_dir, material):
    """Every meshes/frame_NNNN.ply as one object, rend_sheet, whose mesh is that frame's on
    Blender's frame NNNN. Returns the frame numbers ([] without meshes)."""
    paths = sorted(mesh_dir.glob("frame_*.ply"))
    if not paths:
        return []
    numbers = [int(path.stem.split("_")[1]) for path in paths]
    for path, number in zip(paths, numbers):
        frame_mesh(path, number).materials.append(material)
    sheet = bpy.data.objects.new("rend_sheet", bpy.data.meshes[f"rend_frame_{numbers[0]:04d}"])
    sheet["rend_frames"] = numbers
    bpy.context.scene.collection.objects.link(sheet)
    text = bpy.data.texts.new("rend_frames.py")
    text.write(FRAME_HANDLER)
    text.use_module = True
    exec(compile(FRAME_HANDLER, "rend_frames.py", "exec"), {"__name__": "rend_frames"})
    return numbers


def import_volumes(vdb_dir, thickness=0.01):
    """vdb/frame_NNNN.vdb as one volume object, rend_volume, showing file NNNN on Blender's
    frame NNNN (Blender's importer would start any sequence on frame 1), shaded by its
    density grid, dense enough that light crossing the sheet's `thickness` (run.json's
    vdb.thickness) is mostly stopped. Returns the frame numbers, or [] without a vdb folder."""
    paths = sorted(vdb_dir.glob("frame_*.vdb")) if vdb_dir.is_dir() else []
    if not paths:
        return []
    numbers = [int(path.stem.split("_")[1]) for path in paths]
    volume = bpy.data.volumes.new("rend_volume")
    volume.filepath = str(paths[0])
    volume.is_sequence = True
    # File number = Blender frame - frame_start + 1 + frame_offset, within the duration.
    volume.frame_start = 1
    volume.frame_offset = 0
    volume.frame_duration = numbers[-1]
    volume.sequence_mode = "CLIP"
    mat = bpy.data.materials.new("rend_volume")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    shader = nodes.new("ShaderNodeVolumePrincipled")
    shader.inputs["Density"].default_value = 3.0 / thickness  # an optical depth of 3
    mat.node_tree.links.new(shader.outputs["Volume"], nodes["Material Output"].inputs["Volume"])
    volume.materials.append(mat)
    obj = bpy.data.objects.new("rend_volume", volume)
    bpy.context.scene.collection.objects.link(obj)
    return numbers


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


def loose_parts(mesh):
    """The mesh's connected pieces of faces, as Blender's 'Separate by loose parts' finds."""
    parent = list(range(len(mesh.vertices)))

    def root(v):
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for edge in mesh.edges:
        a, b = root(edge.vertices[0]), root(edge.vertices[1])
        parent[a] = b
    used = {v for poly in mesh.polygons for v in poly.vertices}
    return len({root(v) for v in used})


def main():
    args = parse_args()
    run = json.loads((args.out_dir / "run.json").read_text())
    scene_json = run["resolved_scene"]
    render = scene_json.get("render", {})
    background = render.get("background", [0.80, 0.84, 0.90])
    clear_scene()
    # "shading" is the material as rend resolved it (the look's preset under the scene's keys);
    # the resolved scene alone lacks the look's defaults.
    numbers = import_sequence(args.out_dir / "meshes",
                              vertex_colour_material(run.get("shading", render)))
    volumes = import_volumes(args.out_dir / "vdb", (run.get("vdb") or {}).get("thickness", 0.01))
    if args.volume and not volumes:
        sys.exit(f"blender_import: --volume, but no vdb/frame_*.vdb in {args.out_dir}")
    if not numbers and not args.volume:
        sys.exit(f"blender_import: no meshes/frame_*.ply in {args.out_dir} (--export ply), "
                 "and no --volume")
    if numbers:
        bpy.data.objects["rend_sheet"].hide_render = args.volume
    if volumes:
        bpy.data.objects["rend_volume"].hide_render = not args.volume
    numbers = numbers or volumes
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
    scene.frame_start, scene.frame_end = numbers[0], numbers[-1]
    scene.render.fps = int(scene_json.get("time", {}).get("fps", 24))
    scene.render.use_motion_blur = args.motion_blur
    scene.frame_set(args.frame)
    if args.save:
        bpy.ops.wm.save_as_mainfile(filepath=str(args.save.resolve()))
        print(f"blender_import: saved {args.save}")
    if args.no_render:
        return
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
    print(f"blender_import: {len(numbers)} frames, frame {args.frame} -> {output}")
    print(f"render_seconds={seconds:.3f}")
    print(f"coverage={coverage(output, background):.3f}")


if __name__ == "__main__":
    main()
