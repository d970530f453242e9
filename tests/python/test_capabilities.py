"""The one resolution step's table (docs/capabilities.md): current, and every rule in it refusing
its example run through the CLI with exit status 2 and the table's words."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO, run_rtsim

#: How each example's trace is made: a structure kind on the Cornell box, or an animated trace.
EXAMPLE_TRACES = {"frames": ("grove", ["--frames", "2"])}


def _table(sim_exe: Path) -> dict:
    out = subprocess.run(
        [str(sim_exe), "--capabilities"], capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout)


def test_the_page_is_current(sim_exe: Path) -> None:
    spec = importlib.util.spec_from_file_location(
        "gen_capabilities_doc", REPO / "scripts" / "gen_capabilities_doc.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    doc = module.DOC.read_text()
    regenerate = f"{sys.executable} scripts/gen_capabilities_doc.py"
    assert module.render(doc, str(sim_exe)) == doc, f"docs/capabilities.md is stale: `{regenerate}`"


def test_every_rule_refuses_its_example(sim_exe: Path, tmp_path: Path) -> None:
    table = _table(sim_exe)
    assert len(table["rules"]) >= 15
    traces: dict[str, Path] = {}
    for rule in table["rules"]:
        accel = rule["example"]["accel"]
        if not accel:  # a rule no registered structure meets: check that none does
            assert rule["id"] == "unit/packet_kernel", rule["id"]
            assert all(s["capabilities"]["packet_kernel"] for s in table["structures"]), rule["id"]
            continue
        if accel not in traces:
            scene, extra = EXAMPLE_TRACES.get(accel, ("cornell", ["--accel", accel]))
            traces[accel] = tmp_path / accel
            made = run_rtsim(
                "trace", scene, "-o", str(traces[accel]), "--resolution", "8x6", *extra
            )
            assert made.returncode == 0, made.stderr
        sets = [x for s in rule["example"]["set"] for x in ("--set", s)]
        result = run_rtsim(
            "simulate", str(traces[accel]), "-o", str(tmp_path / "run"), "--no-progress", *sets
        )
        assert result.returncode == 2, (rule["id"], result.stderr)
        message = " ".join(result.stderr.split())
        for words in (rule["needs"], rule["reason"], rule["change"]):
            assert " ".join(words.split()) in message, (rule["id"], words, result.stderr)


def test_runs_are_checked_before_any_trace(sim_exe: Path, tmp_path: Path) -> None:
    runs = [
        {"config": {"traversal": {"model": "packet"}}, "accel": "bkd"},
        {"config": {"traversal": {"model": "simt", "simt": {"lanes": 32}}}, "accel": "bvh2"},
        {
            "config": {"traversal": {"stack_overflow": "restart_trail"}},
            "accel": "grid",
        },
        {"config": {"l1": {"size_kib": 3}}, "accel": "bvh2"},
        {"config": {}, "accel": "no_such_structure"},
    ]
    path = tmp_path / "runs.json"
    path.write_text(json.dumps(runs))
    out = subprocess.run(
        [str(sim_exe), "--check-runs", str(path)], capture_output=True, text=True, check=True
    )
    checked = json.loads(out.stdout)
    assert [c["ok"] for c in checked] == [True, True, False, False, False]  # B-Kd: a packet kernel
    derived = {d["key"]: d["value"] for d in checked[1]["resolved"]["derived"]}
    assert derived["traversal.ray_contexts"] == 32  # contexts follow the lanes: one warp
    assert "restart trail" in checked[2]["error"] and "grid" in checked[2]["error"]
    assert "l1.size_kib" in checked[3]["error"]
    assert "no_such_structure" in checked[4]["error"]


@pytest.mark.parametrize(
    ("moved", "to"),
    [
        ("traversal.lanes=32", "traversal.simt.lanes"),
        ("traversal.simt_policy=if_if", "traversal.simt.policy"),
    ],
)
def test_a_moved_key_says_where_it_went(sim_exe: Path, tmp_path: Path, moved: str, to: str) -> None:
    path = tmp_path / "runs.json"
    key, value = moved.split("=")
    section, name = key.split(".")
    path.write_text(json.dumps([{"config": {section: {name: value}}}]))
    out = subprocess.run(
        [str(sim_exe), "--check-runs", str(path)], capture_output=True, text=True, check=True
    )
    error = json.loads(out.stdout)[0]["error"]
    assert f"'{key}'" in error and to in error
