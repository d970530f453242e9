"""Generators of inputs every reader must refuse: malformed glTF/GLB scenes and traces whose CRCs
are valid but whose content is not. Used by test_bad_inputs.py and by scripts/make_fuzz_corpus.py
(the sanitizer run's corpus and the fuzzers' seeds). Each case returns what the error must say.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from gltf_forge import triangle_doc, write_glb
from trace_forge import nodes_view, rays_view

# ---------------------------------------------------------------------------------------------
# Scenes: each makes a file in a folder; SCENE_CASES gives the fragments the error must hold.


def _doc_with(edit: Callable[[dict], None]) -> tuple[dict, bytes]:
    doc, binary = triangle_doc()
    edit(doc)
    return doc, binary


def deep_json(d: Path) -> Path:
    path = d / "deep.gltf"
    path.write_text('{"asset":{"version":"2.0"},"extras":' + "[" * 20000 + "]" * 20000 + "}")
    return path


def glb_byte_length_zero(d: Path) -> Path:
    return write_glb(d / "len0.glb", *_doc_with(lambda doc: doc["buffers"][0].update(byteLength=0)))


def glb_version_1(d: Path) -> Path:
    return write_glb(d / "v1.glb", *triangle_doc(), version=1)


def negative_byte_offset(d: Path) -> Path:
    edit = _doc_with(lambda doc: doc["bufferViews"][0].update(byteOffset=-8))
    return write_glb(d / "negoff.glb", *edit)


def negative_byte_stride(d: Path) -> Path:
    edit = _doc_with(lambda doc: doc["bufferViews"][0].update(byteStride=-12))
    return write_glb(d / "negstride.glb", *edit)


def texture_out_of_range(d: Path) -> Path:
    def edit(doc: dict) -> None:
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 7}}}]
        doc["meshes"][0]["primitives"][0]["material"] = 0

    return write_glb(d / "tex.glb", *_doc_with(edit))


def non_utf8_bytes(d: Path) -> Path:
    doc, binary = triangle_doc()
    text = json.dumps(doc).encode().replace(b'"name": "tri"', b'"name": "tri\xff\xfe"')
    return write_glb(d / "latin.glb", text, binary)


def non_finite_vertex(d: Path) -> Path:
    doc, binary = triangle_doc(np.float32([[0, 0, 0], [np.inf, 0, 0], [0, 1, 0]]))
    return write_glb(d / "inf.glb", doc, binary)


def no_triangles(d: Path) -> Path:
    return write_glb(d / "empty.glb", *_doc_with(lambda doc: doc["nodes"][0].pop("mesh")))


def scene_is_a_folder(d: Path) -> Path:
    path = d / "folder.gltf"
    path.mkdir()
    return path


def instancing_blow_up(d: Path) -> Path:
    """200,000 EXT_mesh_gpu_instancing copies of a 20,000-triangle mesh (4e9 triangles)."""
    pos = np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]).tobytes()
    idx = np.tile(np.arange(3, dtype="<u2"), 20000).tobytes()
    trans = np.zeros((200_000, 3), dtype="<f4").tobytes()
    binary = pos + idx + trans
    views = [(0, len(pos)), (len(pos), len(idx)), (len(pos) + len(idx), len(trans))]
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3},
            {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": 60000},
            {"bufferView": 2, "componentType": 5126, "type": "VEC3", "count": 200_000},
        ],
        "meshes": [
            {"name": "grass", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}
        ],
        "nodes": [
            {
                "name": "field",
                "mesh": 0,
                "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 2}}},
            }
        ],
        "scenes": [{"nodes": [0]}],
    }
    return write_glb(d / "blowup.glb", doc, binary)


def far_scene(d: Path) -> Path:
    a = 1e30
    pos = np.float32([[a, a, a], [a * 1.000001, a, a], [a, a * 1.000001, a]])
    return write_glb(d / "far.glb", *triangle_doc(pos))


def wide_scene(d: Path) -> Path:
    pos = np.float32([[-1e20, 0, 0], [1e20, 0, 0], [0, 1e20, 1]])
    return write_glb(d / "wide.glb", *triangle_doc(pos))


def point_scene(d: Path) -> Path:
    return write_glb(d / "point.glb", *triangle_doc(np.float32([[1, 1, 1]] * 3)))


SCENE_CASES = {
    "deep_json": (deep_json, ["deep.gltf", "nested deeper than 512 levels"]),
    "glb_byte_length_0": (glb_byte_length_zero, ["len0.glb", "buffer 0", "byteLength is 0"]),
    "glb_version_1": (glb_version_1, ["v1.glb", "GLB container version 1"]),
    "negative_byte_offset": (
        negative_byte_offset,
        ["negoff.glb", "bufferView 0", "byteOffset is -8"],
    ),
    "negative_byte_stride": (negative_byte_stride, ["negstride.glb", "bufferView 0", "byteStride"]),
    "texture_out_of_range": (texture_out_of_range, ["tex.glb", "material 0", "texture index 7"]),
    "non_utf8_bytes": (non_utf8_bytes, ["latin.glb", "\\xff"]),
    "non_finite_vertex": (non_finite_vertex, ["inf.glb", "mesh 0 'tri' triangle 0", "non-finite"]),
    "no_triangles": (no_triangles, ["empty.glb", "no triangles"]),
    "scene_is_a_folder": (scene_is_a_folder, ["folder.gltf", "is a folder"]),
    "instancing_blow_up": (
        instancing_blow_up,
        ["blowup.glb", "node 0 'field'", "4000000000 triangles"],
    ),
    "framing_far": (far_scene, ["far.glb", "automatic framing", "1e+30"]),
    "framing_wide": (wide_scene, ["wide.glb", "automatic framing", "overflow"]),
    "framing_zero_extent": (point_scene, ["point.glb", "zero extent"]),
}


# ---------------------------------------------------------------------------------------------
# Traces: each edits the sections of a good trace (names as in trace_forge) and returns the
# text the error must hold.


def _first_slot(nodes: np.ndarray, leaf: bool) -> tuple[int, int]:
    for i in range(len(nodes)):
        for s in range(2):
            count = nodes[i]["child_count"][s]
            if (count != 0) == leaf and count != 0xFFFFFFFF:
                return i, s
    raise AssertionError("no such slot")


def child_out_of_range(t: dict) -> str:
    n = nodes_view(t["bvh_nodes"])
    i, s = _first_slot(n, leaf=False)
    n[i]["child_ref"][s] = 1_000_000
    return f"binary BVH: node {i} child {s} points to node 1000000 (out of range)"


def node_points_to_itself(t: dict) -> str:
    n = nodes_view(t["bvh_nodes"])
    n[1]["child_ref"][0], n[1]["child_count"][0] = 1, 0
    return "binary BVH: node 1 child 0 points to node 1 (not after its parent)"


def leaf_out_of_range(t: dict) -> str:
    n = nodes_view(t["bvh_nodes"])
    i, s = _first_slot(n, leaf=True)
    n[i]["child_ref"][s] = 0x7FFFFFFF
    return f"binary BVH: node {i} child {s} references triangles 2147483647.."


def leaf_count_0xffffff(t: dict) -> str:
    n = nodes_view(t["bvh_nodes"])
    i, s = _first_slot(n, leaf=True)
    n[i]["child_count"][s] = 0xFFFFFF
    return f"binary BVH: node {i} child {s} is a leaf of 16777215 triangles"


def empty_triangle_section(t: dict) -> str:
    t["triangles"] = bytearray()
    return "region 'triangles'"


def unknown_ray_kind(t: dict) -> str:
    rays_view(t["rays"])[5]["kind"] = 9
    return "ray 5 has unknown ray kind 9"


TRACE_CASES = {
    f.__name__: f
    for f in (
        child_out_of_range,
        node_points_to_itself,
        leaf_out_of_range,
        leaf_count_0xffffff,
        empty_triangle_section,
        unknown_ray_kind,
    )
}
