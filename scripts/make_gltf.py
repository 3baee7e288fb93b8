#!/usr/bin/python3
"""Writes the shipped glTF scenes (docs/scene-format.md, "glTF").

  scenes/room/room.gltf, room.bin     the demo room (scenes/room/room.json with
                                      its OBJ, MTL and CSV files) as glTF 2.0
  scenes/gltf/textured.gltf (+ .bin, *.png)
                                      a small textured scene: base-colour,
                                      metallic-roughness, emissive and normal
                                      textures, a point and a spot light

The room is converted from the committed JSON scene, so the two load into the
same triangles (in the same order, quads split as tinyobjloader splits them),
normals, lights and camera; tests/test_gltf.cpp checks that. The materials
become their glTF metallic-roughness counterparts: MTL Kd -> baseColorFactor,
metallic 0, roughness sqrt(GGX alpha) where there is a specular lobe (1
without), Ke -> emissiveFactor with KHR_materials_emissive_strength, and
point lights (JSON or CSV) -> KHR_lights_punctual point lights with colour
scaled to a largest component of 1 and that component as the intensity.
Area lights (emissive materials) stay emissive materials.

Deterministic; Python standard library only.
  /usr/bin/python3 scripts/make_gltf.py [--root .]
"""

import argparse
import base64
import json
import math
import os
import struct
import sys
import zlib

FLOAT, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5123, 5125


def f32(x):
    """x rounded to a 32-bit float, as C++ float arithmetic rounds it."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


# -- OBJ / MTL / CSV, as far as the shipped scenes use them --------------------

def read_mtl(path):
    materials, current = {}, None
    for line in open(path, encoding="ascii"):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if words[0] == "newmtl":
            current = materials.setdefault(words[1], {"Kd": [0.0] * 3, "Ks": [0.0] * 3, "Ke": [0.0] * 3,
                                                      "Ns": 1.0, "Pr": 0.0})
        elif words[0] in ("Kd", "Ks", "Ke"):
            current[words[0]] = [float(w) for w in words[1:4]]
        elif words[0] in ("Ns", "Pr"):
            current[words[0]] = float(words[1])
    return materials


def split_quad(v, face):
    """tinyobjloader's split of a quad: along the shorter diagonal, in float."""
    p = [[f32(c) for c in v[i]] for i, _ in face]

    def sqr(a, b):
        d = [f32(p[b][k] - p[a][k]) for k in range(3)]
        return f32(f32(f32(d[0] * d[0]) + f32(d[1] * d[1])) + f32(d[2] * d[2]))
    if sqr(0, 2) < sqr(1, 3):
        return [[face[0], face[1], face[2]], [face[0], face[2], face[3]]]
    return [[face[0], face[1], face[3]], [face[1], face[2], face[3]]]


def read_obj(path):
    """Shapes in file order: (name, material name, triangles of (v, vn) corner
    indices), plus the vertex and normal lists and the mtllib."""
    v, vn, shapes, mtllib = [], [], [], None
    shape = None
    for line in open(path, encoding="ascii"):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if words[0] == "v":
            v.append([float(w) for w in words[1:4]])
        elif words[0] == "vn":
            vn.append([float(w) for w in words[1:4]])
        elif words[0] == "mtllib":
            mtllib = words[1]
        elif words[0] in ("o", "g"):
            shape = {"name": words[1], "material": None, "triangles": []}
            shapes.append(shape)
        elif words[0] == "usemtl":
            shape["material"] = words[1]
        elif words[0] == "f":
            if shape is None:
                shape = {"name": "", "material": None, "triangles": []}
                shapes.append(shape)
            face = []
            for w in words[1:]:
                parts = w.split("/")
                face.append((int(parts[0]) - 1, int(parts[2]) - 1 if len(parts) > 2 and parts[2] else None))
            if len(face) == 3:
                shape["triangles"].append(face)
            elif len(face) == 4:
                shape["triangles"] += split_quad(v, face)
            else:
                raise SystemExit("%s: only triangles and quads are converted" % path)
    return v, vn, shapes, mtllib


def read_points_csv(path):
    lights = []
    for line in open(path, encoding="ascii"):
        line = line.strip()
        if not line or line.startswith("#") or line.startswith("x"):
            continue
        x, y, z, r, g, b = (float(w) for w in line.split(","))
        lights.append(((x, y, z), (r, g, b)))
    return lights


# -- glTF building ---------------------------------------------------------------

def quat_from_matrix(m):
    """Unit quaternion (x, y, z, w) of a rotation matrix given as rows."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0, 0.0, 0.0, (m[k][j] - m[j][k]) / s]
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    return q


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def quat_euler_xyz(degrees):
    """Rotation about X, then Y, then Z (the scene JSON's rotate_degrees)."""
    q = [0.0, 0.0, 0.0, 1.0]
    for axis in (2, 1, 0):  # q = qz * qy * qx
        half = math.radians(degrees[axis]) / 2.0
        r = [0.0, 0.0, 0.0, math.cos(half)]
        r[axis] = math.sin(half)
        q = quat_mul(q, r)
    return q


def normalize(v):
    length = math.sqrt(sum(c * c for c in v))
    return [c / length for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def look_rotation(forward, up=(0.0, 1.0, 0.0)):
    """Quaternion turning the node's -Z to `forward` with +Y towards `up`."""
    f = normalize(forward)
    if abs(sum(a * b for a, b in zip(f, up))) > 0.999:
        up = (1.0, 0.0, 0.0)
    r = normalize(cross(f, up))
    u = cross(r, f)
    z = [-c for c in f]
    return quat_from_matrix([[r[0], u[0], z[0]], [r[1], u[1], z[1]], [r[2], u[2], z[2]]])


class Gltf:
    def __init__(self, generator):
        self.doc = {"asset": {"version": "2.0", "generator": generator}, "scene": 0,
                    "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                    "accessors": [], "bufferViews": [], "buffers": []}
        self.data = bytearray()
        self.lights = []

    def view(self, payload, target=None):
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if target:
            view["target"] = target
        self.data += payload
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, kind, component=FLOAT, target=34962):
        n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[kind]
        fmt = {FLOAT: "f", UNSIGNED_SHORT: "H", UNSIGNED_INT: "I"}[component]
        flat = [c for value in values for c in (value if n > 1 else [value])]
        payload = struct.pack("<%d%s" % (len(flat), fmt), *flat)
        accessor = {"bufferView": self.view(payload, target), "componentType": component,
                    "count": len(values), "type": kind}
        if kind == "VEC3" and component == FLOAT:
            accessor["min"] = [min(f32(v[k]) for v in values) for k in range(3)]
            accessor["max"] = [max(f32(v[k]) for v in values) for k in range(3)]
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def node(self, node, root=True):
        self.doc["nodes"].append(node)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def material(self, material):
        self.doc["materials"].append(material)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, primitives):
        self.doc["meshes"].append({"name": name, "primitives": primitives})
        return len(self.doc["meshes"]) - 1

    def light(self, light):
        self.lights.append(light)
        return len(self.lights) - 1

    def extension(self, name):
        for key in ("extensionsUsed",):
            self.doc.setdefault(key, [])
            if name not in self.doc[key]:
                self.doc[key].append(name)

    def write(self, gltf_path, indent=1):
        bin_name = os.path.splitext(os.path.basename(gltf_path))[0] + ".bin"
        self.doc["buffers"] = [{"uri": bin_name, "byteLength": len(self.data)}]
        if self.lights:
            self.extension("KHR_lights_punctual")
            self.doc.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": self.lights}
        for key in [k for k, v in self.doc.items() if v == []]:
            del self.doc[key]
        with open(os.path.join(os.path.dirname(gltf_path), bin_name), "wb") as f:
            f.write(self.data)
        with open(gltf_path, "w", encoding="ascii", newline="\n") as f:
            f.write(json.dumps(self.doc, indent=indent, separators=(",", ":") if indent is None else None) + "\n")


def colour_and_scale(rgb):
    """(colour with largest component 1, that component); black: (white, 0)."""
    peak = max(rgb)
    return ([c / peak for c in rgb], peak) if peak > 0.0 else ([1.0, 1.0, 1.0], 0.0)


def gltf_material(name, kd, ks=(0.0, 0.0, 0.0), alpha=1.0, emission=(0.0, 0.0, 0.0), two_sided=False):
    m = {"name": name, "pbrMetallicRoughness": {
        "baseColorFactor": list(kd) + [1.0], "metallicFactor": 0.0,
        "roughnessFactor": math.sqrt(alpha) if max(ks) > 0.0 else 1.0}}
    colour, strength = colour_and_scale(emission)
    if strength > 0.0:
        m["emissiveFactor"] = colour
        if strength != 1.0:
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
    if two_sided:
        m["doubleSided"] = True
    return m


def mtl_alpha(mtl):
    if mtl["Pr"] > 0.0:
        return mtl["Pr"] ** 2
    return math.sqrt(2.0 / (mtl["Ns"] + 2.0))


# -- the room --------------------------------------------------------------------

def add_obj(g, obj_path, materials, override, node_extra):
    """Every OBJ shape as a mesh of one indexed primitive, on its own node."""
    v, vn, shapes, _ = read_obj(obj_path)
    for shape in shapes:
        corners, positions, normals, indices = {}, [], [], []
        for triangle in shape["triangles"]:
            for corner in triangle:
                if corner not in corners:
                    corners[corner] = len(positions)
                    positions.append(v[corner[0]])
                    normals.append(vn[corner[1]] if corner[1] is not None else None)
                indices.append(corners[corner])
        attributes = {"POSITION": g.accessor(positions, "VEC3")}
        if all(n is not None for n in normals):
            attributes["NORMAL"] = g.accessor(normals, "VEC3")
        component = UNSIGNED_SHORT if len(positions) < 65536 else UNSIGNED_INT
        primitive = {"attributes": attributes, "mode": 4,
                     "indices": g.accessor(indices, "SCALAR", component, 34963),
                     "material": override if override is not None else materials[shape["material"]]}
        node = {"name": shape["name"] or os.path.basename(obj_path), "mesh": g.mesh(shape["name"], [primitive])}
        node.update(node_extra)
        g.node(node)


def transform_node(transform):
    node = {}
    if "translate" in transform:
        node["translation"] = transform["translate"]
    if "rotate_degrees" in transform:
        node["rotation"] = quat_euler_xyz(transform["rotate_degrees"])
    if "scale" in transform:
        s = transform["scale"]
        node["scale"] = s if isinstance(s, list) else [s, s, s]
    return node


def convert_scene(json_path, gltf_path):
    folder = os.path.dirname(json_path)
    scene = json.load(open(json_path, encoding="ascii"))
    g = Gltf("scripts/make_gltf.py from " + os.path.basename(json_path))

    cam = scene["camera"]
    forward = [b - a for a, b in zip(cam["position"], cam["look_at"])]
    g.doc["cameras"] = [{"name": "main", "type": "perspective", "perspective": {
        "yfov": math.radians(cam.get("fov_y_degrees", 40.0)),
        "aspectRatio": cam.get("width", 256) / cam.get("height", 256), "znear": 0.01}}]
    g.node({"name": "camera", "camera": 0, "translation": cam["position"],
            "rotation": look_rotation(forward, cam.get("up", [0, 1, 0]))})

    for mesh in scene["meshes"]:
        obj_path = os.path.join(folder, mesh["obj"])
        override, materials = None, {}
        if "material" in mesh:
            m = mesh["material"]
            override = g.material(gltf_material(
                os.path.basename(obj_path), m.get("kd", [0.8] * 3), m.get("ks", [0.0] * 3),
                m.get("roughness", 0.5) ** 2, m.get("emission", [0.0] * 3), m.get("emission_two_sided", False)))
        else:
            mtllib = read_obj(obj_path)[3]
            for name, mtl in read_mtl(os.path.join(os.path.dirname(obj_path), mtllib)).items():
                materials[name] = g.material(gltf_material(name, mtl["Kd"], mtl["Ks"], mtl_alpha(mtl), mtl["Ke"]))
        add_obj(g, obj_path, materials, override, transform_node(mesh.get("transform", {})))

    points = []
    for light in scene.get("lights", []):
        if light["type"] == "points_csv":
            points += read_points_csv(os.path.join(folder, light["file"]))
        elif light["type"] == "point":
            points.append((light["position"], light["intensity"]))
        else:
            raise SystemExit("%s: light type %s is not converted" % (json_path, light["type"]))
    for i, (position, intensity) in enumerate(points):
        colour, peak = colour_and_scale(intensity)
        index = g.light({"type": "point", "color": colour, "intensity": peak})
        g.node({"name": "light_%d" % i, "translation": list(position),
                "extensions": {"KHR_lights_punctual": {"light": index}}})
    g.write(gltf_path, indent=None)  # a thousand lights: compact


# -- the textured scene ----------------------------------------------------------

def write_png(path, width, height, pixel):
    """An 8-bit RGBA PNG; pixel(x, y) gives (r, g, b, a), row 0 at the top."""
    rows = b"".join(b"\x00" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(kind, payload):
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(png)


def box_faces(centre, size):
    """24 corners (4 per face, outward, counter-clockwise), normals and UVs."""
    cx, cy, cz = centre
    hx, hy, hz = (s / 2.0 for s in size)
    faces = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    positions, normals, uvs, indices = [], [], [], []
    for n, u, v in faces:
        base = len(positions)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = [n[k] * (hx, hy, hz)[k] + su * u[k] * (hx, hy, hz)[k] + sv * v[k] * (hx, hy, hz)[k]
                 for k in range(3)]
            positions.append([cx + p[0], cy + p[1], cz + p[2]])
            normals.append(list(n))
            uvs.append([(su + 1) / 2.0, (1 - sv) / 2.0])  # glTF: v grows downwards
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return positions, normals, uvs, indices


def write_textured(folder):
    os.makedirs(folder, exist_ok=True)
    size = 64
    write_png(os.path.join(folder, "checker.png"), size, size, lambda x, y: (
        (220, 200, 170, 255) if (x // 8 + y // 8) % 2 == 0 else (60, 70, 90, 255)))
    # glTF metallic-roughness: roughness in G, metallic in B; stripes of polished metal.
    write_png(os.path.join(folder, "metal_rough.png"), size, size, lambda x, y: (
        (0, 40, 255, 255) if (x // 16) % 2 == 0 else (0, 230, 0, 255)))
    write_png(os.path.join(folder, "glow.png"), size, size, lambda x, y: (
        (255, 220, 120, 255) if abs(x - 31.5) < 6 or abs(y - 31.5) < 6 else (0, 0, 0, 255)))

    def bumps(x, y):  # tangent-space normals of round bumps
        dx, dy = (x % 16) - 7.5, (y % 16) - 7.5
        r = math.hypot(dx, dy)
        nx, ny = (dx / 8.0, -dy / 8.0) if r < 6.0 else (0.0, 0.0)
        nz = math.sqrt(max(0.0, 1.0 - nx * nx - ny * ny))
        return (int(round((nx * 0.5 + 0.5) * 255)), int(round((ny * 0.5 + 0.5) * 255)),
                int(round((nz * 0.5 + 0.5) * 255)), 255)
    write_png(os.path.join(folder, "bumps.png"), size, size, bumps)

    g = Gltf("scripts/make_gltf.py")
    g.doc["images"] = [{"uri": name} for name in ("checker.png", "metal_rough.png", "glow.png", "bumps.png")]
    g.doc["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]
    g.doc["textures"] = [{"sampler": 0, "source": i} for i in range(4)]
    checker = g.material({"name": "checker_floor", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.8}})
    metal = g.material({"name": "striped_metal", "pbrMetallicRoughness": {
        "baseColorFactor": [0.9, 0.75, 0.5, 1.0], "metallicRoughnessTexture": {"index": 1},
        "metallicFactor": 1.0, "roughnessFactor": 1.0}})
    glow = g.material({"name": "glow", "pbrMetallicRoughness": {
        "baseColorFactor": [0.2, 0.2, 0.2, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6},
        "emissiveTexture": {"index": 2}, "emissiveFactor": [1.0, 1.0, 1.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}})
    bumpy = g.material({"name": "bumpy_wall", "pbrMetallicRoughness": {
        "baseColorFactor": [0.75, 0.75, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5},
        "normalTexture": {"index": 3, "scale": 1.0}})
    g.extension("KHR_materials_emissive_strength")

    def add_box(name, centre, size, material, uv_repeat=1.0):
        positions, normals, uvs, indices = box_faces(centre, size)
        primitive = {"attributes": {"POSITION": g.accessor(positions, "VEC3"),
                                    "NORMAL": g.accessor(normals, "VEC3"),
                                    "TEXCOORD_0": g.accessor([[u * uv_repeat, v * uv_repeat] for u, v in uvs],
                                                             "VEC2")},
                     "indices": g.accessor(indices, "SCALAR", UNSIGNED_SHORT, 34963), "material": material}
        g.node({"name": name, "mesh": g.mesh(name, [primitive])})

    add_box("floor", (0.0, -0.05, 0.0), (6.0, 0.1, 6.0), checker, 4.0)
    add_box("back_wall", (0.0, 1.5, -2.0), (6.0, 3.0, 0.1), bumpy, 3.0)
    add_box("metal_box", (-0.9, 0.5, -0.6), (1.0, 1.0, 1.0), metal)
    add_box("glow_box", (0.9, 0.35, -0.3), (0.7, 0.7, 0.7), glow)

    g.doc["cameras"] = [{"name": "front", "type": "perspective", "perspective": {
        "yfov": math.radians(50.0), "aspectRatio": 4.0 / 3.0, "znear": 0.01}},
        {"name": "top", "type": "perspective", "perspective": {"yfov": math.radians(60.0), "znear": 0.01}}]
    g.node({"name": "front_camera", "camera": 0, "translation": [0.0, 1.6, 3.6],
            "rotation": look_rotation([0.0, -0.9, -3.9])})
    # The second camera sits under a parent node: the hierarchy places it.
    top = g.node({"name": "top_camera", "camera": 1, "translation": [0.0, 4.0, 0.0],
                  "rotation": look_rotation([0.0, -1.0, -0.3])}, root=False)
    g.node({"name": "top_rig", "translation": [0.0, 0.5, 0.0], "children": [top]})
    point = g.light({"type": "point", "color": [1.0, 0.9, 0.8], "intensity": 6.0})
    spot = g.light({"type": "spot", "color": [0.8, 0.9, 1.0], "intensity": 30.0,
                    "spot": {"innerConeAngle": math.radians(12.0), "outerConeAngle": math.radians(22.0)}})
    g.node({"name": "point_light", "translation": [1.2, 2.6, 1.0],
            "extensions": {"KHR_lights_punctual": {"light": point}}})
    g.node({"name": "spot_light", "translation": [-2.0, 2.8, 1.5],
            "rotation": look_rotation([1.1, -2.8, -2.1]),
            "extensions": {"KHR_lights_punctual": {"light": spot}}})
    g.write(os.path.join(folder, "textured.gltf"))


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", default=os.path.join(here, ".."))
    args = parser.parse_args(argv)
    scenes = os.path.join(os.path.normpath(args.root), "scenes")
    convert_scene(os.path.join(scenes, "room", "room.json"), os.path.join(scenes, "room", "room.gltf"))
    write_textured(os.path.join(scenes, "gltf"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
