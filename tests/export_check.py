#!/usr/bin/env python3
"""Reads one frame's PLY, OBJ and GLB as rend wrote them, with Python's standard library only,
and checks that they agree: the same vertices in the same order, the same triangles (so the
same loose parts), and every per-point value each format carries equal to the PLY's.

    python3 tests/export_check.py MESH_DIR FRAME PARTICLES [MIN_PARTS [theta]]

PARTICLES: the run's particle count (vertex i < PARTICLES has id i). MIN_PARTS: the loose parts
the frame must have at least (2 for a torn frame). Prints one line per check; exit 1 on a
failure. With `theta`, the frame must carry theta.
"""
import json
import pathlib
import struct
import sys

PLY_TYPES = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I",
             "float": "f", "double": "d"}
failures = []


def check(ok, what):
    print(f"export_check: {'ok' if ok else 'FAILED'}: {what}")
    if not ok:
        failures.append(what)


def read_ply(path):
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    names, fmt, counts = [], "<", {}
    for line in data[:end].decode("ascii").splitlines():
        words = line.split()
        if words[0] == "element":
            counts[words[1]] = int(words[2])
        elif words[0] == "property" and words[1] != "list":
            names.append(words[2])
            fmt += PLY_TYPES[words[1]]
    size = struct.calcsize(fmt)
    n = counts["vertex"]
    rows = [struct.unpack_from(fmt, data, end + k * size) for k in range(n)]
    columns = {name: [row[i] for row in rows] for i, name in enumerate(names)}
    offset, faces = end + n * size, []
    for _ in range(counts["face"]):
        faces.append(struct.unpack_from("<BIII", data, offset)[1:])
        offset += 13
    return columns, faces


def read_obj(path):
    v, vt, vn, faces, shared = [], [], [], [], True
    for line in path.read_text().splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "v":
            v.append(tuple(f32(float(w)) for w in words[1:4]))
        elif words[0] == "vt":
            vt.append(tuple(f32(float(w)) for w in words[1:3]))
        elif words[0] == "vn":
            vn.append(tuple(f32(float(w)) for w in words[1:4]))
        elif words[0] == "f":
            corners = [tuple(int(i) - 1 if i else None for i in w.split("/")) for w in words[1:]]
            shared = shared and all(len(set(c)) == 1 for c in corners)
            faces.append(tuple(c[0] for c in corners))
    check(shared, "OBJ f: every corner's v/vt/vn are one index")
    return v, vt, vn, faces


def read_glb(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<III", data, 0)
    check(magic == 0x46546C67 and version == 2 and length == len(data), "GLB header")
    json_length, _ = struct.unpack_from("<II", data, 12)
    gltf = json.loads(data[20:20 + json_length])
    bin_start = 20 + json_length + 8
    widths = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}

    def accessor(index):
        a = gltf["accessors"][index]
        view = gltf["bufferViews"][a["bufferView"]]
        width, code = widths[a["type"]], "I" if a["componentType"] == 5125 else "f"
        flat = struct.unpack_from(f"<{a['count'] * width}{code}", data,
                                  bin_start + view.get("byteOffset", 0) + a.get("byteOffset", 0))
        return [flat[k:k + width] if width > 1 else flat[k] for k in range(0, len(flat), width)]

    primitive = gltf["meshes"][0]["primitives"][0]
    attributes = {name: accessor(i) for name, i in primitive["attributes"].items()}
    indices = accessor(primitive["indices"])
    return attributes, [tuple(indices[k:k + 3]) for k in range(0, len(indices), 3)]


def loose_parts(n, faces):
    parent = list(range(n))

    def root(v):
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for a, b, c in faces:
        parent[root(a)] = root(b)
        parent[root(b)] = root(c)
    return len({root(v) for f in faces for v in f})


def y_up(vectors):
    """rend's z-up vectors in the y-up frame of the OBJ and the GLB: (x, y, z) -> (x, z, -y)."""
    return [(x, z, -y) for x, y, z in vectors]


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def main():
    mesh_dir, frame, particles = pathlib.Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    min_parts = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    stem = mesh_dir / f"frame_{frame:04d}"
    ply, ply_faces = read_ply(stem.with_suffix(".ply"))
    obj_v, obj_vt, obj_vn, obj_faces = read_obj(stem.with_suffix(".obj"))
    glb, glb_faces = read_glb(stem.with_suffix(".glb"))
    n = len(ply["x"])
    xyz = list(zip(ply["x"], ply["y"], ply["z"]))
    normals = list(zip(ply["nx"], ply["ny"], ply["nz"]))
    check(n > particles - 1, f"{n} vertices, the {particles} particles first")
    check(ply["id"][:particles] == list(range(particles)), "PLY id: vertex i is particle i")
    check(obj_v == y_up(xyz) and obj_vn == y_up(normals),
          "OBJ v and vn: the PLY's in order, y up")
    check(obj_vt == [(s, t) for s, t in zip(ply["s"], ply["t"])], "OBJ vt: the rest UV")
    check([tuple(p) for p in glb["POSITION"]] == y_up(xyz),
          "GLB POSITION: the PLY's in order, y up")
    check([tuple(p) for p in glb["NORMAL"]] == y_up(normals), "GLB NORMAL")
    check([tuple(p) for p in glb["TEXCOORD_0"]] ==
          [(s, f32(1 - t)) for s, t in zip(ply["s"], ply["t"])], "GLB TEXCOORD_0: the rest UV")
    check([int(i) for i in glb["_ID"]] == ply["id"], "GLB _ID = PLY id")
    check([tuple(v) for v in glb["_VELOCITY"]] == y_up(zip(ply["vx"], ply["vy"], ply["vz"])),
          "GLB _VELOCITY = PLY vx vy vz, y up")
    check(list(glb["_DAMAGE"]) == ply["damage"], "GLB _DAMAGE = PLY damage")
    check([tuple(v) for v in glb["_REST"]] == y_up(zip(ply["rest_x"], ply["rest_y"],
                                                        ply["rest_z"])), "GLB _REST = PLY rest, y up")
    if sys.argv[5:6] == ["theta"]:
        check("theta" in ply and "_THETA" in glb, "theta in the PLY and the GLB")
    if "theta" in ply:
        check(list(glb["_THETA"]) == ply["theta"], "GLB _THETA = PLY theta")
    check(ply_faces == obj_faces == glb_faces, f"the same {len(ply_faces)} triangles in all three")
    parts = [loose_parts(n, f) for f in (ply_faces, obj_faces, glb_faces)]
    check(len(set(parts)) == 1 and parts[0] >= min_parts,
          f"loose parts PLY {parts[0]}, OBJ {parts[1]}, GLB {parts[2]} (at least {min_parts})")
    sys.exit(1 if failures else 0)


main()
