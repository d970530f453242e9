"""Trace folders as numpy arrays: each section of ``trace.rtt`` memory-mapped at its offset.

Every record is read with the layout C++ declares for it (traces/common/record_layout.h): the
sections' through ``rtsim._core.section_layouts()``, an image region's from the trace's own ACCL
descriptor, so nothing here re-declares a layout and a new structure's regions read as records
with no change here. ``open_trace`` checks each section's record size against the file's.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from rtsim._core import RtsimError, section_layouts, trace_sections, verify_trace
from rtsim.args import int_arg, path_arg
from rtsim.errors import RtsimIndexError
from rtsim.kinds import RAY_KINDS as RAY_KINDS  # RayKind values stored in RayRecord.kind

TRACE_FILE = "trace.rtt"
MANIFEST_FILE = "manifest.json"


def dtype_of(fields: list[dict[str, Any]], itemsize: int | None = None) -> np.dtype:
    """The numpy dtype of a record layout as C++ declares it (traces/common/record_layout.h):
    [{name, type, offset, shape}]; a single unnamed field is a plain scalar record."""
    if len(fields) == 1 and fields[0]["name"] == "":
        return np.dtype(fields[0]["type"])
    spec: dict[str, Any] = {
        "names": [f["name"] for f in fields],
        "formats": [(f["type"], tuple(f["shape"])) if f["shape"] else f["type"] for f in fields],
        "offsets": [f["offset"] for f in fields],
    }
    if itemsize is not None:
        spec["itemsize"] = itemsize
    return np.dtype(spec)


#: The trace sections' records (RayRecord, HitRecord, WorkRecord, FrameRecord), with the layouts
#: the C++ declares (rtsim._core.section_layouts); ACCL is JSON bytes.
SECTION_DTYPES: dict[str, np.dtype] = {
    name: dtype_of(fields) for name, fields in section_layouts().items()
}
SECTION_DTYPES["accl"] = np.dtype("u1")
RAY_DTYPE = SECTION_DTYPES["rays"]
HIT_DTYPE = SECTION_DTYPES["hits"]
WORK_DTYPE = SECTION_DTYPES["work"]
#: Bytes of a WORK record before version 6 (no sphere_tests; read widened, sphere_tests 0).
WORK_BYTES_V5 = 32
FRAME_DTYPE = SECTION_DTYPES["frms"]


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
        # Each record section's CRCs are checked on its first use (one streaming pass), as
        # rtsim-sim checks them: a flipped byte raises RtsimError naming the section and chunk.
        verify_trace(self.path, name.upper())
        dtype = SECTION_DTYPES[name]
        if section.record_count == 0:
            return np.zeros(0, dtype=dtype)
        if section.record_bytes < dtype.itemsize:
            return _widened(self.path, section, dtype)
        return np.memmap(
            self.path, dtype=dtype, mode="r", offset=section.offset, shape=(section.record_count,)
        )

    def has(self, name: str) -> bool:
        return name in self.sections

    def section(self, name: str) -> np.ndarray:
        """Records of a record section by its name ("SHAD", "TXFT", ...; docs/trace_format.md)."""
        return self._map(name.lower())

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
        """Records of an image region: a structured array in the layout the trace declares for
        it (nodes, triangles, cells, ...), else a (count, record_bytes) array of bytes."""
        regions = self.accel["regions"]
        for index, info in enumerate(regions):
            if info.get("name") != name:
                continue
            record_bytes = int(info["record_bytes"])
            count = int(info["count"])
            fields = info.get("fields")
            dtype = dtype_of(fields, record_bytes) if fields else np.dtype(("u1", (record_bytes,)))
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
        f = int_arg(f, "frame", 0, len(self.frames) - 1, RtsimIndexError)
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
        """Checks the CRC32 of every chunk of every section now (raises RtsimError). Opening
        checks the header, table, image regions and frame table; RAYS, HITS and WORK are
        checked when first read."""
        verify_trace(self.path)


def _widened(path: Path, section: Section, dtype: np.dtype) -> np.ndarray:
    """An older version's shorter records (WORK before version 6 has no sphere_tests) in this
    version's layout, the counters they predate zero (as the C++ reader widens them)."""
    stored = np.memmap(
        path, dtype=np.uint8, mode="r", offset=section.offset,
        shape=(section.record_count, section.record_bytes),
    )  # fmt: skip
    out = np.zeros((section.record_count, dtype.itemsize), dtype=np.uint8)
    out[:, : section.record_bytes] = stored
    wide = out.view(dtype).reshape(section.record_count)
    wide.flags.writeable = False
    return wide


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
    image is not a tree the traversal can walk (rtsim._core.trace_sections checks it), if RAYS,
    HITS and WORK differ in length or the frame table does not cover the rays, if a ray has an
    unknown kind, or if manifest.json is not a JSON object. RAYS is CRC-checked here, HITS and
    WORK when first read (``trace.hits``), each naming the section and chunk that failed.
    """
    file, folder = _resolve(path_arg(path, "path"))
    if not file.is_file():
        what = "not a regular file" if file.exists() else "no trace file"
        raise RtsimError(f"{file}: {what} (expected a trace folder or a .rtt file)")
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
        older_work = name == "work" and section.record_bytes == WORK_BYTES_V5
        if dtype is not None and dtype.itemsize != section.record_bytes and not older_work:
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


def verify_trace_file(path: str | Path) -> None:
    """Checks the CRC32 of every chunk of every section of a trace file (raises RtsimError
    naming the section and chunk)."""
    verify_trace(path_arg(path, "path"))


def trace_section_table(path: str | Path) -> list[dict[str, Any]]:
    """Validates a trace file's header, section table, structure image and frame table; returns
    its sections (kind, record_bytes, record_count, offset, bytes, chunk_bytes, crc_offset)."""
    return trace_sections(path_arg(path, "path"))
