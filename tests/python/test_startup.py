"""Start-up stays cheap: `rtsim --version`, `rtsim simulate` and rtsim.simulate() load neither
numpy, nor the C++ extension, nor plotting or Dask (docs/benchmarks.md has the timings)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import rtsim

HEAVY = ("numpy", "matplotlib", "dask", "distributed", "yaml", "rtsim._core")

LOADED_AFTER = """
import json, sys
{body}
print(json.dumps(sorted(sys.modules)))
"""


def modules_after(body: str) -> set[str]:
    code = LOADED_AFTER.format(body=body)
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=False, timeout=120
    )
    assert result.returncode == 0, result.stderr
    return set(json.loads(result.stdout.splitlines()[-1]))


def heavy(modules: set[str]) -> set[str]:
    return {m for m in modules if m.split(".")[0] in HEAVY or m in HEAVY}


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("startup") / "trace"
    rtsim.trace_scene("cornell", out, workload="primary", width=16, height=12)
    return out


def test_version_loads_nothing_heavy() -> None:
    loaded = modules_after(
        "from rtsim.cli import main\ntry:\n    main(['--version'])\nexcept SystemExit:\n    pass"
    )
    assert not heavy(loaded) and "rich" not in loaded


def test_simulate_command_loads_nothing_heavy(trace: Path, tmp_path: Path) -> None:
    run = tmp_path / "run"
    loaded = modules_after(
        "from rtsim.cli import main\n"
        f"assert main(['simulate', {str(trace)!r}, '-o', {str(run)!r}, '--no-progress']) == 0"
    )
    assert not heavy(loaded), heavy(loaded)
    assert (run / "stats.json").is_file()


def test_import_and_simulate_load_nothing_heavy(trace: Path) -> None:
    loaded = modules_after(f"import rtsim\nassert rtsim.simulate({str(trace)!r}).rays > 0")
    assert not heavy(loaded), heavy(loaded)


def test_version_is_the_extensions() -> None:
    from rtsim import _core

    assert rtsim.__version__ == _core.__version__
    result = subprocess.run(
        [sys.executable, "-m", "rtsim", "--version"], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == f"rtsim {_core.__version__}"
