"""A sampling request that ends in a full run (the sample would be the whole trace) says so."""

from __future__ import annotations

import json
from pathlib import Path

from test_model import Sim, cornell_small, sim, trace_of  # noqa: F401  (fixtures)


def test_a_sample_of_the_whole_trace_says_it_ran_every_ray(
    cornell_small: Path,  # noqa: F811
    sim: Sim,  # noqa: F811
    tmp_path: Path,
) -> None:
    run = tmp_path / "all"
    p = sim(cornell_small, run, "sampling.fraction=1", extra=("--no-verdict",))
    assert p.returncode == 0, p.stderr
    summary = json.loads((run / "stats.json").read_text())["summary"]
    assert summary["sampled"] is False
    assert "every ray was simulated" in summary["sampling_note"]
    assert "rtsim-sim: note: sampling" in p.stderr
    plain = tmp_path / "plain"
    assert sim(cornell_small, plain, extra=("--no-verdict",)).returncode == 0
    assert "sampling_note" not in json.loads((plain / "stats.json").read_text())["summary"]
