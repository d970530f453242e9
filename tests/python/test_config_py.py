"""The Python config tree (rtsim.config) mirrors the C++ one exactly: same fields, defaults,
units, ranges and choices, checked against `rtsim-sim --dump-schema` both ways."""

from __future__ import annotations

import dataclasses
import json
import subprocess
from pathlib import Path
from typing import Any

import pytest

from rtsim.config import (
    MODIFIERS,
    PRESETS,
    ConfigError,
    SimConfig,
    compose,
    config_keys,
    field_info,
)
from rtsim.launcher import find_sim


def sim_json(*args: str) -> Any:
    out = subprocess.run([str(find_sim()), *args], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def schema_fields(schema: dict[str, Any], prefix: str = "") -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name, entry in schema.items():
        path = f"{prefix}.{name}" if prefix else name
        if entry["type"] == "section":
            out.update(schema_fields(entry["fields"], path))
        else:
            out[path] = entry
    return out


def test_defaults_equal_cpp() -> None:
    assert SimConfig().to_dict() == sim_json("--dump-defaults")


def test_schema_matches_both_ways() -> None:
    cpp = schema_fields(sim_json("--dump-schema"))
    assert set(cpp) == set(config_keys()), set(cpp) ^ set(config_keys())
    defaults = SimConfig()
    for key, entry in cpp.items():
        meta = field_info(key).metadata
        assert defaults.get(key) == entry["default"], key
        assert meta.get("doc") == entry["doc"], key
        if entry["type"] in ("int", "float"):
            assert (meta["unit"], meta["min"], meta["max"]) == (
                entry["unit"], entry["min"], entry["max"]), key  # fmt: skip
            assert field_info(key).type == entry["type"], key
        elif entry["type"] == "choice":
            assert list(meta["choices"]) == entry["choices"], key
        else:
            assert entry["type"] == "bool" and field_info(key).type == "bool", key


def test_round_trip_through_rtsim_sim(cornell_trace: Path, tmp_path: Path) -> None:
    """Python dict -> rtsim-sim --config -> config.resolved.json -> Python: nothing changes but
    what the run resolves from the trace (traversal.stack_entry_bytes 0: the structure's, a
    BVH's 8 here)."""
    config = compose("base+tu16+l1-64k+shared-pipes")
    path = tmp_path / "config.json"
    path.write_text(config.to_json())
    run = tmp_path / "run"
    proc = subprocess.run([str(find_sim()), str(cornell_trace), "--config", str(path), "-o",
                           str(run)], capture_output=True, text=True, check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    resolved = json.loads((run / "config.resolved.json").read_text())
    assert config.traversal.stack_entry_bytes == 0
    # ...and the contexts the unit kind's groups derive (traversal.ray_contexts 0: 16 for MIMD).
    expected = {"traversal.stack_entry_bytes": 8, "traversal.ray_contexts": 16}
    assert resolved == config.with_values(expected).to_dict()
    assert SimConfig.from_dict(resolved) == config.with_values(expected)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"l1": {"size_kb": 16}}, "'l1.size_kb'"),
        ({"dram": {"speed": 1}}, "'dram.speed'"),
        ({"treelets": {"enable": True}}, "'treelets.enable'"),
        ({"l1": {"size_kib": "big"}}, "'l1.size_kib' must be a non-negative integer"),
        ({"box": {"sharing": "pooled"}}, "'box.sharing' = 'pooled' is not one of"),
        ({"ideal_memory": 1}, "'ideal_memory' must be true or false"),
        ({"l2": 5}, "'l2' must be a mapping"),
    ],
)
def test_from_dict_rejects_with_full_path(data: dict[str, Any], message: str) -> None:
    with pytest.raises(ConfigError, match=message.replace("(", r"\(")):
        SimConfig.from_dict(data)


def test_presets_and_modifiers_compose() -> None:
    for name in [*PRESETS, *MODIFIERS]:
        compose(name)  # every patch names only keys the C++ tree has
    c = compose("base+tu16+l1-64k+dram-2x")
    assert (c.traversal.units, c.l1.size_kib, c.dram.bytes_per_cycle) == (16, 64, 32)
    assert c.l2 == SimConfig().l2
    # later modifiers win
    assert compose("tu16+tu4").traversal.units == 4
    with pytest.raises(ConfigError, match="unknown preset or modifier 'tu17'"):
        compose("base+tu17")


def test_dataclasses_are_typed() -> None:
    for f in dataclasses.fields(SimConfig):
        assert f.type != "Any", f.name
