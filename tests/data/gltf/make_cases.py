#!/usr/bin/python3
"""Writes the small glTF files tests/test_gltf.cpp and tests/cli_test.sh load:
one per feature and one per kind of malformed input (bad_*). Each is a
.gltf with its buffer embedded as a base64 data URI (one .glb too), written
out explicitly here so a reader sees every number the tests check.

  /usr/bin/python3 tests/data/gltf/make_cases.py
"""

import base64
import copy
import json
import math
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "scripts"))
import make_gltf  # noqa: E402  (write_png, look_rotation)

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125


class Buffer:
    """Byte views appended one after another, 4-byte aligned."""

    def __init__(self):
        self.data = bytearray()
        self.views = []

    def view(self, payload, stride=None):
        while len(self.data) % 4:
            self.data.append(0)
        v = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if stride:
            v["byteStride"] = stride
        self.data += payload
        self.views.append(v)
        return len(self.views) - 1

    def uri(self):
        return "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode()


def pack(fmt, values):
    return struct.pack("<%d%s" % (len(values), fmt), *values)


def floats(rows):
    return pack("f", [c for row in rows for c in row])


def gltf(buffer, accessors, meshes, nodes, scene_nodes=None, **extra):
    doc = {"asset": {"version": "2.0", "generator": "tests/data/gltf/make_cases.py"},
           "scene": 0, "scenes": [{"nodes": scene_nodes if scene_nodes is not None else list(range(len(nodes)))}],
           "nodes": nodes, "meshes": meshes, "accessors": accessors, "bufferViews": buffer.views,
           "buffers": [{"byteLength": len(buffer.data), "uri": buffer.uri()}]}
    doc.update(extra)
    return doc


def point_light_ext(intensity=2.0):
    return {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1.0, 1.0, 1.0],
                                                "intensity": intensity}]}}


def light_node(position, light=0):
    return {"translation": position, "extensions": {"KHR_lights_punctual": {"light": light}}}


def write(name, doc):
    with open(os.path.join(HERE, name), "w", encoding="ascii", newline="\n") as f:
        f.write(json.dumps(doc, indent=1) + "\n")


# One triangle in z = 0, counter-clockwise seen from +z: face normal +z.
TRIANGLE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]


def triangle_doc():
    b = Buffer()
    pos = b.view(floats(TRIANGLE))
    acc = [{"bufferView": pos, "componentType": FLOAT, "count": 3, "type": "VEC3",
            "min": [0, 0, 0], "max": [1, 1, 0]}]
    return gltf(b, acc, [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                [{"mesh": 0}, light_node([0.2, 0.2, 1.0])], extensionsUsed=["KHR_lights_punctual"],
                extensions=point_light_ext())


def write_glb(name, doc):
    """The same document as a .glb: the buffer moves into the BIN chunk."""
    doc = copy.deepcopy(doc)
    data = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    del doc["buffers"][0]["uri"]
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(data), b"BIN\0") + data
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)


def accessors_doc():
    """Index types, an interleaved view with byteStride, normalized UVs and a
    sparse accessor."""
    b = Buffer()
    # Interleaved POSITION + NORMAL, 24 bytes per vertex: a quad in z = 0.
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    interleaved = b.view(b"".join(floats([p, [0.0, 0.0, 1.0]]) for p in quad), stride=24)
    i8 = b.view(pack("B", [0, 1, 2, 0, 2, 3]))
    i16 = b.view(pack("H", [0, 1, 2]))
    i32 = b.view(pack("I", [0, 2, 3]))
    uv = b.view(pack("H", [0, 0, 65535, 0, 65535, 65535, 0, 32768]))
    # Sparse: vertex 2 of the quad's positions moved to z = 0.5.
    sparse_index = b.view(pack("B", [2]))
    sparse_value = b.view(floats([[1.0, 1.0, 0.5]]))
    acc = [
        {"bufferView": interleaved, "byteOffset": 0, "componentType": FLOAT, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": interleaved, "byteOffset": 12, "componentType": FLOAT, "count": 4, "type": "VEC3"},
        {"bufferView": i8, "componentType": UBYTE, "count": 6, "type": "SCALAR"},
        {"bufferView": i16, "componentType": USHORT, "count": 3, "type": "SCALAR"},
        {"bufferView": i32, "componentType": UINT, "count": 3, "type": "SCALAR"},
        {"bufferView": uv, "componentType": USHORT, "normalized": True, "count": 4, "type": "VEC2"},
        {"bufferView": interleaved, "componentType": FLOAT, "count": 4, "type": "VEC3",
         "sparse": {"count": 1, "indices": {"bufferView": sparse_index, "componentType": UBYTE},
                    "values": {"bufferView": sparse_value}}},
    ]
    attrs = {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 5}
    meshes = [{"primitives": [{"attributes": attrs, "indices": 2},
                              {"attributes": attrs, "indices": 3},
                              {"attributes": attrs, "indices": 4},
                              {"attributes": {"POSITION": 6}, "indices": 2}]}]
    return gltf(b, acc, meshes, [{"mesh": 0}, light_node([0.5, 0.5, 2.0])],
                extensionsUsed=["KHR_lights_punctual"], extensions=point_light_ext())


def hierarchy_doc():
    """A parent's TRS and a child's matrix multiply; a mirrored node; an
    unreferenced node outside the scene is not drawn."""
    b = Buffer()
    pos = b.view(floats(TRIANGLE))
    nrm = b.view(floats([[0.0, 0.0, 1.0]] * 3))
    acc = [{"bufferView": pos, "componentType": FLOAT, "count": 3, "type": "VEC3",
            "min": [0, 0, 0], "max": [1, 1, 0]},
           {"bufferView": nrm, "componentType": FLOAT, "count": 3, "type": "VEC3"}]
    half = math.sqrt(0.5)
    nodes = [
        # 0: parent: translate (10, 0, 0), rotate 90 degrees about +y, scale 2.
        {"translation": [10.0, 0.0, 0.0], "rotation": [0.0, half, 0.0, half], "scale": [2.0, 2.0, 2.0],
         "children": [1]},
        # 1: child: matrix (column-major) translating by (0, 1, 0) and scaling x by 3.
        {"matrix": [3, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1], "mesh": 0},
        # 2: mirrored: scale x by -1.
        {"scale": [-1.0, 1.0, 1.0], "mesh": 0},
        # 3: not in the scene.
        {"mesh": 0, "translation": [100.0, 0.0, 0.0]},
        light_node([0.0, 5.0, 5.0]),
    ]
    return gltf(b, acc, [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}}]}], nodes,
                scene_nodes=[0, 2, 4], extensionsUsed=["KHR_lights_punctual"], extensions=point_light_ext())


def modes_doc():
    """TRIANGLE_STRIP and TRIANGLE_FAN are converted; POINTS and LINES skipped."""
    b = Buffer()
    strip = b.view(floats([[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [2, 0, 0]]))
    acc = [{"bufferView": strip, "componentType": FLOAT, "count": 5, "type": "VEC3",
            "min": [0, 0, 0], "max": [2, 1, 0]}]
    meshes = [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 5},
                              {"attributes": {"POSITION": 0}, "mode": 6},
                              {"attributes": {"POSITION": 0}, "mode": 0},
                              {"attributes": {"POSITION": 0}, "mode": 1}]}]
    return gltf(b, acc, meshes, [{"mesh": 0}, light_node([0.5, 0.5, 2.0])],
                extensionsUsed=["KHR_lights_punctual"], extensions=point_light_ext())


def corrupt_png():
    """A PNG whose chunks are whole but whose pixels are not zlib data."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", b"not zlib data") + chunk(b"IEND", b""))


def png_uri(width, height, pixel):
    path = os.path.join(HERE, "_tmp.png")
    make_gltf.write_png(path, width, height, pixel)
    data = open(path, "rb").read()
    os.remove(path)
    return "data:image/png;base64," + base64.b64encode(data).decode()


def materials_doc():
    b = Buffer()
    pos = b.view(floats(TRIANGLE))
    uv = b.view(floats([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
    acc = [{"bufferView": pos, "componentType": FLOAT, "count": 3, "type": "VEC3",
            "min": [0, 0, 0], "max": [1, 1, 0]},
           {"bufferView": uv, "componentType": FLOAT, "count": 3, "type": "VEC2"}]
    # A 2 x 2 image: red, green / blue, white (row 0 at the top).
    colours = [[(255, 0, 0, 255), (0, 255, 0, 255)], [(0, 0, 255, 255), (255, 255, 255, 255)]]
    images = [{"uri": png_uri(2, 2, lambda x, y: colours[y][x])},
              {"uri": png_uri(1, 1, lambda x, y: (128, 128, 255, 255))}]
    textures = [{"source": 0}, {"source": 0, "sampler": 0}, {"source": 1}, {"source": 1, "sampler": 1}]
    materials = [
        # 0: factors, clearcoat, sheen, emission with strength, two-sided, textures.
        {"name": "everything",
         "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1.0], "metallicFactor": 0.75,
                                  "roughnessFactor": 0.4, "baseColorTexture": {"index": 0},
                                  "metallicRoughnessTexture": {"index": 1}},
         "normalTexture": {"index": 2, "scale": 0.5},
         "emissiveFactor": [1.0, 0.5, 0.25], "emissiveTexture": {"index": 0}, "doubleSided": True,
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 8.0},
                        "KHR_materials_clearcoat": {"clearcoatFactor": 0.6, "clearcoatRoughnessFactor": 0.2},
                        "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.25, 0.125]}}},
        # 1: what is noted and left out: TEXCOORD_1, BLEND, occlusion, a
        # mipmap minFilter read trilinearly; the texture transform of the
        # extension's example (the image's lower-left quarter, turned).
        {"name": "noted",
         "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1},
                                  "metallicRoughnessTexture": {
                                      "index": 1, "extensions": {"KHR_texture_transform": {
                                          "offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}}}},
         "normalTexture": {"index": 3},
         "alphaMode": "BLEND", "occlusionTexture": {"index": 0},
         "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5]}}},
    ]
    meshes = [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0},
                              {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 1},
                              {"attributes": {"POSITION": 0}}]}]
    return gltf(b, acc, meshes, [{"mesh": 0}], images=images, textures=textures,
                samplers=[{"wrapS": 33071, "wrapT": 10497, "magFilter": 9728, "minFilter": 9729},
                          {"wrapS": 33648, "wrapT": 33648, "magFilter": 9729, "minFilter": 9984}],
                materials=materials,
                extensionsUsed=["KHR_materials_emissive_strength", "KHR_materials_clearcoat",
                                "KHR_materials_sheen", "KHR_texture_transform"])


def lights_doc():
    """Point, spot and directional lights placed by their nodes; cameras."""
    doc = triangle_doc()
    half = math.sqrt(0.5)
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 4.0, "range": 10.0},
        {"type": "spot", "color": [0.5, 1.0, 1.0], "intensity": 2.0,
         "spot": {"innerConeAngle": math.radians(10.0), "outerConeAngle": math.radians(30.0)}},
        {"type": "directional", "intensity": 3.0}]}}
    doc["cameras"] = [{"name": "ortho", "type": "orthographic",
                       "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}},
                      {"name": "wide", "type": "perspective",
                       "perspective": {"yfov": math.radians(90.0), "aspectRatio": 2.0, "znear": 0.1}},
                      {"name": "near", "type": "perspective", "perspective": {"yfov": math.radians(30.0), "znear": 0.1}}]
    doc["nodes"] = [
        {"mesh": 0},
        light_node([1.0, 2.0, 3.0], 0),
        # Spot at (0, 3, 0) rotated -90 degrees about x: its -Z points down (-y).
        {"translation": [0.0, 3.0, 0.0], "rotation": [-half, 0.0, 0.0, half],
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
        # Directional rotated 90 degrees about y: its -Z travels along -x.
        {"rotation": [0.0, half, 0.0, half], "extensions": {"KHR_lights_punctual": {"light": 2}}},
        {"camera": 0},
        {"camera": 1, "translation": [0.0, 0.0, 5.0]},
        {"camera": 2, "translation": [0.0, 0.0, 7.0]},
    ]
    doc["scenes"] = [{"nodes": list(range(7))}]
    return doc


def unsupported_doc():
    """Animations, skins, morph targets, vertex colours and an unknown used
    extension are noted and skipped."""
    doc = triangle_doc()
    b = Buffer()
    b.data = bytearray(base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1]))
    b.views = doc["bufferViews"]
    times = b.view(pack("f", [0.0, 1.0]))
    moves = b.view(floats([[0, 0, 0], [0, 1, 0]]))
    doc["accessors"] += [{"bufferView": times, "componentType": FLOAT, "count": 2, "type": "SCALAR",
                          "min": [0], "max": [1]},
                         {"bufferView": moves, "componentType": FLOAT, "count": 2, "type": "VEC3"}]
    doc["buffers"] = [{"byteLength": len(b.data), "uri": b.uri()}]
    doc["animations"] = [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                          "samplers": [{"input": 1, "output": 2}]}]
    doc["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": 0}]
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 0
    doc["extensionsUsed"].append("EXT_unknown_feature")
    # A textured material on a primitive without TEXCOORD_0.
    doc["images"] = [{"uri": png_uri(1, 1, lambda x, y: (255, 255, 255, 255))}]
    doc["textures"] = [{"source": 0}]
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    return doc


def no_camera_gltf_with_emission():
    """No lights, but an emissive material: lit by its area light."""
    doc = triangle_doc()
    del doc["extensions"], doc["extensionsUsed"]
    doc["nodes"] = [{"mesh": 0}]
    doc["scenes"] = [{"nodes": [0]}]
    doc["materials"] = [{"emissiveFactor": [1.0, 1.0, 1.0]}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    return doc


def bad_cases():
    cases = {}

    def variant(name, change):
        doc = triangle_doc()
        change(doc)
        cases[name] = doc

    variant("bad_required_draco", lambda d: d.update(extensionsRequired=["KHR_draco_mesh_compression"],
                                                     extensionsUsed=["KHR_draco_mesh_compression"]))

    def index_out_of_range(d):
        b = Buffer()
        b.data = bytearray(base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1]))
        b.views = d["bufferViews"]
        view = b.view(pack("H", [0, 1, 7]))
        d["accessors"].append({"bufferView": view, "componentType": USHORT, "count": 3, "type": "SCALAR"})
        d["buffers"] = [{"byteLength": len(b.data), "uri": b.uri()}]
        d["meshes"][0]["primitives"][0]["indices"] = 1
    variant("bad_index_range", index_out_of_range)
    variant("bad_accessor_past_view", lambda d: d["accessors"][0].update(count=4))
    # The largest count an accessor may have, in a 3-element buffer view:
    # refused before room is made for 2^31 elements (51 GB as doubles).
    variant("bad_accessor_count_huge", lambda d: d["accessors"][0].update(count=2**31))
    # An accessor of zeros (no bufferView) one element past the limit.
    variant("bad_zeros_count", lambda d: (d["accessors"][0].update(count=2**24 + 1), d["accessors"][0].pop("bufferView")))
    variant("bad_view_past_buffer", lambda d: d["bufferViews"][0].update(byteOffset=8))

    def nan_position(d):
        data = bytearray(base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1]))
        data[16:20] = struct.pack("<f", float("nan"))
        d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()
    variant("bad_nan_position", nan_position)
    variant("bad_missing_buffer", lambda d: d["buffers"][0].update(uri="missing.bin"))
    # URIs naming a folder: tinygltf would take the folder's "size" as about 2^63 bytes.
    variant("bad_buffer_folder", lambda d: d["buffers"][0].update(uri="."))
    variant("bad_image_folder", lambda d: d.update(images=[{"uri": ".."}]))
    variant("bad_data_uri", lambda d: d["buffers"][0].update(uri="data:application/octet-stream;base64,@@@@"))
    variant("bad_no_position", lambda d: d["meshes"][0]["primitives"][0].update(attributes={"NORMAL": 0}))
    variant("bad_no_light", lambda d: (d.pop("extensions"), d["nodes"].pop(), d["scenes"][0]["nodes"].pop()))
    variant("bad_node_cycle", lambda d: (d["nodes"].append({"children": [3]}), d["nodes"].append({"children": [2]}),
                                         d["scenes"][0]["nodes"].append(2)))
    variant("bad_material_index", lambda d: d["meshes"][0]["primitives"][0].update(material=3))
    variant("bad_base_color", lambda d: (d.update(materials=[{"pbrMetallicRoughness": {
        "baseColorFactor": [1.5, 0, 0, 1]}}]), d["meshes"][0]["primitives"][0].update(material=0)))
    variant("bad_base_alpha", lambda d: (d.update(materials=[{"pbrMetallicRoughness": {
        "baseColorFactor": [1, 1, 1, 7]}}]), d["meshes"][0]["primitives"][0].update(material=0)))

    def textured(d, texture_info, sampler=None):
        """The triangle with a base-colour texture of one white texel."""
        d["images"] = [{"uri": png_uri(1, 1, lambda x, y: (255, 255, 255, 255))}]
        d["textures"] = [{"source": 0}]
        if sampler is not None:
            d["samplers"] = [sampler]
            d["textures"][0]["sampler"] = 0
        d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": dict(index=0, **texture_info)}}]
        d["meshes"][0]["primitives"][0]["material"] = 0

    variant("bad_wrap", lambda d: textured(d, {}, {"wrapS": 12345}))
    # A missing image, though only an occlusion texture (which is not read) uses it.
    variant("bad_image_missing", lambda d: (textured(d, {}), d["images"].append({"uri": "missing.png"}),
                                            d["textures"].append({"source": 1}),
                                            d["materials"][0].update(occlusionTexture={"index": 1})))
    # A PNG whose chunks are whole but whose pixels are not zlib data (corrupt.png).
    variant("bad_image_corrupt", lambda d: (textured(d, {}), d["images"].__setitem__(0, {"uri": "corrupt.png"})))
    # Not bad: the same image in a texture that no material reads (it is not decoded); in a data
    # URI, so that the fuzzer's copy of the file (which is alone in its folder) reaches it.
    variant("unused_image_corrupt", lambda d: (
        textured(d, {}),
        d["images"].append({"uri": "data:image/png;base64," + base64.b64encode(corrupt_png()).decode()}),
        d["textures"].append({"source": 1})))
    variant("bad_mag_filter", lambda d: textured(d, {}, {"magFilter": 1}))
    variant("bad_min_filter", lambda d: textured(d, {}, {"minFilter": 9990}))
    variant("bad_transform_offset", lambda d: textured(d, {"extensions": {"KHR_texture_transform": {
        "offset": ["0", 0]}}}))
    variant("bad_transform_scale", lambda d: textured(d, {"extensions": {"KHR_texture_transform": {
        "scale": [1e39, 1]}}}))
    variant("bad_spot_cone", lambda d: d["extensions"]["KHR_lights_punctual"]["lights"][0].update(
        type="spot", spot={"innerConeAngle": 0.5, "outerConeAngle": 2.0}))
    # Not bad: pi/2 as exporters that keep angles in floats write it, a hair above pi/2.
    variant("spot_float_half_pi", lambda d: d["extensions"]["KHR_lights_punctual"]["lights"][0].update(
        type="spot", spot={"innerConeAngle": 1.5707964, "outerConeAngle": 1.5707964}))
    # Bad: the next float above that.
    variant("bad_spot_past_float_half_pi", lambda d: d["extensions"]["KHR_lights_punctual"]["lights"][0].update(
        type="spot", spot={"innerConeAngle": 0.5, "outerConeAngle": 1.5707965}))
    variant("bad_position_type", lambda d: d["accessors"][0].update(componentType=USHORT))
    # Values of the wrong JSON type, which tinygltf 2.7 would replace by its default.
    variant("bad_roughness_string", lambda d: (d.update(materials=[{"pbrMetallicRoughness": {
        "roughnessFactor": "0.5"}}]), d["meshes"][0]["primitives"][0].update(material=0)))
    variant("bad_emissive_strength_number", lambda d: (d.update(materials=[{"emissiveFactor": [1, 1, 1],
        "extensions": {"KHR_materials_emissive_strength": 5}}]), d["meshes"][0]["primitives"][0].update(material=0),
        d.update(extensionsUsed=d.get("extensionsUsed", []) + ["KHR_materials_emissive_strength"])))
    variant("bad_emissive_strength_huge", lambda d: (d.update(materials=[{"emissiveFactor": [1, 1, 1],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e39}}}]),
        d["meshes"][0]["primitives"][0].update(material=0),
        d.update(extensionsUsed=d.get("extensionsUsed", []) + ["KHR_materials_emissive_strength"])))
    variant("bad_lights_array", lambda d: d["extensions"].update(KHR_lights_punctual=[1]))
    variant("bad_light_string", lambda d: d["extensions"]["KHR_lights_punctual"]["lights"].__setitem__(0, "point"))
    variant("bad_node_light_number", lambda d: d["nodes"][1]["extensions"].update(KHR_lights_punctual=0))
    variant("bad_negative_view", lambda d: d["accessors"][0].update(bufferView=-5))
    variant("bad_aspect_zero", lambda d: (d.update(cameras=[{"type": "perspective", "perspective": {
        "yfov": 0.8, "aspectRatio": 0, "znear": 0.1}}]), d["nodes"].append({"camera": 0, "translation": [0, 0, 3]}),
        d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)))
    # A yfov inside (0, pi) that rounds to 180 degrees as a float.
    variant("bad_yfov_rounds", lambda d: (d.update(cameras=[{"type": "perspective", "perspective": {
        "yfov": math.pi - 1e-12, "znear": 0.1}}]), d["nodes"].append({"camera": 0, "translation": [0, 0, 3]}),
        d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)))
    # A camera 3e38 from the origin, looking away from it: a point along its view is the
    # camera's own position as a float.
    variant("bad_camera_too_far", lambda d: (d.update(cameras=[{"type": "perspective", "perspective": {
        "yfov": 0.8, "znear": 0.1}}]), d["nodes"].append({"camera": 0, "translation": [3e38, 0, 0],
        "rotation": [0, -math.sin(math.radians(45.0)), 0, math.cos(math.radians(45.0))]}),
        d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)))
    # Not bad: one camera, named, on two nodes (--camera takes the first, with a note).
    variant("camera_on_two_nodes", lambda d: (d.update(cameras=[{"name": "a", "type": "perspective", "perspective": {
        "yfov": 0.8, "znear": 0.1}}]), d["nodes"].append({"camera": 0, "translation": [0, 0, 3]}),
        d["nodes"].append({"camera": 0, "translation": [0, 0, 5]}),
        d["scenes"][0]["nodes"].extend([len(d["nodes"]) - 2, len(d["nodes"]) - 1])))
    # Not bad: a camera 1e8 from the origin, turned 10 degrees about x (it
    # looks along (0, sin 10, -cos 10)).
    variant("far_camera", lambda d: (d.update(cameras=[{"type": "perspective", "perspective": {
        "yfov": 0.8, "znear": 0.1}}]), d["nodes"].append({"camera": 0, "translation": [0, 0, 1e8],
        "rotation": [math.sin(math.radians(5.0)), 0, 0, math.cos(math.radians(5.0))]}),
        d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)))
    # Not bad: a camera whose aspect ratio would make the image wider than 16384 columns.
    variant("wide_camera", lambda d: (d.update(cameras=[{"type": "perspective", "perspective": {
        "yfov": 0.8, "aspectRatio": 100, "znear": 0.1}}]), d["nodes"].append({"camera": 0, "translation": [0, 0, 3]}),
        d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)))
    variant("bad_projective_matrix", lambda d: d["nodes"][0].update(
        matrix=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0]))
    # The only mesh node scaled below what a float triangle can hold.
    variant("bad_scale_tiny", lambda d: d["nodes"][0].update(scale=[1e-30, 1e-30, 1e-30]))
    # Not bad: a second instance of the mesh hidden by a scale of 0 (as
    # tools hide objects), left out with a note.
    variant("hidden_node", lambda d: (d["nodes"].append({"mesh": 0, "scale": [0, 0, 0]}),
                                      d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)))
    return cases


def main():
    write("triangle.gltf", triangle_doc())
    write_glb("triangle.glb", triangle_doc())
    write("accessors.gltf", accessors_doc())
    write("hierarchy.gltf", hierarchy_doc())
    write("modes.gltf", modes_doc())
    write("materials.gltf", materials_doc())
    write("lights.gltf", lights_doc())
    write("unsupported.gltf", unsupported_doc())
    write("emissive_only.gltf", no_camera_gltf_with_emission())
    for name, doc in bad_cases().items():
        write(name + ".gltf", doc)
    with open(os.path.join(HERE, "corrupt.png"), "wb") as f:
        f.write(corrupt_png())
    with open(os.path.join(HERE, "bad_json.gltf"), "w", encoding="ascii") as f:
        f.write('{"asset": {"version": "2.0"}, "nodes": [\n')
    # A JSON scene with an OBJ and two glTF files (one placed by a transform), next to its own lights.
    with open(os.path.join(HERE, "with_json.json"), "w", encoding="ascii") as f:
        f.write(json.dumps({
            "camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0], "width": 16, "height": 16},
            "meshes": [{"obj": "../scenes/tri.obj"},
                       {"gltf": "hierarchy.gltf", "transform": {"translate": [0, 0, -1]}},
                       {"gltf": "triangle.glb"}],
            "lights": [{"type": "point", "position": [0, 1, 1], "intensity": [1, 1, 1]}]}, indent=1) + "\n")
    with open(os.path.join(HERE, "bad_json_gltf_material.json"), "w", encoding="ascii") as f:
        f.write(json.dumps({
            "camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
            "meshes": [{"gltf": "triangle.gltf", "material": {"kd": [1, 0, 0]}}]}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
