"""Run inside Blender by tests/blender_test.sh: rend's exports of one torn frame, read back.

    blender -b --factory-startup --python-exit-code 1 -P tests/blender_check.py -- OUT_DIR N [P]

- scripts/blender_import.py: one object whose mesh on frame N is frame N's, and every per-point
  value of the PLY (id, velocity, theta, damage, rest, the rest UV, the normals) read back
  equal from the mesh's attributes;
- Blender's own importers (PLY, OBJ, glTF): the same vertices and loose parts in every format,
  and the normals kept where the importer can (OBJ and glTF; 3.4's PLY importer has none); at
  least P loose parts (default 1: P = 2 checks a torn frame);
- the VDB sequence: file N on frame N, with its density grid.
Prints `blender_check: ...` lines; any failed check raises (exit status 1).
"""
import importlib.util
import pathlib
import sys

import bpy
import numpy

argv = sys.argv[sys.argv.index("--") + 1:]
out_dir, frame = pathlib.Path(argv[0]), int(argv[1])
min_parts = int(argv[2]) if len(argv) > 2 else 1
root = pathlib.Path(__file__).resolve().parent.parent
spec = importlib.util.spec_from_file_location("blender_import", root / "scripts/blender_import.py")
rend = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rend)
ply_path = out_dir / "meshes" / f"frame_{frame:04d}.ply"
vertices, triangles = rend.read_ply(ply_path)
failures = []


def check(ok, what):
    print(f"blender_check: {'ok' if ok else 'FAILED'}: {what}", flush=True)
    if not ok:
        failures.append(what)


def clear():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)


def column(*keys):
    return numpy.stack([vertices[k] for k in keys], axis=1).astype(numpy.float32)


def attribute(mesh, name, width):
    data = mesh.attributes[name].data
    kind = "vector" if width == 3 else "value"
    out = numpy.zeros(len(data) * width, numpy.int32 if name == "id" else numpy.float32)
    data.foreach_get(kind, out)
    return out.reshape(-1, width) if width == 3 else out


def check_own_import():
    clear()
    material = bpy.data.materials.new("m")
    numbers = rend.import_sequence(out_dir / "meshes", material)
    check(frame in numbers and len(numbers) > 1, f"{len(numbers)} frames imported")
    bpy.context.scene.frame_set(frame)
    sheets = [o for o in bpy.data.objects if o.type == "MESH"]
    check(len(sheets) == 1, f"one mesh object for {len(numbers)} frames ({len(sheets)})")
    mesh = sheets[0].data
    check(mesh.name == f"rend_frame_{frame:04d}", f"frame {frame} shows {mesh.name}")
    check(len(mesh.vertices) == len(vertices), f"{len(mesh.vertices)} vertices, as the PLY")
    check(numpy.array_equal(attribute(mesh, "id", 1), vertices["id"]), "id equal")
    for name, keys in (("velocity", ("vx", "vy", "vz")), ("rest", ("rest_x", "rest_y", "rest_z"))):
        check(numpy.array_equal(attribute(mesh, name, 3), column(*keys)), f"{name} equal")
    for name in ("damage", "theta"):
        if name in vertices.dtype.names:
            check(numpy.array_equal(attribute(mesh, name, 1), vertices[name]), f"{name} equal")
    uv = numpy.zeros(2 * len(mesh.loops), numpy.float32)
    mesh.uv_layers["rest_uv"].data.foreach_get("uv", uv)
    check(numpy.array_equal(uv.reshape(-1, 2), column("s", "t")[triangles.ravel()]),
          "rest UV equal")
    mesh.calc_normals_split()
    normals = numpy.zeros(3 * len(mesh.loops), numpy.float32)
    mesh.loops.foreach_get("normal", normals)
    error = numpy.abs(normals.reshape(-1, 3) - column("nx", "ny", "nz")[triangles.ravel()]).max()
    # Blender stores custom normals as two 16-bit factors in each corner's own frame: a few
    # thousandths is its rounding (a flat-shaded face would differ by tenths).
    check(error < 1e-2, f"normals kept (largest difference {error:.2g})")
    return rend.loose_parts(mesh)


def import_with_blender(path):
    clear()
    if path.suffix == ".ply":
        bpy.ops.import_mesh.ply(filepath=str(path))
    elif path.suffix == ".obj":
        bpy.ops.wm.obj_import(filepath=str(path))
    else:
        # The work-around for Debian's Blender 3.4 against Debian's numpy 1.24 (README).
        if not hasattr(numpy, "bool"):
            numpy.bool = bool
        bpy.ops.import_scene.gltf(filepath=str(path))
    objects = [o for o in bpy.data.objects if o.type == "MESH"]
    check(len(objects) == 1, f"{path.name}: one mesh ({len(objects)})")
    return objects[0]


def check_placed(suffix, obj):
    """Vertex i where the PLY has vertex i in Blender's world (the OBJ and the GLB are y up,
    and Blender's importers turn them back), and each corner's normal its vertex's in the PLY."""
    mesh = obj.data
    matrix = numpy.array(obj.matrix_world)
    local = numpy.zeros(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", local)
    world = local.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
    error = numpy.abs(world - column("x", "y", "z")).max()
    check(error < 1e-5, f"{suffix}: vertex i where the PLY has it (largest difference "
                        f"{error:.2g} m)")
    if suffix == "ply":
        return  # Blender 3.4's PLY importer reads no normals (README)
    mesh.calc_normals_split()
    corner = numpy.zeros(3 * len(mesh.loops))
    mesh.loops.foreach_get("normal", corner)
    index = numpy.zeros(len(mesh.loops), numpy.int64)
    mesh.loops.foreach_get("vertex_index", index)
    worst = numpy.abs(corner.reshape(-1, 3) @ matrix[:3, :3].T -
                      column("nx", "ny", "nz")[index]).max()
    check(worst < 1e-2, f"{suffix}: the normals kept (largest difference {worst:.2g})")


def check_formats(parts):
    counts = {"blender_import.py": parts}
    for suffix in ("ply", "obj", "glb"):
        obj = import_with_blender(ply_path.with_suffix("." + suffix))
        mesh = obj.data
        counts[suffix] = rend.loose_parts(mesh)
        check_placed(suffix, obj)
        check(len(mesh.vertices) == len(vertices),
              f"{suffix}: {len(mesh.vertices)} vertices, as the PLY's {len(vertices)}")
        if suffix != "ply":
            loops = numpy.zeros(len(mesh.loops), numpy.int64)
            mesh.loops.foreach_get("vertex_index", loops)
            uv = numpy.zeros(2 * len(mesh.loops), numpy.float32)
            mesh.uv_layers[0].data.foreach_get("uv", uv)
            error = numpy.abs(uv.reshape(-1, 2) - column("s", "t")[loops]).max()
            check(error < 1e-6, f"{suffix}: the rest UV (largest difference {error:.2g})")
    print(f"blender_check: loose parts {counts}")
    check(len(set(counts.values())) == 1, "the same loose parts in every format")
    check(parts >= min_parts, f"{parts} loose parts, at least {min_parts}")


def check_volume():
    clear()
    numbers = rend.import_volumes(out_dir / "vdb")
    check(frame in numbers, f"{len(numbers)} volumes imported")
    bpy.context.scene.frame_set(frame)
    grids = bpy.data.objects["rend_volume"].data.grids
    grids.load()
    name = pathlib.Path(grids.frame_filepath).name
    check(grids.frame == frame and name == f"frame_{frame:04d}.vdb",
          f"frame {frame} shows {name}")
    check("density" in [g.name for g in grids], "a density grid")


check_formats(check_own_import())
check_volume()
if failures:
    raise AssertionError(f"{len(failures)} checks failed: {failures}")
print("blender_check: all passed")
