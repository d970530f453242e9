"""Every cell of the capability table's matrices, run (docs/capabilities.md): a tiny trace per
structure through every unit kind x technique (at approx) and every unit kind x technique x level
(on bvh2). A `yes` replays with 0 hit and 0 work mismatches; `no effect` replays too and names
the setting it ignores in summary.resolved.unused; a rule's id exits 2 with that rule's words."""

from __future__ import annotations

import json
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from conftest import run_rtsim


def _trace(structure: str, out: Path) -> Path:
    # Two levels come from an instanced scene; every other structure from the Cornell box.
    if structure.startswith("two_level"):
        args = ["grove", "--resolution", "8x6"]
    else:
        args = ["cornell", "--resolution", "8x6", "--accel", structure]
    made = run_rtsim("trace", *args, "-o", str(out))
    assert made.returncode == 0, made.stderr
    return out


def _cells(table: dict) -> list[tuple[str, str, str, list[str], str]]:
    """(structure, unit, level, sets, expected) for every distinct cell of both matrices."""
    sets = {t["name"]: t["set"] for t in table["techniques"]}
    cells: dict[tuple[str, str, str, tuple[str, ...]], str] = {}
    for row in table["by_structure"]:
        for structure, want in row["cells"].items():
            key = (structure, row["unit"], "approx", tuple(sets[row["technique"]]))
            cells[key] = want
    for row in table["by_level"]:
        for level, want in row["cells"].items():
            key = ("bvh2", row["unit"], level, tuple(sets[row["technique"]]))
            assert cells.setdefault(key, want) == want, key  # the two matrices agree
    return [(s, u, lv, list(a), want) for (s, u, lv, a), want in cells.items()]


def test_every_cell_runs_or_is_refused_with_its_rule(sim_exe: Path, tmp_path: Path) -> None:
    table = json.loads(
        subprocess.run(
            [str(sim_exe), "--capabilities"], capture_output=True, text=True, check=True
        ).stdout
    )
    rules = {r["id"]: r for r in table["rules"]}
    cells = _cells(table)
    assert len(cells) >= 300
    structures = sorted({c[0] for c in cells})
    traces = {s: _trace(s, tmp_path / "traces" / s.split(" ")[0]) for s in structures}

    def run(i: int, cell: tuple[str, str, str, list[str], str]) -> str | None:
        structure, unit, level, sets, want = cell
        args = [f"traversal.model={unit}", f"fidelity={level}", *sets]
        out = tmp_path / "runs" / str(i)
        result = subprocess.run(
            [str(sim_exe), str(traces[structure]), "-o", str(out), "--no-verdict"]
            + [x for a in args for x in ("--set", a)],
            capture_output=True,
            text=True,
        )
        what = f"{structure} {' '.join(args)} (table: {want})"
        if want in ("yes", "no effect"):
            if result.returncode != 0:
                return f"{what}: exit {result.returncode}: {result.stderr.strip()[-300:]}"
            if "0 hit mismatches, 0 work mismatches" not in result.stderr + result.stdout:
                return f"{what}: mismatches: {result.stderr.strip()[-300:]}"
            unused = json.loads((out / "stats.json").read_text())["summary"]["resolved"]["unused"]
            named = {u["key"] for u in unused}
            if want == "no effect" and not any(a.split("=")[0] in named for a in sets):
                return f"{what}: summary.resolved.unused names none of its settings: {named}"
            if want == "yes" and named:
                return f"{what}: the table says yes, the run calls {named} unused"
            return None
        rule = rules[want]
        message = " ".join(result.stderr.split())
        if result.returncode != 2:
            return f"{what}: exit {result.returncode}, not 2"
        for words in (rule["needs"], rule["reason"], rule["change"]):
            if " ".join(words.split()) not in message:
                return f"{what}: the message lacks '{words}': {message[-300:]}"
        return None

    with ThreadPoolExecutor(max_workers=2) as pool:
        failures = [f for f in pool.map(run, range(len(cells)), cells) if f]
    assert not failures, "\n".join(failures[:20])


@pytest.mark.parametrize("unit", ["mimd", "simt", "packet"])
def test_the_table_names_each_kinds_treelet_prefetching(sim_exe: Path, unit: str) -> None:
    # A kind whose rays share one walk says prefetching has no effect rather than ignoring it.
    table = json.loads(
        subprocess.run(
            [str(sim_exe), "--capabilities"], capture_output=True, text=True, check=True
        ).stdout
    )
    kind = next(k for k in table["unit_kinds"] if k["name"] == unit)
    row = next(
        r
        for r in table["by_level"]
        if r["unit"] == unit and r["technique"] == "prefetching, no queues"
    )
    expected = "yes" if kind["needs"]["treelet_prefetch"] else "no effect"
    assert row["cells"]["approx"] == expected
    assert row["cells"]["analytic"] == "no effect"
