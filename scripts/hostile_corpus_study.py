"""Measures the hostile-input corpus and writes its figures into docs/validation.md (between the
`hostile-corpus` markers): how many inputs each generator makes, the pytest outcome and time of
the four test files that run them, and the fuzz corpus scripts/make_fuzz_corpus.py writes.

usage: python scripts/hostile_corpus_study.py   (needs the rtsim package installed)
"""

from __future__ import annotations

import datetime
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "python"))

from gltf_mutations import collapse_mutations, number_mutations, type_mutations  # noqa: E402
from rtsim.doc_markers import write_between  # noqa: E402

FILES = [
    "test_hostile_gltf.py",
    "test_hostile_traces.py",
    "test_hostile_cli.py",
    "test_api_fuzz.py",
]


def pytest_run() -> tuple[str, float, float]:
    """The pytest summary line, wall and CPU seconds of the four files."""
    t0, c0 = time.monotonic(), os.times()
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", *(f"tests/python/{f}" for f in FILES)],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=False,
    )
    c1 = os.times()
    cpu = c1.children_user + c1.children_system - c0.children_user - c0.children_system
    return out.stdout.strip().splitlines()[-1], time.monotonic() - t0, cpu


def fuzz_corpus() -> dict[str, int]:
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run(
            [sys.executable, "scripts/make_fuzz_corpus.py", f"{tmp}/c"],
            cwd=REPO,
            check=True,
            capture_output=True,
        )
        c = Path(tmp) / "c"
        return {
            p: len(list((c / p).iterdir()))
            for p in (
                "gltf/bad",
                "trace/bad",
                "config/bad",
                "sim",
                "gltf/seed",
                "trace/seed",
                "config/seed",
            )
        }


def main() -> int:
    numbers = list(number_mutations())
    fields = len({m.name.split("=")[0] for m in numbers})
    summary, wall, cpu = pytest_run()
    corpus = fuzz_corpus()
    seeds = corpus["gltf/seed"] + corpus["trace/seed"] + corpus["config/seed"]
    load = os.getloadavg()[0]
    text = (
        f"Measured ({datetime.date.today()}, `python scripts/hostile_corpus_study.py` on "
        f"{os.cpu_count()} cores, load average {load:.0f} when it ended): {len(numbers)} glTF "
        f"number mutations ({fields} integer fields x {len(numbers) // fields} forms, "
        f"{sum(m.valid for m in numbers)} of them valid), {len(list(type_mutations()))} type "
        f"mutations and {len(list(collapse_mutations()))} collapsing transforms, the trace, "
        f"command-line and hypothesis cases of the four test files: `{summary}` "
        f"({wall:.0f} s wall, {cpu:.0f} s CPU, within `scripts/test.sh`), with no signal, hang, "
        f"traceback of the wrong type or silent wrong output (each would fail a test). "
        f"`scripts/make_fuzz_corpus.py` writes {corpus['gltf/bad']} bad glTF files, "
        f"{corpus['trace/bad']} bad trace inputs, {corpus['config/bad']} bad configs and "
        f"{corpus['sim']} bad traces for the sanitized `rtsim-sim` (each must exit 2 naming the "
        f"file), and {seeds} seeds."
    )
    if not re.search(r"\d+ passed", summary) or "failed" in summary:
        print(text)
        return 1
    write_between(REPO / "docs" / "validation.md", "hostile-corpus", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
