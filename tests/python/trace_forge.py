"""Writes trace files byte by byte (docs/trace_format.md) with valid CRCs and any content, so
tests can hand the reader and the simulator traces that are well-formed but wrong inside.

``read_sections`` takes a real trace apart; ``write_trace`` puts (possibly edited) sections back
together with fresh CRCs. Everything here is independent of the C++ writer on purpose.

Sections are named ``rays``, ``hits``, ``work``, ``accel`` (the structure's JSON descriptor) and
``RG00``.. (the image's regions). A binary BVH (``bvh2``) has its nodes in ``RG00`` and its
triangles in ``RG01``; ``bvh_nodes`` and ``triangles`` name them too.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

MAGIC = b"RTSIMTRC"
VERSION = 6
HEADER_BYTES = 64
ENTRY_BYTES = 64
ALIGN = 64
CHUNK_BYTES = 1 << 20

FOURCC = {
    "rays": 0x53594152,
    "hits": 0x53544948,
    "work": 0x4B524F57,
    "accel": 0x4C434341,
}
RECORD_BYTES = {"rays": 40, "hits": 20, "work": 40, "accel": 1}
#: WORK records before version 6 (no sphere_tests, capsule_tests).
WORK_BYTES_V5 = 32
#: bvh2's region sections under the names older tests use.
ALIASES = {"bvh_nodes": "RG00", "triangles": "RG01"}


def _fourcc(name: str) -> int:
    if name in FOURCC:
        return FOURCC[name]
    return int.from_bytes(name.encode("ascii"), "little")  # "RG00" -> 'R','G','0','0'


class Sections(dict):
    """Section payloads by name, with each section's record size (`record_bytes`)."""

    def __init__(self) -> None:
        super().__init__()
        self.record_bytes: dict[str, int] = dict(RECORD_BYTES)

    def __getitem__(self, name: str) -> bytearray:
        return super().__getitem__(ALIASES.get(name, name))

    def __setitem__(self, name: str, value: bytearray) -> None:
        super().__setitem__(ALIASES.get(name, name), value)


def as_version_5_work(sections: Sections) -> None:
    """Narrows the WORK records to version 5's 32 bytes (sphere_tests dropped), for a trace
    written as an older version."""
    rb = sections.record_bytes["work"]
    rows = np.frombuffer(bytes(sections["work"]), np.uint8).reshape(-1, rb)
    sections["work"] = bytearray(rows[:, :WORK_BYTES_V5].tobytes())
    sections.record_bytes["work"] = WORK_BYTES_V5


def _align(x: int) -> int:
    return (x + ALIGN - 1) // ALIGN * ALIGN


def read_sections(path: Path) -> Sections:
    """The payload of every section of a trace file, by name (no CRC checks)."""
    data = Path(path).read_bytes()
    count = struct.unpack_from("<I", data, 16)[0]
    table = struct.unpack_from("<Q", data, 24)[0]
    names = {v: k for k, v in FOURCC.items()}
    out = Sections()
    for i in range(count):
        kind, rb, _n, offset, nbytes = struct.unpack_from("<IIQQQ", data, table + i * ENTRY_BYTES)
        name = names.get(kind) or kind.to_bytes(4, "little").decode("ascii")
        out[name] = bytearray(data[offset : offset + nbytes])
        out.record_bytes[name] = rb
    return out


def write_trace(path: Path, sections: dict[str, bytes], version: int = VERSION) -> Path:
    """Writes a trace with the given payloads (names as read_sections gives them), every CRC
    valid. Record sizes come from `sections.record_bytes` when it has them."""
    record_bytes = getattr(sections, "record_bytes", RECORD_BYTES)
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
        rb = record_bytes[name]
        table += struct.pack(
            "<IIQQQIIQ16x",
            _fourcc(name),
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
