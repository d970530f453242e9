"""Writes trace files byte by byte (docs/trace_format.md) with valid CRCs and any content, so
tests can hand the reader and the simulator traces that are well-formed but wrong inside.

``read_sections`` takes a real trace apart; ``write_trace`` puts (possibly edited) sections back
together with fresh CRCs. Everything here is independent of the C++ writer on purpose.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

MAGIC = b"RTSIMTRC"
VERSION = 2
HEADER_BYTES = 64
ENTRY_BYTES = 64
ALIGN = 64
CHUNK_BYTES = 1 << 20

FOURCC = {
    "rays": 0x53594152,
    "hits": 0x53544948,
    "work": 0x4B524F57,
    "bvh_nodes": 0x45444F4E,
    "triangles": 0x53495254,
}
RECORD_BYTES = {"rays": 40, "hits": 20, "work": 20, "bvh_nodes": 64, "triangles": 48}


def _align(x: int) -> int:
    return (x + ALIGN - 1) // ALIGN * ALIGN


def read_sections(path: Path) -> dict[str, bytearray]:
    """The payload of every known section of a trace file, by name (no CRC checks)."""
    data = Path(path).read_bytes()
    count = struct.unpack_from("<I", data, 16)[0]
    table = struct.unpack_from("<Q", data, 24)[0]
    names = {v: k for k, v in FOURCC.items()}
    out: dict[str, bytearray] = {}
    for i in range(count):
        kind, _rb, _n, offset, nbytes = struct.unpack_from("<IIQQQ", data, table + i * ENTRY_BYTES)
        out[names[kind]] = bytearray(data[offset : offset + nbytes])
    return out


def write_trace(path: Path, sections: dict[str, bytes], version: int = VERSION) -> Path:
    """Writes a trace with the given payloads (names as in FOURCC), every CRC valid."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    body = bytearray(HEADER_BYTES)
    entries = []
    for name, payload in sections.items():
        body += bytes(_align(len(body)) - len(body))
        entries.append([name, len(body), len(payload)])
        body += payload
    for entry in entries:
        name, offset, nbytes = entry
        payload = bytes(body[offset : offset + nbytes])
        body += bytes(_align(len(body)) - len(body))
        entry.append(len(body))
        for c in range(0, nbytes, CHUNK_BYTES):
            body += struct.pack("<I", zlib.crc32(payload[c : c + CHUNK_BYTES]))
    body += bytes(_align(len(body)) - len(body))
    table_offset = len(body)
    table = bytearray()
    for name, offset, nbytes, crc_offset in entries:
        rb = RECORD_BYTES[name]
        table += struct.pack(
            "<IIQQQIIQ16x",
            FOURCC[name],
            rb,
            nbytes // rb,
            offset,
            nbytes,
            CHUNK_BYTES,
            0,
            crc_offset,
        )
    table += struct.pack("<I", zlib.crc32(bytes(table)))
    body += table
    head = struct.pack(
        "<8sIIIIQQQ12x",
        MAGIC,
        version,
        HEADER_BYTES,
        len(entries),
        0,
        table_offset,
        len(table),
        len(body),
    )
    head += struct.pack("<I", zlib.crc32(head))
    body[0:HEADER_BYTES] = head
    path.write_bytes(bytes(body))
    return path


def nodes_view(payload: bytearray) -> np.ndarray:
    """The NODE payload as a writable (n,) array with child_ref and child_count fields."""
    dtype = np.dtype(
        [("bounds", "<f4", (12,)), ("child_ref", "<u4", (2,)), ("child_count", "<u4", (2,))]
    )
    return np.frombuffer(payload, dtype=dtype)


def rays_view(payload: bytearray) -> np.ndarray:
    """The RAYS payload as a writable (n,) array (kind is a field)."""
    dtype = np.dtype(
        [
            ("origin", "<f4", (3,)),
            ("tmin", "<f4"),
            ("direction", "<f4", (3,)),
            ("tmax", "<f4"),
            ("pixel", "<u4"),
            ("kind", "u1"),
            ("flags", "u1"),
            ("depth", "<u2"),
        ]
    )
    return np.frombuffer(payload, dtype=dtype)
