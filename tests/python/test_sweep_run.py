"""Sweeps end to end: a tiny sweep with a crashing config, resume after `kill -9`, a timeout on
an existing Dask scheduler, the CSV export and the report rendered in headless Chromium."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from contextlib import closing
from pathlib import Path

import pytest

from conftest import rtsim_command, run_rtsim
from rtsim.launcher import find_sim

TINY = """\
name: tiny
scenes: [cornell]
workloads:
  - {name: primary, rays: [primary], resolution: 32x24}
grid:
  traversal.units: [4, 8]
  l1.size_kib: [16, 32]      # 32 KiB: the run fails (FAIL_32_KIB below), by design
"""

#: rtsim-sim, except that a run of a 32 KiB L1 fails as a run fails that the spec check cannot
#: foresee (the check itself, --check-runs, is the real one): the sweep must record the failure
#: and finish the other runs. (A config the real rtsim-sim refuses, such as 24 KiB, which is no
#: power-of-two number of sets, is stopped by the spec check before any run.)
FAIL_32_KIB = """#!/bin/sh
config=""
prev=""
for a in "$@"; do
  if [ "$a" = "--check-runs" ]; then exec "{real}" "$@"; fi
  if [ "$prev" = "--config" ]; then config="$a"; fi
  prev="$a"
done
if [ -n "$config" ] && tr -d ' \n' < "$config" | grep -q '"l1":{[^}]*"size_kib":32[,}}]'; then
  echo "rtsim-sim: error: config: 'l1.size_kib' = 32 fails in this test, after the check" >&2
  exit 2
fi
exec "{real}" "$@"
"""


def rows(sweep: Path) -> list[dict]:
    with closing(sqlite3.connect(sweep / "results.sqlite")) as conn:
        conn.row_factory = sqlite3.Row
        return [dict(r) for r in conn.execute("SELECT * FROM runs")]


def rows_so_far(sweep: Path) -> list[dict]:
    """The rows of a sweep that may still be creating its store."""
    try:
        return rows(sweep) if (sweep / "results.sqlite").is_file() else []
    except sqlite3.OperationalError:
        return []


@pytest.fixture(scope="module")
def tiny_sweep(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("sweep")
    (folder / "tiny.yaml").write_text(TINY)
    wrapper = folder / "rtsim-sim"
    wrapper.write_text(FAIL_32_KIB.replace("{real}", str(find_sim())))
    wrapper.chmod(0o755)
    old = os.environ.get("RTSIM_SIM")
    os.environ["RTSIM_SIM"] = str(wrapper)
    try:
        result = run_rtsim("sweep", str(folder / "tiny.yaml"), "-o", str(folder / "out"),
                           "--workers", "2", "--no-progress")  # fmt: skip
    finally:
        if old is None:
            os.environ.pop("RTSIM_SIM")
        else:
            os.environ["RTSIM_SIM"] = old
    assert result.returncode == 1, result.stdout + result.stderr  # some runs failed, by design
    return folder / "out"


def test_sweep_records_every_run(tiny_sweep: Path) -> None:
    runs = rows(tiny_sweep)
    assert len(runs) == 4
    by_l1 = {(r["traversal.units"], r["l1.size_kib"]): r for r in runs}
    for units in (4, 8):
        ok, bad = by_l1[(units, 16)], by_l1[(units, 32)]
        assert ok["status"] == "ok" and ok["error"] is None
        stats = json.loads(ok["stats_json"])
        assert stats["summary"]["hit_mismatches"] == 0
        assert json.loads(ok["config_json"])["traversal"]["units"] == units
        assert json.loads(ok["provenance_json"])["git"]
        assert bad["status"] == "failed" and bad["exit_code"] == 2
        assert "l1.size_kib" in bad["error"]
    run_dirs = sorted((tiny_sweep / "runs").iterdir())
    assert len(run_dirs) == 4
    done = [d for d in run_dirs if (d / "stats.json").is_file()]
    assert len(done) == 2
    for d in done:
        for name in ("config.json", "config.resolved.json", "provenance.json", "command.txt"):
            assert (d / name).is_file(), d / name


def test_rerun_skips_everything(tiny_sweep: Path) -> None:
    before = {r["run_id"]: r for r in rows(tiny_sweep)}
    result = run_rtsim("sweep", str(tiny_sweep.parent / "tiny.yaml"), "-o", str(tiny_sweep),
                       "--no-progress")  # fmt: skip
    assert "4 already" in result.stdout.replace("\n", " ")
    assert {r["run_id"]: r for r in rows(tiny_sweep)} == before


def test_results_csv(tiny_sweep: Path) -> None:
    result = run_rtsim("results", str(tiny_sweep), "--csv")
    assert result.returncode == 0, result.stderr
    table = list(csv.DictReader(io.StringIO(result.stdout)))
    assert len(table) == 4
    assert {"scene", "workload", "status", "traversal.units", "l1.size_kib", "rays_per_second",
            "sram_bytes", "dram_bytes_per_ray.node", "area_mm2"} <= set(table[0])  # fmt: skip
    ok = [r for r in table if r["status"] == "ok"]
    assert len(ok) == 2 and all(float(r["rays_per_second"]) > 0 for r in ok)


def test_resume_after_kill(tmp_path: Path) -> None:
    """SIGKILL the whole sweep (client, cluster, simulations) after the first result; the
    rerun finishes the rest, leaves finished rows untouched and duplicates nothing."""
    spec = tmp_path / "many.yaml"
    spec.write_text(TINY.replace("[16, 32]", "[8, 16, 32, 64]").replace("[4, 8]", "[1, 2, 4, 8]"))
    out = tmp_path / "out"
    cmd = [*rtsim_command(), "sweep", str(spec), "-o", str(out), "--workers", "1", "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)  # fmt: skip
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if rows_so_far(out):
                break
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    first = {r["run_id"]: r for r in rows(out)}
    assert 1 <= len(first) < 16, "the sweep finished before it could be killed"
    print(f"killed after {len(first)} of 16 runs")
    result = run_rtsim("sweep", str(spec), "-o", str(out), "--workers", "1", "--no-progress")
    assert result.returncode == 0, result.stdout + result.stderr
    final = rows(out)
    assert len(final) == 16 and len({r["run_id"] for r in final}) == 16
    assert all(r["status"] == "ok" and r["attempts"] == 1 for r in final)
    for r in final:
        if r["run_id"] in first:  # not re-run: same start and finish stamps
            old = first[r["run_id"]]
            assert (r["started_utc"], r["finished_utc"]) == (
                old["started_utc"],
                old["finished_utc"],
            )


def test_timeout_on_existing_scheduler(tmp_path: Path) -> None:
    """The same spec runs unchanged on a Dask scheduler address; a timeout is a failed run."""
    distributed = pytest.importorskip("distributed")
    spec = tmp_path / "one.yaml"
    spec.write_text(TINY.replace("[4, 8]", "[4]").replace("[16, 32]", "[16]"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster:  # fmt: skip
        address = cluster.scheduler_address
        result = run_rtsim("sweep", str(spec), "-o", str(tmp_path / "out"), "--scheduler",
                           address, "--timeout", "0.001", "--no-progress")  # fmt: skip
    assert result.returncode == 1, result.stdout + result.stderr
    (run,) = rows(tmp_path / "out")
    assert run["status"] == "failed" and "timed out after 0.001 s" in run["error"]


CHECK_IMAGES = """<script>
window.addEventListener('load', () => {
  const imgs = [...document.images];
  const bad = imgs.filter(i => !(i.complete && i.naturalWidth > 0));
  const d = document.createElement('div');
  d.id = 'imgcheck';
  d.textContent = 'images=' + imgs.length + ' broken=' + bad.length;
  document.body.appendChild(d);
});
</script></body>"""


def chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        for folder in os.environ.get("PATH", "").split(os.pathsep):
            if (Path(folder) / name).is_file():
                return str(Path(folder) / name)
    return None


def test_report_renders_in_chromium(tiny_sweep: Path, tmp_path: Path) -> None:
    report = tmp_path / "report.html"
    result = run_rtsim("report", str(tiny_sweep), "-o", str(report))
    assert result.returncode == 0, result.stderr
    html = report.read_text()
    assert "http://" not in html.replace("http://www.w3.org", "")  # self-contained
    assert html.count("data:image/png;base64,") >= 5
    exe = chromium()
    if exe is None:
        pytest.skip("chromium is not installed")
    page = tmp_path / "check.html"
    page.write_text(html.replace("</body>", CHECK_IMAGES))
    dom = subprocess.run(
        [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=10000", "--dump-dom",
         page.as_uri()],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert "imgcheck" in dom.stdout, dom.stderr[-2000:]
    count = html.count("<img ")
    assert f"images={count} broken=0" in dom.stdout, dom.stdout[-500:]


def test_bad_spec_exit_code(tmp_path: Path) -> None:
    spec = tmp_path / "bad.yaml"
    spec.write_text("scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrid:\n  l1.sise: [1]\n")
    result = run_rtsim("sweep", str(spec), "-o", str(tmp_path / "out"))
    assert result.returncode == 2
    assert f"{spec}:4: grid.l1.sise: unknown key" in result.stderr
    assert sys.executable  # the CLI ran in this interpreter's environment
