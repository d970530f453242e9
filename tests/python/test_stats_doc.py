"""The summary keys are declared once (sim/report/summary_schema.cpp): docs/stats.md's summary
table is generated from that declaration, and a real run writes exactly the declared keys."""

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


def test_stats_doc_summary_table_is_generated_from_the_declaration() -> None:
    gen = load_generator()
    try:
        schema = gen.load_schema()
    except FileNotFoundError as err:
        pytest.skip(str(err))
    current = gen.DOC.read_text()
    assert gen.render(current, schema) == current, (
        f"docs/stats.md's summary table is out of date: run `{sys.executable} "
        "scripts/gen_stats_doc.py`"
    )


def test_stats_schema_declares_each_key_once_with_a_meaning() -> None:
    gen = load_generator()
    try:
        sim = gen.find_sim()
    except FileNotFoundError as err:
        pytest.skip(str(err))
    out = subprocess.run([sim, "--dump-stats-schema"], capture_output=True, text=True, check=True)
    schema = json.loads(out.stdout)
    keys = [d["key"] for d in schema]
    assert len(keys) == len(set(keys))
    assert {"rays", "cycles", "mrays_per_second", "hit_mismatches", "verdict"} <= set(keys)
    assert all(d["meaning"].strip() for d in schema)
