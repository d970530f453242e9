"""Stats are declared once, by the block that produces them (rtl_model/common/stats.h):
docs/stats.md's tables are generated from the declarations, and real runs write exactly the
declared keys (checked in rtsim-sim before stats.json is written)."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from types import ModuleType

import pytest

from conftest import REPO


def load_generator() -> ModuleType:
    path = REPO / "scripts" / "gen_stats_doc.py"
    spec = importlib.util.spec_from_file_location("gen_stats_doc", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_stats_doc_tables_are_generated_from_the_declarations() -> None:
    gen = load_generator()
    try:
        schema = gen.load_schema()
    except FileNotFoundError as err:
        pytest.skip(str(err))
    current = gen.DOC.read_text()
    assert gen.render(current, schema) == current, (
        f"docs/stats.md's stats tables are out of date: run `{sys.executable} "
        "scripts/gen_stats_doc.py`"
    )


def test_stats_schema_declares_each_key_once_with_a_meaning() -> None:
    gen = load_generator()
    try:
        sim = gen.find_sim()
    except FileNotFoundError as err:
        pytest.skip(str(err))
    out = subprocess.run([sim, "--dump-stats-schema"], capture_output=True, text=True, check=True)
    blocks = {b["path"]: b["stats"] for b in json.loads(out.stdout)}
    for path, stats in blocks.items():
        keys = [d["key"] for d in stats]
        assert len(keys) == len(set(keys)), path
        assert all(d["meaning"].strip() for d in stats), path
    summary = {d["key"] for d in blocks["summary"]}
    assert {"rays", "cycles", "mrays_per_second", "hit_mismatches", "verdict"} <= summary
    assert {"busy_fraction", "stack_spill_writes"} <= {
        d["key"] for d in blocks["model.units.<unit>"]
    }
    assert {"model.dram", "model.l1.<l1>, model.l2", "model.analytic"} <= blocks.keys()
