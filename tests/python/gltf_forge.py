"""Small glTF and GLB files built in memory for the bad-input tests (and the fuzz seed corpus):
one triangle (or an instanced one), with hooks to break any part of the document or container.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path
from typing import Any

import numpy as np

GLB_MAGIC = 0x46546C67  # "glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942


def triangle_doc(positions: np.ndarray | None = None) -> tuple[dict[str, Any], bytes]:
    """A one-mesh document (no buffer uri yet) and its binary buffer: positions then u16 indices."""
    if positions is None:
        positions = np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    pos = np.ascontiguousarray(positions, dtype="<f4").tobytes()
    idx = np.arange(len(positions), dtype="<u2").tobytes()
    idx += bytes((-len(idx)) % 4)
    doc: dict[str, Any] = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(pos) + len(idx)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(positions) * 2},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": len(positions)},
            {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": len(positions)},
        ],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"name": "root", "mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    return doc, pos + idx


def write_gltf(path: Path, doc: dict[str, Any], binary: bytes | None = None) -> Path:
    """A .gltf with the buffer embedded as a data URI (when given)."""
    doc = json.loads(json.dumps(doc))
    if binary is not None:
        uri = "data:application/octet-stream;base64," + base64.b64encode(binary).decode()
        doc["buffers"][0]["uri"] = uri
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc))
    return path


def glb_bytes(doc: dict[str, Any] | bytes, binary: bytes | None, version: int = 2) -> bytes:
    """A GLB container: header, JSON chunk (padded with spaces), BIN chunk (padded with zeros)."""
    text = doc if isinstance(doc, bytes) else json.dumps(doc).encode()
    text += b" " * ((-len(text)) % 4)
    out = struct.pack("<II", len(text), CHUNK_JSON) + text
    if binary is not None:
        binary += bytes((-len(binary)) % 4)
        out += struct.pack("<II", len(binary), CHUNK_BIN) + binary
    return struct.pack("<III", GLB_MAGIC, version, 12 + len(out)) + out


def write_glb(
    path: Path, doc: dict[str, Any] | bytes, binary: bytes | None, version: int = 2
) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(glb_bytes(doc, binary, version))
    return path


def png_bytes(width: int, height: int) -> bytes:
    """An all-black greyscale PNG (compresses to almost nothing, decodes to width x height)."""
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    raw = zlib.compressobj(9)
    row = bytes(1 + width)
    body = b"".join(raw.compress(row) for _ in range(height)) + raw.flush()
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", body) + chunk(b"IEND", b"")
