"""Edits of a trace's sections, written back with every CRC repaired (trace_forge), generated at
test time (and as fuzz seeds by scripts/make_fuzz_corpus.py). Each named edit says which section
the refusal must name; `random_edits` flips bytes anywhere with CRCs repaired, for the property
that whatever open_trace refuses rtsim-sim refuses too and nothing crashes or hangs."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator

import numpy as np

from trace_forge import Sections

FRAME = np.dtype([("first_ray", "<u8"), ("rays", "<u8")])


def _drop_last(name: str) -> Callable[[Sections], str]:
    def edit(s: Sections) -> str:
        s[name] = s[name][: -s.record_bytes[name]]
        return "different record counts"

    edit.__name__ = f"{name}_one_record_short"
    return edit


def _extra(name: str) -> Callable[[Sections], str]:
    def edit(s: Sections) -> str:
        s[name] = s[name] + s[name][: s.record_bytes[name]]
        return "different record counts"

    edit.__name__ = f"{name}_one_record_more"
    return edit


def accel_region_renamed(s: Sections) -> str:
    accel = json.loads(bytes(s["accel"]))
    accel["regions"][-1]["name"] = "tris"
    s["accel"] = bytearray(json.dumps(accel).encode())
    return "no region"


COUNT_EDITS = [
    _drop_last("hits"),
    _drop_last("work"),
    _extra("hits"),
    _extra("work"),
    accel_region_renamed,
]


def _frames(s: Sections) -> np.ndarray:
    return np.frombuffer(s["FRMS"], dtype=FRAME)


def frames_gap(s: Sections) -> str:
    f = _frames(s)
    f[1]["first_ray"] += 1
    return "FRMS"


def frames_short(s: Sections) -> str:
    f = _frames(s)
    f[-1]["rays"] -= 1
    return "FRMS"


def frames_overrun(s: Sections) -> str:
    f = _frames(s)
    f[-1]["rays"] = 1 << 40
    return "FRMS"


def frames_one_more(s: Sections) -> str:
    s["FRMS"] = s["FRMS"] + s["FRMS"][-16:]
    return "frame(s)"


FRAME_EDITS = [frames_gap, frames_short, frames_overrun, frames_one_more]


def empty_first_frame(s: Sections) -> None:
    """Valid: frame 0's rays (and their hits and work) removed, so frame 0 holds none (as when
    a workload of secondary rays finds nothing to bounce from in the first frame)."""
    f = _frames(s)
    n0 = int(f[0]["rays"])
    for name in ("rays", "hits", "work"):
        s[name] = s[name][n0 * s.record_bytes[name] :]
    if "SHAD" in s:
        # Shading records too, their parents renumbered (a frame's rays spawn only its own).
        shade = np.frombuffer(bytes(s["SHAD"][n0 * 32 :]), dtype=np.uint8).copy().reshape(-1, 32)
        parent = shade[:, :8].copy().view(np.int64).reshape(-1)
        parent[parent >= 0] -= n0
        shade[:, :8] = parent.view(np.uint8).reshape(-1, 8)
        s["SHAD"] = bytearray(shade.tobytes())
    f["first_ray"][1:] -= n0
    f[0]["rays"] = 0


def random_edits(sections: Sections, seed: int, count: int) -> Iterator[tuple[str, Sections]]:
    """`count` copies of the trace, each with 1 to 4 random bytes of one section changed."""
    rng = np.random.default_rng(seed)
    names = [n for n in sections if len(sections[n])]
    for i in range(count):
        name = names[i % len(names)]
        copy = Sections()
        copy.record_bytes = dict(sections.record_bytes)
        for n in sections:
            copy[n] = bytearray(sections[n])
        data = copy[name]
        for _ in range(int(rng.integers(1, 5))):
            data[int(rng.integers(len(data)))] = int(rng.integers(256))
        yield f"{name}_{i}", copy
