"""The bad-input corpus, generated at test time: every case gives exit status 2 (or
RtsimError from Python) and a message naming the file and the element, key or ray.

Scene and trace cases run in-process through ``rtsim.cli.main`` and the Python API (fast);
trace-content cases run the real ``rtsim-sim``. Inputs come from gltf_forge and trace_forge.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import rtsim
from bad_corpus import SCENE_CASES, TRACE_CASES
from conftest import rtsim_trace
from gltf_forge import png_bytes, triangle_doc, write_gltf
from rtsim.cli import main
from rtsim.launcher import find_sim
from trace_forge import read_sections, write_trace

# ---------------------------------------------------------------------------------------------
# Scenes: `rtsim trace SCENE` exits 2 naming the file and the element.


@pytest.mark.parametrize("case", sorted(SCENE_CASES))
def test_bad_scene_exits_2(case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    make, fragments = SCENE_CASES[case]
    scene = make(tmp_path)
    code = main(["trace", str(scene), "-o", str(tmp_path / "out"), "--resolution", "8x8"])
    err = capsys.readouterr().err
    assert code == 2, err
    message = err.strip().splitlines()[-1]
    assert message.startswith("rtsim: error: "), err
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    assert not (tmp_path / "out" / "trace.rtt").exists()  # no trace of invalid rays written


@pytest.mark.parametrize(
    "case", ["deep_json", "non_utf8_bytes", "glb_byte_length_0", "no_triangles"]
)
def test_bad_scene_raises_rtsim_error(case: str, tmp_path: Path) -> None:
    make, fragments = SCENE_CASES[case]
    with pytest.raises(rtsim.RtsimError) as info:
        rtsim.load_scene(str(make(tmp_path)))
    assert all(f in str(info.value) for f in fragments), str(info.value)


@pytest.mark.parametrize(
    ("camera", "fragment"),
    [
        ("1e300,0,0,0,0,0,60", "finite single-precision"),
        ("nan,0,0,0,0,0,60", "finite single-precision"),
        ("1,2,3,1,2,3,60", "eye equals the target"),
    ],
)
def test_bad_camera_exits_2(
    camera: str, fragment: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main(["trace", "cornell", "-o", str(tmp_path / "t"), f"--camera={camera}"])
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert "--camera" in err and fragment in err, err


@pytest.mark.parametrize(
    ("camera", "fragment"),
    [
        (((1e25, 0, 0), (0, 0, 0), 60.0), "reaches 1e+25 from the camera eye"),
        (((float("nan"), 0, 0), (0, 0, 0), 60.0), "camera eye and target must be finite"),
        (((1, 2, 3), (1, 2, 3), 60.0), "equals the target"),
    ],
)
def test_bad_camera_raises_rtsim_error(camera: tuple, fragment: str, tmp_path: Path) -> None:
    with pytest.raises(rtsim.RtsimError, match="camera") as info:
        rtsim.trace_scene("cornell", tmp_path / "t", width=8, height=8, camera=camera)
    assert fragment in str(info.value)
    assert not (tmp_path / "t" / "trace.rtt").exists()


@pytest.mark.parametrize(
    "args",
    [
        ["trace", "hairball", "--hairball-triangles", "4294967296"],
        ["trace", "cornell", "--seed", "12345678901234567890123"],
        ["trace", "cornell", "--resolution", "99999999999x1"],
        ["scene", "hairball", "--hairball-triangles", "4294967296"],
    ],
)
def test_cli_integers_out_of_range(
    args: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main([*args, "-o", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert info.value.code == 2
    option = next(a for a in args if a.startswith("--"))
    assert f"argument {option}" in err and ("out of range" in err or "pixels" in err), err


def test_images_are_not_decoded(tmp_path: Path) -> None:
    """Eight references to one 4000 x 4000 PNG: decoding would cost 8 x 64 MB; not decoding
    costs the PNG's 16 KB once per reference. Peak RSS of a fresh process tells them apart."""
    (tmp_path / "big.png").write_bytes(png_bytes(4000, 4000))
    doc, binary = triangle_doc()
    doc["images"] = [{"uri": "big.png"} for _ in range(8)]
    doc["textures"] = [{"source": i} for i in range(8)]
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    scene = write_gltf(tmp_path / "eight.gltf", doc, binary)
    probe = (
        "import resource, sys, rtsim; base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss; "
        "s = rtsim.load_scene(sys.argv[1]); assert len(s.triangles()) == 1; "
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base)"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe, str(scene)], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    growth_mb = int(out.stdout.strip()) / 1024
    assert growth_mb < 100, f"loading grew the process by {growth_mb:.0f} MB (images decoded?)"


# ---------------------------------------------------------------------------------------------
# Traces with valid CRCs and bad content: rtsim-sim exits 2, open_trace raises RtsimError.


@pytest.fixture(scope="module")
def good_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("bad_inputs") / "good"
    rtsim_trace("cornell", "-o", str(out), "--resolution", "16x12")
    return out


def _corrupt(good: Path, out: Path, case: str) -> tuple[Path, str]:
    sections = read_sections(good / "trace.rtt")
    expected = TRACE_CASES[case](sections)
    write_trace(out / "trace.rtt", sections)
    return out, expected


@pytest.mark.parametrize("case", sorted(TRACE_CASES))
def test_bad_trace_content(case: str, good_trace: Path, tmp_path: Path) -> None:
    trace, expected = _corrupt(good_trace, tmp_path / "bad", case)
    sim = subprocess.run(
        [str(find_sim()), str(trace), "-o", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert sim.returncode == 2, sim.stderr
    assert f"{trace / 'trace.rtt'}: {expected}" in sim.stderr, sim.stderr
    with pytest.raises(rtsim.RtsimError) as info:
        rtsim.open_trace(trace)
    assert expected in str(info.value)


def test_forged_copy_of_a_good_trace_simulates(good_trace: Path, tmp_path: Path) -> None:
    """The forge itself writes valid traces: an unmodified copy simulates with exit 0."""
    sections = read_sections(good_trace / "trace.rtt")
    write_trace(tmp_path / "copy" / "trace.rtt", sections)
    result = subprocess.run(
        [str(find_sim()), str(tmp_path / "copy"), "-o", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr


def _sim(trace: Path, run: Path, *args: str) -> subprocess.CompletedProcess[str]:
    cmd = [str(find_sim()), str(trace), "-o", str(run), *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=60, check=False)


def test_manifest_of_the_wrong_shape_or_a_folder(good_trace: Path, tmp_path: Path) -> None:
    for name, make in (
        ("list", lambda p: p.write_text("[1, 2]")),
        ("scene_number", lambda p: p.write_text('{"scene": 3}')),
        ("folder", lambda p: p.mkdir()),
    ):
        trace = tmp_path / name
        trace.mkdir()
        (trace / "trace.rtt").write_bytes((good_trace / "trace.rtt").read_bytes())
        make(trace / "manifest.json")
        result = _sim(trace, tmp_path / f"run_{name}")
        assert result.returncode == 2, result.stderr
        assert f"{trace / 'manifest.json'}: " in result.stderr, result.stderr
        if name != "scene_number":
            with pytest.raises(rtsim.RtsimError, match=r"manifest\.json"):
                rtsim.open_trace(trace)


def test_config_is_a_folder(
    good_trace: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "cfg").mkdir()
    code = main(
        [
            "simulate",
            str(good_trace),
            "-o",
            str(tmp_path / "run"),
            "--config",
            str(tmp_path / "cfg"),
        ]
    )
    assert code == 2
    err = " ".join(capsys.readouterr().err.split())  # the console may wrap long lines
    assert f"{tmp_path / 'cfg'}: is a folder" in err


def test_absurd_config_refused_with_the_figure(good_trace: Path, tmp_path: Path) -> None:
    result = _sim(
        good_trace,
        tmp_path / "run",
        "--set",
        "traversal.units=4096",
        "--set",
        "traversal.ray_contexts=4096",
    )
    assert result.returncode == 2, result.stderr
    assert "traversal.units=4096" in result.stderr and "GiB of host memory" in result.stderr
    assert "16777216 ray contexts" in result.stderr


def test_simulate_timeout_kills_and_exits_4(
    good_trace: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A simulator that never finishes (a stand-in script) is killed after --timeout."""
    slow = tmp_path / "slow-sim"
    slow.write_text("#!/bin/sh\nexec sleep 60\n")
    slow.chmod(0o755)
    monkeypatch.setenv("RTSIM_SIM", str(slow))
    code = main(
        [
            "simulate",
            str(good_trace),
            "-o",
            str(tmp_path / "run"),
            "--timeout",
            "0.5",
            "--no-progress",
        ]
    )
    err = capsys.readouterr().err
    assert code == 4, err
    assert "timed out after 0.5 s" in err
    with pytest.raises(SystemExit):
        main(["simulate", str(good_trace), "-o", str(tmp_path / "run"), "--timeout", "-1"])
