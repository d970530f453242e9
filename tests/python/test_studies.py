"""The project's studies (rtsim/studies): every registered study's specs resolve, at its
documented options and in quick mode, into sweep plans without running a simulation; and the
studies moved onto that form have no private trace, simulate or cache code left in scripts/."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rtsim import studies
from rtsim.sweep.spec import spec_from_dict

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"

#: Scripts that still carry their own trace/simulate/cache code (moving onto rtsim/studies
#: shrinks this list; a script not named here must have none).
NOT_YET_MOVED = {
    "accel_study.py",
    "composition_matrix.py",
    "hostile_corpus_study.py",
    "partition_study.py",
    "presets_doc.py",
    "shading_study.py",
    "techniques_matrix.py",
    "two_level_study.py",
    "verdict_study.py",
}
#: Benchmarks and doc generators: they time or describe the binaries one process at a time.
KEPT_SCRIPTS = re.compile(r"^(bench_|gen_|analytic_sweep_speed|sampling_coverage|stats_identity|"
                          r"make_fuzz_corpus|technique_costs_doc)")  # fmt: skip
PRIVATE = re.compile(
    r"^def (trace|simulate|run_sim\w*)\(|rtsim-sim|rtsim-trace|from rtsim\.launcher import|"
    r"\"-m\", \"rtsim\", \"trace\"",
    re.M,
)


@pytest.mark.parametrize("name", studies.names())
@pytest.mark.parametrize("quick", [False, True])
def test_study_specs_resolve_without_running(name: str, quick: bool) -> None:
    study = studies.load(name)
    specs = [spec_from_dict(d, f"study {name}") for d in study.specs(study.resolve(quick))]
    plans = [p for s in specs for p in s.plans()]
    assert plans, f"study {name}: no runs"
    # Every table and figure names its page or file in the docs folder.
    for t in study.tables:
        assert t.doc.endswith(".md") and t.marker, (name, t)
    for f in study.figures:
        assert f.path.endswith(".png"), (name, f)


def test_moved_studies_left_no_private_simulation_code() -> None:
    found = {}
    for path in sorted(SCRIPTS.rglob("*.py")):
        rel = path.relative_to(SCRIPTS).as_posix()
        if rel in NOT_YET_MOVED or rel.startswith("papers/") or KEPT_SCRIPTS.match(path.name):
            continue
        hits = PRIVATE.findall(path.read_text())
        if hits:
            found[rel] = hits
    assert not found, f"scripts with their own trace/simulate code (move them to a Study): {found}"


def test_moved_scripts_are_gone_and_named_nowhere() -> None:
    root = SCRIPTS.parent
    moved = ["execution_models_study.py", "execution_models_packets.py", "frames_study.py"]
    for name in moved:
        assert not (SCRIPTS / name).exists(), name
    texts = [p.read_text() for p in [root / "README.md", *(root / "docs").glob("*.md")]]
    for name in moved:
        # Only a table's measured-by note may still name the script that wrote it.
        cmds = [ln for t in texts for ln in t.splitlines() if f"scripts/{name}" in ln]
        assert all(ln.startswith("Measured") for ln in cmds), (name, cmds)
