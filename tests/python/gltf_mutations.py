"""Structured mutations of a glTF document's numbers and types, generated at test time (and
written as fuzz seeds by scripts/make_fuzz_corpus.py).

`rich_doc()` is a small valid scene that uses every kind of index the loader reads: a camera, two
materials, a KHR_lights_punctual light, an EXT_mesh_gpu_instancing node, node transforms and
children. `number_mutations()` finds every integer field of it (by the glTF 2.0 schema's keys)
and yields, for each, the same value written as a float (valid: the scene must load exactly as
before) and values the loader must refuse naming the element and key (a fraction, a negative
index, 1e20, a string, null, a list, an object). `type_mutations()` breaks node transforms and
extension objects the same way.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

#: Keys whose values the glTF 2.0 schema declares integers (indices, offsets, counts, enums).
INTEGER_KEYS = {
    "scene",
    "nodes",
    "camera",
    "mesh",
    "skin",
    "children",
    "material",
    "indices",
    "mode",
    "bufferView",
    "byteOffset",
    "byteLength",
    "byteStride",
    "componentType",
    "count",
    "buffer",
    "index",
    "source",
    "light",
    "POSITION",
    "TRANSLATION",
    "SCALE",
}


def rich_doc() -> tuple[dict[str, Any], bytes]:
    """A valid two-triangle scene placed twice by instancing, with a camera looking at it, two
    materials (the second metallic), a light and a child node; the binary buffer with it."""
    pos = np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]).tobytes()
    idx = np.uint16([0, 1, 2, 1, 3, 2]).tobytes()
    trans = np.float32([[0, 0, 0], [2, 0, 0]]).tobytes()
    binary = pos + idx + b"\0\0\0\0" + trans  # 48 + 12 + 4 + 24 bytes
    views = [(0, 48), (48, 12), (64, 24)]
    doc: dict[str, Any] = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing", "KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
        "accessors": [
            {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "type": "VEC3", "count": 4},
            {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": 6},
            {"bufferView": 2, "componentType": 5126, "type": "VEC3", "count": 2},
        ],
        "materials": [
            {"name": "matte", "pbrMetallicRoughness": {"metallicFactor": 0.0}},
            {
                "name": "mirror",
                "pbrMetallicRoughness": {"metallicFactor": 1.0, "roughnessFactor": 0},
            },
        ],
        "meshes": [
            {
                "name": "quad",
                "primitives": [
                    {"attributes": {"POSITION": 0}, "indices": 1, "material": 1, "mode": 4}
                ],
            }
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "nodes": [
            {
                "name": "field",
                "mesh": 0,
                "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 2}}},
                "children": [1],
            },
            {
                "name": "lamp",
                "translation": [0.5, 0.5, 2],
                "extensions": {"KHR_lights_punctual": {"light": 0}},
            },
            {"name": "eye", "camera": 0, "translation": [1.5, 0.5, 4], "scale": [1, 1, 1]},
        ],
    }
    return doc, binary


def _pointers(value: Any, path: tuple = ()) -> Iterator[tuple[tuple, Any]]:
    """(path, value) of every integer under a key of INTEGER_KEYS (list items of `nodes` and
    `children` included)."""
    if isinstance(value, dict):
        for key, child in value.items():
            if key in INTEGER_KEYS and isinstance(child, int) and not isinstance(child, bool):
                yield (*path, key), child
            elif (
                key in ("nodes", "children")
                and isinstance(child, list)
                and all(isinstance(c, int) for c in child)
            ):
                for i, c in enumerate(child):
                    yield (*path, key, i), c
            else:
                yield from _pointers(child, (*path, key))
    elif isinstance(value, list):
        for i, child in enumerate(value):
            yield from _pointers(child, (*path, i))


def _set(doc: Any, path: tuple, value: Any) -> None:
    for part in path[:-1]:
        doc = doc[part]
    doc[path[-1]] = value


def _key(path: tuple) -> str:
    """The key an error must name: the last string of the path ('children' for children[0])."""
    return next(p for p in reversed(path) if isinstance(p, str))


@dataclass
class Mutation:
    name: str
    doc: dict[str, Any]
    valid: bool  # True: must load exactly as rich_doc(); False: must be refused
    key: str  # what the refusal must name


def number_mutations() -> Iterator[Mutation]:
    base, _binary = rich_doc()
    for path, value in _pointers(base):
        label = "/".join(str(p) for p in path)
        bad = {
            "fraction": value + 0.5,
            "negative": -2,
            "huge": 1e20,
            "string": str(value),
            "null": None,
            "list": [value],
            "object": {"value": value},
        }
        doc = copy.deepcopy(base)
        _set(doc, path, float(value))
        yield Mutation(f"{label}=float", doc, True, _key(path))
        for kind, wrong in bad.items():
            doc = copy.deepcopy(base)
            _set(doc, path, wrong)
            yield Mutation(f"{label}={kind}", doc, False, _key(path))


def type_mutations() -> Iterator[Mutation]:
    """Node transforms and extension objects of the wrong type or shape."""
    base, _binary = rich_doc()
    edits: dict[str, tuple[tuple, Any, str]] = {
        "matrix_strings": (("nodes", 2, "matrix"), ["1"] * 16, "matrix"),
        "matrix_short": (("nodes", 2, "matrix"), [1, 0, 0], "matrix"),
        "translation_string": (("nodes", 2, "translation"), "0,0,4", "translation"),
        "rotation_null": (("nodes", 2, "rotation"), [None, 0, 0, 1], "rotation"),
        "scale_object": (("nodes", 2, "scale"), {"x": 1}, "scale"),
        "instancing_number": (
            ("nodes", 0, "extensions", "EXT_mesh_gpu_instancing"),
            5,
            "EXT_mesh_gpu_instancing",
        ),
        "instancing_attributes_list": (
            ("nodes", 0, "extensions", "EXT_mesh_gpu_instancing", "attributes"),
            [2],
            "attributes",
        ),
        "light_string": (
            ("nodes", 1, "extensions", "KHR_lights_punctual"),
            "lamp",
            "KHR_lights_punctual",
        ),
        "node_not_object": (("nodes", 1), 7, "node 1"),
        "attributes_string": (
            ("meshes", 0, "primitives", 0, "attributes"),
            "POSITION",
            "attributes",
        ),
    }
    for name, (path, value, key) in edits.items():
        doc = copy.deepcopy(base)
        _set(doc, path, value)
        yield Mutation(name, doc, False, key)


def collapse_mutations() -> Iterator[tuple[str, dict[str, Any], str]]:
    """Documents whose every instance's transform collapses the geometry (with a glTF camera,
    so automatic framing never sees them): each must be refused naming node 0."""
    base, _binary = rich_doc()
    for name, node_edit in {
        "matrix_zeros": {"matrix": [0.0] * 16},
        "scale_0": {"scale": [0, 0, 0]},
        "scale_1e-30": {"scale": [1e-30, 1e-30, 1e-30]},
    }.items():
        doc = copy.deepcopy(base)
        doc["nodes"][0].update(node_edit)
        yield name, doc, "node 0"
