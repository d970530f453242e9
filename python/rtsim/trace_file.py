"""Trace folders as numpy arrays: each section of ``trace.rtt`` memory-mapped at its offset.

The dtypes below mirror the packed C++ records in ``traces/format/trace_format.h`` field by
field; ``open_trace`` checks each against the record size the file declares, so a layout change
on one side is caught instead of silently misread.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from rtsim._core import RtsimError, trace_sections, verify_trace
from rtsim.kinds import RAY_KINDS as RAY_KINDS  # RayKind values stored in RayRecord.kind

TRACE_FILE = "trace.rtt"
MANIFEST_FILE = "manifest.json"

#: RayRecord (40 bytes).
RAY_DTYPE = np.dtype(
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
#: HitRecord (20 bytes).
HIT_DTYPE = np.dtype([("prim", "<i4"), ("inst", "<i4"), ("t", "<f4"), ("u", "<f4"), ("v", "<f4")])
#: WorkRecord (32 bytes): the neutral work counts of every acceleration structure.
WORK_DTYPE = np.dtype(
    [
        ("steps", "<u4"),
        ("box_tests", "<u4"),
        ("tri_tests", "<u4"),
        ("anyhit_calls", "<u4"),
        ("transforms", "<u4"),
        ("cell_steps", "<u4"),
        ("plane_tests", "<u4"),
        ("refs", "<u4"),
    ]
)
#: bvh2 HwNode (64 bytes): two child boxes, child references and leaf sizes.
#: bounds[axis][0 = min, 1 = max][child] (docs/bvh_layout.md).
NODE_DTYPE = np.dtype(
    [
        ("bounds", "<f4", (3, 2, 2)),
        ("child_ref", "<u4", (2,)),
        ("child_count", "<u4", (2,)),
    ]
)


def wide_node_dtype(width: int) -> np.dtype:
    """fp32 wide node WideNode<N> (32 N bytes): bounds[axis][0 = min, 1 = max][slot], child
    references, child counts (0 interior, 0xFFFFFFFF empty, else leaf size; docs/accel.md)."""
    return np.dtype(
        [
            ("bounds", "<f4", (3, 2, width)),
            ("child_ref", "<u4", (width,)),
            ("child_count", "<u4", (width,)),
        ]
    )


#: CwNode8 (80 bytes): compressed 8-wide node (Ylitie et al. 2017; docs/accel.md).
CWNODE8_DTYPE = np.dtype(
    [
        ("p", "<f4", (3,)),
        ("e", "u1", (3,)),
        ("imask", "u1"),
        ("base_node", "<u4"),
        ("base_tri", "<u4"),
        ("meta", "u1", (8,)),
        ("qlo", "u1", (3, 8)),
        ("qhi", "u1", (3, 8)),
    ]
)
#: CwNode6 (64 bytes): compressed 6-wide node; bases = base_node | base_tri << 28 (56 bits, LE).
CWNODE6_DTYPE = np.dtype(
    [
        ("p", "<f4", (3,)),
        ("e", "u1", (3,)),
        ("meta", "u1", (6,)),
        ("bases", "u1", (7,)),
        ("qlo", "u1", (3, 6)),
        ("qhi", "u1", (3, 6)),
    ]
)
#: HwTriangle (48 bytes).
TRIANGLE_DTYPE = np.dtype(
    [
        ("v0", "<f4", (3,)),
        ("v1", "<f4", (3,)),
        ("v2", "<f4", (3,)),
        ("prim", "<u4"),
        ("inst", "<u4"),
        ("flags", "<u4"),
    ]
)

#: grid GridCell (8 bytes): the cell's list in prim_refs (docs/accel.md, "grid").
CELL_DTYPE = np.dtype([("first_ref", "<u4"), ("ref_count", "<u4")])

#: kdtree KdNode (8 bytes; docs/accel.md, "kdtree"): word0 = split (f32 bits) or first ref;
#: word1 = axis (bits 0-1, 3: leaf) | above child or ref count << 2.
KDNODE_DTYPE = np.dtype([("word0", "<u4"), ("word1", "<u4")])
#: bih BihNode (12 bytes; docs/accel.md, "bih"): word0 = axis (3: leaf) | left child or first
#: triangle << 2; word1, word2 = the clip planes (f32 bits), or for a leaf the count and 0.
BIHNODE_DTYPE = np.dtype([("word0", "<u4"), ("word1", "<u4"), ("word2", "<u4")])
#: octree OctNode (16 bytes; docs/accel.md, "octree"): word0 = child mask (0: leaf) | first child
#: << 8; interior: centre x, y, z; leaf: first ref, ref count, 0.
OCTNODE_DTYPE = np.dtype([("word0", "<u4"), ("word1", "<u4"), ("word2", "<u4"), ("word3", "<u4")])

#: two_level InstanceRecord (128 bytes; docs/accel.md, "Two-level structures").
INSTANCE_DTYPE = np.dtype(
    [
        ("world_to_object", "<f4", (3, 4)),
        ("blas", "<u4"),
        ("prim_base", "<u4"),
        ("instance", "<u4"),
        ("reserved0", "<u4"),
        ("object_to_world", "<f4", (3, 4)),
        ("reserved1", "<u4", (4,)),
    ]
)

#: Section name (as the C++ section_name() spells it, lower-cased) -> record dtype.
#: FrameRecord (16 bytes): an animated trace's frame, rays [first_ray, first_ray + rays).
FRAME_DTYPE = np.dtype([("first_ray", "<u8"), ("rays", "<u8")])

SECTION_DTYPES: dict[str, np.dtype] = {
    "rays": RAY_DTYPE,
    "hits": HIT_DTYPE,
    "work": WORK_DTYPE,
    "accl": np.dtype("u1"),
    "frms": FRAME_DTYPE,
}
#: Layouts of image regions this package knows, by (structure kind, region name); ("*", name)
#: for every kind. Other regions are read as raw records (docs/accel.md documents them).
REGION_DTYPES: dict[tuple[str, str], np.dtype] = {
    ("*", "triangles"): TRIANGLE_DTYPE,
    ("bvh2", "nodes"): NODE_DTYPE,
    ("bvh4", "nodes"): wide_node_dtype(4),
    ("bvh6", "nodes"): wide_node_dtype(6),
    ("bvh8", "nodes"): wide_node_dtype(8),
    ("bvh8_octant", "nodes"): wide_node_dtype(8),
    ("cwbvh6", "nodes"): CWNODE6_DTYPE,
    ("cwbvh8", "nodes"): CWNODE8_DTYPE,
    ("cwbvh8_octant", "nodes"): CWNODE8_DTYPE,
    ("grid", "cells"): CELL_DTYPE,
    ("grid", "prim_refs"): np.dtype("<u4"),
    ("kdtree", "nodes"): KDNODE_DTYPE,
    ("kdtree", "prim_refs"): np.dtype("<u4"),
    ("bih", "nodes"): BIHNODE_DTYPE,
    ("octree", "nodes"): OCTNODE_DTYPE,
    ("octree", "prim_refs"): np.dtype("<u4"),
    ("two_level", "tlas_nodes"): NODE_DTYPE,
    ("two_level", "instances"): INSTANCE_DTYPE,
    ("two_level", "blas_triangles"): TRIANGLE_DTYPE,
}


@dataclass(frozen=True)
class Section:
    """One section of a trace file, as its section table describes it."""

    name: str
    record_bytes: int
    record_count: int
    offset: int
    bytes: int


@dataclass
class Trace:
    """An opened trace folder. Record arrays are read-only memory maps, loaded on access."""

    path: Path
    folder: Path
    sections: dict[str, Section]
    manifest: dict[str, Any] = field(default_factory=dict)

    def _map(self, name: str) -> np.ndarray:
        section = self.sections.get(name)
        if section is None:
            raise RtsimError(f"{self.path}: trace has no '{name}' section")
        dtype = SECTION_DTYPES[name]
        if section.record_count == 0:
            return np.zeros(0, dtype=dtype)
        return np.memmap(
            self.path, dtype=dtype, mode="r", offset=section.offset, shape=(section.record_count,)
        )

    def has(self, name: str) -> bool:
        return name in self.sections

    @cached_property
    def accel(self) -> dict[str, Any]:
        """The acceleration structure's descriptor: kind, params, stats, bounds, regions."""
        raw = bytes(self._map("accl"))
        try:
            data = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as err:
            raise RtsimError(f"{self.path}: section ACCL is not JSON ({err})") from err
        if not isinstance(data, dict) or not isinstance(data.get("regions"), list):
            raise RtsimError(f"{self.path}: section ACCL is not a structure descriptor")
        return data

    def region(self, name: str) -> np.ndarray:
        """Records of an image region: a structured array where the layout is known (bvh2
        nodes, grid cells and prim_refs, triangles), else a (count, record_bytes) array of bytes."""
        regions = self.accel["regions"]
        for index, info in enumerate(regions):
            if info.get("name") != name:
                continue
            kind = str(self.accel.get("kind", ""))
            dtype = REGION_DTYPES.get((kind, name), REGION_DTYPES.get(("*", name)))
            record_bytes = int(info["record_bytes"])
            count = int(info["count"])
            if dtype is None or dtype.itemsize != record_bytes:
                dtype = np.dtype(("u1", (record_bytes,)))
            section = self.sections.get(f"rg{index:02d}")
            if count == 0 or section is None:
                return np.zeros(0, dtype=dtype)
            return np.memmap(
                self.path, dtype=dtype, mode="r", offset=section.offset, shape=(count,)
            )
        names = ", ".join(str(r.get("name")) for r in regions)
        raise RtsimError(f"{self.path}: the structure has no region '{name}' (has: {names})")

    @cached_property
    def rays(self) -> np.ndarray:
        return self._map("rays")

    @cached_property
    def hits(self) -> np.ndarray:
        return self._map("hits")

    @cached_property
    def work(self) -> np.ndarray:
        return self._map("work")

    @cached_property
    def frames(self) -> np.ndarray:
        """The frames (first_ray, rays): the FRMS table of an animated trace (`rtsim trace
        --frames N`, docs/accel.md "Frames"), else one frame of every ray."""
        if self.has("frms"):
            return np.asarray(self._map("frms"))
        return np.array([(0, len(self.rays))], dtype=FRAME_DTYPE)

    def frame(self, f: int) -> slice:
        """The rays of frame f, as a slice of rays, hits and work."""
        first, count = (int(x) for x in self.frames[f])
        return slice(first, first + count)

    @cached_property
    def nodes(self) -> np.ndarray | None:
        """The structure's node region, if it has one."""
        return self.region("nodes") if self._has_region("nodes") else None

    @cached_property
    def triangles(self) -> np.ndarray | None:
        return self.region("triangles") if self._has_region("triangles") else None

    def _has_region(self, name: str) -> bool:
        return self.has("accl") and any(r.get("name") == name for r in self.accel["regions"])

    @property
    def ray_count(self) -> int:
        return self.sections["rays"].record_count if self.has("rays") else 0

    @property
    def scene_name(self) -> str:
        scene = self.manifest.get("scene")
        if isinstance(scene, dict):
            for key in ("name", "source", "path"):
                if isinstance(scene.get(key), str):
                    return Path(scene[key]).stem if key != "name" else scene[key]
        if isinstance(scene, str):
            return Path(scene).stem
        return self.folder.name

    def verify(self) -> None:
        """Checks the CRC32 of every chunk of every section (raises RtsimError)."""
        verify_trace(self.path)


def _section_name(info: dict[str, Any]) -> str:
    return str(info.get("kind", "")).lower()


def _resolve(path: str | Path) -> tuple[Path, Path]:
    path = Path(path)
    if path.is_dir():
        return path / TRACE_FILE, path
    return path, path.parent


def open_trace(path: str | Path) -> Trace:
    """Opens a trace folder (or its ``trace.rtt``); validates the header and section table.

    Raises RtsimError naming the file if it is missing, truncated, corrupted or of another
    version, if a section's record size differs from the dtype this package expects, if its BVH
    image is not a tree the traversal can walk (rtsim._core.trace_sections checks it), if a ray
    has an unknown kind, or if manifest.json is not a JSON object.
    """
    file, folder = _resolve(path)
    if not file.is_file():
        raise RtsimError(f"{file}: no trace file (expected a trace folder or a .rtt file)")
    sections: dict[str, Section] = {}
    for info in trace_sections(file):
        name = _section_name(info)
        section = Section(
            name=name,
            record_bytes=int(info["record_bytes"]),
            record_count=int(info["record_count"]),
            offset=int(info["offset"]),
            bytes=int(info["bytes"]),
        )
        dtype = SECTION_DTYPES.get(name)
        if dtype is not None and dtype.itemsize != section.record_bytes:
            raise RtsimError(
                f"{file}: section '{name}' has {section.record_bytes}-byte records but this "
                f"rtsim reads {dtype.itemsize}-byte records (trace written by another version?)"
            )
        sections[name] = section
    trace = Trace(path=file, folder=folder, sections=sections, manifest=_read_manifest(folder))
    _check_ray_kinds(trace)
    return trace


def _read_manifest(folder: Path) -> dict[str, Any]:
    """The trace's manifest.json (a JSON object), {} if there is none."""
    path = folder / MANIFEST_FILE
    if not path.exists():
        return {}
    if not path.is_file():
        raise RtsimError(f"{path}: is not a file (expected the trace's manifest)")
    try:
        manifest = json.loads(path.read_bytes())
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as err:
        raise RtsimError(f"{path}: not valid JSON ({type(err).__name__}: {err})") from err
    if not isinstance(manifest, dict):
        raise RtsimError(
            f"{path}: expected a JSON object (the trace manifest), found {type(manifest).__name__}"
        )
    return manifest


def _check_ray_kinds(trace: Trace) -> None:
    """Refuses a ray whose kind this rtsim does not know, naming the first one."""
    if not trace.has("rays") or trace.ray_count == 0:
        return
    kinds = trace.rays["kind"]
    bad = np.flatnonzero(kinds >= len(RAY_KINDS))
    if bad.size:
        first = int(bad[0])
        raise RtsimError(
            f"{trace.path}: ray {first} has unknown ray kind {int(kinds[first])} "
            f"(known kinds: 0..{len(RAY_KINDS) - 1}); {bad.size} such rays"
        )
