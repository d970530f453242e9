"""Traces edited and written back with valid CRCs, and traces with a flipped byte: open_trace
verifies what rtsim-sim verifies (counts, frames, structure, CRCs) and names the section; both
refuse the same inputs; nothing crashes, hangs or answers wrongly with exit 0."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import rtsim_trace
from rtsim.launcher import find_sim
from trace_forge import read_sections, write_trace
from trace_mutations import COUNT_EDITS, FRAME_EDITS, empty_first_frame, random_edits


def _sim(trace: Path, run: Path, *sets: str) -> subprocess.CompletedProcess[str]:
    cmd = [str(find_sim()), str(trace), "-o", str(run)]
    for s in sets:
        cmd += ["--set", s]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("hostile") / "small"
    rtsim_trace("cornell", "-o", str(out), "--resolution", "12x8")
    return out


@pytest.fixture(scope="module")
def animated(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("hostile") / "grove"
    rtsim_trace(
        "grove", "-o", str(out), "--resolution", "8x6", "--frames", "3", "--workload", "primary"
    )
    return out


def _forge(good: Path, out: Path, edit) -> tuple[Path, object]:
    sections = read_sections(good / "trace.rtt")
    expected = edit(sections)
    write_trace(out / "trace.rtt", sections)
    manifest = good / "manifest.json"
    (out / "manifest.json").write_text(manifest.read_text())
    return out, expected


def _both_refuse(trace: Path, run: Path, fragment: str) -> None:
    sim = _sim(trace, run)
    assert sim.returncode == 2 and fragment in sim.stderr, sim.stderr
    assert f"{trace / 'trace.rtt'}: " in sim.stderr
    with pytest.raises(rtsim.RtsimError) as info:
        rtsim.open_trace(trace)
    assert fragment in str(info.value) and str(trace / "trace.rtt") in str(info.value)


@pytest.mark.parametrize("edit", COUNT_EDITS, ids=lambda e: e.__name__)
def test_count_and_structure_edits_refused_by_both(edit, small: Path, tmp_path: Path) -> None:
    trace, fragment = _forge(small, tmp_path / "t", edit)
    _both_refuse(trace, tmp_path / "run", fragment)


@pytest.mark.parametrize("edit", FRAME_EDITS, ids=lambda e: e.__name__)
def test_frame_table_edits_refused_by_both(edit, animated: Path, tmp_path: Path) -> None:
    trace, fragment = _forge(animated, tmp_path / "t", edit)
    _both_refuse(trace, tmp_path / "run", fragment)


@pytest.mark.parametrize("section", ["rays", "hits", "work"])
def test_flipped_byte_named_by_section(section: str, small: Path, tmp_path: Path) -> None:
    """A byte flipped after writing (CRC not repaired): open_trace refuses when the section is
    read (RAYS when opening), naming it, as rtsim-sim does."""
    sections = read_sections(small / "trace.rtt")
    data = (small / "trace.rtt").read_bytes()
    payload = bytes(sections[section])
    offset = data.find(payload)
    corrupt = bytearray(data)
    corrupt[offset + 7] ^= 0x10
    trace = tmp_path / "flip"
    trace.mkdir()
    (trace / "trace.rtt").write_bytes(bytes(corrupt))
    label = section.upper()
    sim = _sim(trace, tmp_path / "run")
    assert sim.returncode == 2 and f"checksum mismatch in section {label}" in sim.stderr
    with pytest.raises(rtsim.RtsimError, match=f"checksum mismatch in section {label} chunk 0"):
        t = rtsim.open_trace(trace)
        getattr(t, section)  # HITS and WORK: checked on first read


def test_crc_repaired_hit_edit_is_a_mismatch_not_a_pass(small: Path, tmp_path: Path) -> None:
    """A reference hit changed with its CRC repaired reads as valid; the simulation then
    differs from it: exit 3, never a silent exit 0."""
    sections = read_sections(small / "trace.rtt")
    hits = np.frombuffer(sections["hits"], dtype=[("prim", "<i4"), ("rest", "V16")])
    i = int(np.flatnonzero(hits["prim"] >= 0)[0])
    hits["prim"][i] += 1
    trace = tmp_path / "t"
    write_trace(trace / "trace.rtt", sections)
    assert _sim(trace, tmp_path / "run").returncode == 3


def test_empty_first_frame_simulates(animated: Path, tmp_path: Path) -> None:
    trace, _ = _forge(animated, tmp_path / "t", empty_first_frame)
    assert len(rtsim.open_trace(trace).frames) == 3
    # Also through the shaded frame loop, whose first frame's camera rays are the first frame
    # with rays (an empty frame has no wavefront: its figures are still recorded, in order).
    for name, sets in (("functional", ["fidelity=functional"]), ("approx", ["fidelity=approx"]),
                       ("shaded", ["fidelity=approx", "shading.enabled=true"])):  # fmt: skip
        sim = _sim(trace, tmp_path / f"run-{name}", *sets)
        assert sim.returncode == 0, sim.stderr
        stats = json.loads((tmp_path / f"run-{name}" / "stats.json").read_text())
        frames = stats["frames"]
        assert frames[0]["rays"] == 0 and [f["frame"] for f in frames] == [0, 1, 2]
        if name == "shaded":
            assert stats["validation"]["order_violations"] == 0
            assert stats["model"]["shading"]["breakdown"]["raygen"] > 0


def test_bad_manifest_frames_block_refused_before_the_run(animated: Path, tmp_path: Path) -> None:
    trace, _ = _forge(animated, tmp_path / "t", lambda s: None)
    manifest = json.loads((trace / "manifest.json").read_text())
    manifest["frames"]["per_frame"][1] = "fast"
    (trace / "manifest.json").write_text(json.dumps(manifest))
    sim = _sim(trace, tmp_path / "run")
    assert sim.returncode == 2, sim.stderr
    assert f"{trace / 'manifest.json'}: 'frames.per_frame[1]' must be an object" in sim.stderr
    assert not (tmp_path / "run" / "stats.json").exists()


@pytest.mark.parametrize("seed", [1, 2])
def test_random_crc_repaired_edits(seed: int, small: Path, tmp_path: Path) -> None:
    """Random bytes of every section changed, CRCs repaired: rtsim-sim ends with 0, 2 or 3
    (never a signal or a hang), and whatever open_trace refuses, rtsim-sim refuses too."""
    outcomes = []
    for name, sections in random_edits(read_sections(small / "trace.rtt"), seed, 24):
        trace = tmp_path / name
        write_trace(trace / "trace.rtt", sections)
        sim = _sim(trace, tmp_path / f"run-{name}", "fidelity=functional")
        assert sim.returncode in (0, 2, 3), (name, sim.returncode, sim.stderr)
        try:
            t = rtsim.open_trace(trace)
            t.hits, t.work  # noqa: B018 (read: verifies their CRCs)
            opened = True
        except rtsim.RtsimError:
            opened = False
        assert opened or sim.returncode == 2, (name, sim.stderr)
        outcomes.append(sim.returncode)
    assert 2 in outcomes  # the edits reach the checks (not all land in ignored bytes)


def test_grid_with_overlapping_cell_lists_refused(tmp_path: Path) -> None:
    """Every cell listing every reference: a ray would test cells x references triangles."""
    good = tmp_path / "grid"
    rtsim_trace("cornell", "-o", str(good), "--resolution", "8x6", "--accel", "grid")

    def overlap(s) -> str:
        cells = np.frombuffer(s["RG00"], dtype=[("first_ref", "<u4"), ("ref_count", "<u4")])
        refs = len(s["RG01"]) // 4
        cells["first_ref"], cells["ref_count"] = 0, refs
        return "lists must be back to back"

    trace, fragment = _forge(good, tmp_path / "t", overlap)
    _both_refuse(trace, tmp_path / "run", fragment)


@pytest.mark.parametrize("sampling", ["sampling.fraction=1.0", "sampling.count=1"])
def test_sample_of_the_whole_small_trace_runs_exact(
    sampling: str, small: Path, tmp_path: Path
) -> None:
    sim = _sim(small, tmp_path / "run", sampling)
    assert sim.returncode == 0, sim.stderr
    summary = json.loads((tmp_path / "run" / "stats.json").read_text())["summary"]
    assert summary["sampled"] is False and summary["rays"] == rtsim.open_trace(small).ray_count


@pytest.mark.parametrize("kind", ["fifo", "dev_zero"])
def test_trace_that_is_a_special_file(kind: str, tmp_path: Path) -> None:
    """A FIFO would block the reader's open and /dev/zero read without end: both refused."""
    trace = tmp_path / "t"
    trace.mkdir()
    if kind == "fifo":
        os.mkfifo(trace / "trace.rtt")
    else:
        (trace / "trace.rtt").symlink_to("/dev/zero")
    sim = _sim(trace, tmp_path / "run")  # times out (fails) if it blocks
    assert sim.returncode == 2 and "is not a regular file" in sim.stderr, sim.stderr
    with pytest.raises(rtsim.RtsimError, match="not a regular file"):
        rtsim.open_trace(trace)
