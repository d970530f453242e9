"""The reference tracer against Embree (docs/benchmarks.md): runs `rtsim bench` several times and
writes the tables between the bench-tracer markers of the doc, with the host, its load and the
dates the figures come from. With --model, the simulator's own speed instead: one
`rtsim bench --model TRACE ... --json OUT/model.json` process (its rounds interleave the levels,
and with --against an older rtsim-sim run by run), its tables written between the bench-model
markers with the host, its load, the date and whether the verdict was timed.

    python scripts/bench_doc.py --out out/bench [--runs 6] [--scene sponza] \\
        [--accel bvh2,bvh8,cwbvh8,bvh8:sbvh] [--build-threads 2] [--repeat 5] \\
        [--before OLD_RTSIM_BENCH] [--before-accel bvh2,bvh8,cwbvh8] [--doc docs/benchmarks.md]
    python scripts/bench_doc.py --out out/bench --from-json [--doc docs/benchmarks.md]
    python scripts/bench_doc.py --out out/bench_model --model TRACE [--model TRACE ...] \\
        [--levels functional,analytic,approx] [--repeat 5] [--against OLD_RTSIM_SIM] [--verdict] \\
        [--from-json] [--doc docs/benchmarks.md]

Each run is one `rtsim bench ... --json OUT/run-K.json` process (with --before, an older
rtsim-bench binary runs right after each, into OUT/before-K.json: interleaved, so the machine's
load falls on both alike). Every figure in the tables is the median over the runs of each run's
own figure, itself the median of --repeat interleaved repetitions in that process; ratios
against Embree are taken within each run first (CPU time, measured in the same process as
Embree's), then their median. --from-json re-renders the tables from the JSON files already in
OUT.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between

Run = dict[str, Any]
RAYS = ("primary", "diffuse", "shadow")


def run_bench(exe: list[str], args: argparse.Namespace, accel: str, out: Path, threads: int) -> Run:
    cmd = [*exe, "--repeat", str(args.repeat), "--accel", accel, "--json", str(out)]
    if args.scene:
        from rtsim.scenes import resolve_scene

        cmd.insert(len(exe), resolve_scene(args.scene))
    if threads > 1:
        cmd += ["--build-threads", str(threads)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return json.loads(out.read_text())


def collect(args: argparse.Namespace) -> tuple[list[Run], list[Run]]:
    args.out.mkdir(parents=True, exist_ok=True)
    if args.from_json:
        load = lambda pattern: [json.loads(p.read_text()) for p in sorted(args.out.glob(pattern))]  # noqa: E731
        return load("run-*.json"), load("before-*.json")
    runs: list[Run] = []
    before: list[Run] = []
    bench = [sys.executable, "-m", "rtsim", "bench"]
    for k in range(args.runs):
        runs.append(
            run_bench(bench, args, args.accel, args.out / f"run-{k}.json", args.build_threads)
        )
        if args.before:
            before.append(
                run_bench([args.before], args, args.before_accel, args.out / f"before-{k}.json", 1)
            )
        print(f"run {k + 1}/{args.runs} done", file=sys.stderr)
    return runs, before


def median(values: list[float]) -> float:
    return statistics.median(values) if values else float("nan")


def spread(values: list[float]) -> str:
    return f"{min(values):.2f}-{max(values):.2f}" if values else "-"


def kinds_of(runs: list[Run]) -> list[str]:
    """The structures in the order the runs named them (--accel)."""
    return list(runs[0]["accel"]) if runs else []


def build_rows(runs: list[Run]) -> dict[str, dict[str, list[float]]]:
    rows: dict[str, dict[str, list[float]]] = {}
    for r in runs:
        embree = r["build"]["embree"]["cpu_ms"]
        rows.setdefault("Embree", {"ms": [], "ratio": []})["ms"].append(embree)
        for kind, b in r["build"]["structures"].items():
            row = rows.setdefault(kind, {"ms": [], "ratio": []})
            row["ms"].append(b["cpu_ms"])
            row["ratio"].append(b["cpu_ms"] / embree)
    return rows


def ray_rows(runs: list[Run], rays: str) -> dict[str, dict[str, list[float]]]:
    rows: dict[str, dict[str, list[float]]] = {}
    for r in runs:
        figures = r["rays"][rays]
        rows.setdefault("Embree", {"mrays": [], "ratio": []})["mrays"].append(
            figures["embree"]["mrays_per_s_cpu"]
        )
        for kind, f in figures["structures"].items():
            row = rows.setdefault(kind, {"mrays": [], "ratio": []})
            row["mrays"].append(f["rtsim"]["mrays_per_s_cpu"])
            row["ratio"].append(f["ratio_cpu"])
    return rows


def provenance(runs: list[Run], before: list[Run], args: argparse.Namespace) -> str:
    first = runs[0]
    loads = [
        r["host"][k] for r in runs + before for k in ("load_average_start", "load_average_end")
    ]
    dates = sorted(r["date"] for r in runs + before)
    res = "x".join(str(v) for v in first["resolution"])
    counts = ", ".join(f"{first['rays'][k]['rays']:,} {k}" for k in RAYS)
    text = (
        f"{dates[0][:10]}, {dates[0][11:16]}-{dates[-1][11:16]} UTC, on {first['host']['cpu']} "
        f"({first['hardware_threads']} hardware threads), load average {min(loads):.1f} to "
        f"{max(loads):.1f} during the runs (other jobs shared the machine: read the CPU-time "
        f"figures and the ratios, which Embree's runs in the same process share). rtsim git "
        f"`{first['git']}`, Embree {first['embree_version']}. {len(runs)} runs of `rtsim bench "
        f"{Path(first['scene']).stem.lower()} --accel {','.join(kinds_of(runs))} --repeat "
        f"{first['repeat']}` ({res}: {first['triangles']:,} triangles; {counts} rays)"
    )
    if before:
        text += (
            f", each followed by the previous binary (git `{before[0]['git']}`) on "
            f"`--accel {','.join(kinds_of(before))}`"
        )
    return (
        text + ". Generated by `python scripts/bench_doc.py`; per figure, the median over the runs."
    )


def table_build(runs: list[Run], before: list[Run]) -> list[str]:
    now, old = build_rows(runs), build_rows(before)
    head = "| build, one thread | CPU ms | / Embree (runs) |"
    rule = "|---|---:|---:|"
    if before:
        head += " before: CPU ms | before: / Embree |"
        rule += "---:|---:|"
    lines = [head, rule]
    for kind, row in now.items():
        line = f"| `{kind}` | {median(row['ms']):.1f} | "
        line += (
            "1 |"
            if kind == "Embree"
            else f"**{median(row['ratio']):.2f}** ({spread(row['ratio'])}) |"
        )
        if before:
            b = old.get(kind)
            if b is None:
                line += " - | - |"
            else:
                ratio = "1" if kind == "Embree" else f"{median(b['ratio']):.2f}"
                line += f" {median(b['ms']):.1f} | {ratio} |"
        lines.append(line)
    return lines


def table_parallel(runs: list[Run]) -> list[str]:
    parallel = [r["build"]["parallel"] for r in runs if "parallel" in r["build"]]
    if not parallel:
        return []
    lines = [
        f"| build on {parallel[0]['threads']} threads | wall ms | process CPU ms | speed-up "
        "over one thread (wall) |",
        "|---|---:|---:|---:|",
    ]
    for kind in parallel[0]["structures"]:
        s = [p["structures"][kind] for p in parallel]
        up = [x["speedup_wall"] for x in s]
        lines.append(
            f"| `{kind}` | {median([x['wall_ms'] for x in s]):.1f} | "
            f"{median([x['process_cpu_ms'] for x in s]):.1f} | {median(up):.2f} ({spread(up)}) |"
        )
    return lines


def table_rays(runs: list[Run], before: list[Run]) -> list[str]:
    head = "| Mrays/s (CPU) |" + "".join(f" {k} | / Embree |" for k in RAYS)
    rule = "|---|" + "---:|---:|" * len(RAYS)
    lines = [head, rule]
    for label, source in [("", runs), ("before: ", before)] if before else [("", runs)]:
        rows = {k: ray_rows(source, k) for k in RAYS}
        for kind in rows["primary"]:
            if label and kind == "Embree":
                continue
            cells = ""
            for k in RAYS:
                row = rows[k][kind]
                ratio = (
                    "1"
                    if kind == "Embree"
                    else f"**{median(row['ratio']):.2f}** ({spread(row['ratio'])})"
                )
                if label:
                    ratio = ratio.replace("**", "")
                cells += f" {median(row['mrays']):.2f} | {ratio} |"
            lines.append(f"| {label}`{kind}` |{cells}")
    return lines


def render(runs: list[Run], before: list[Run], args: argparse.Namespace) -> str:
    parts = [provenance(runs, before, args), "", *table_build(runs, before), ""]
    parallel = table_parallel(runs)
    if parallel:
        parts += [*parallel, ""]
    parts += table_rays(runs, before)
    return "\n".join(parts) + "\n"


def run_model(args: argparse.Namespace) -> dict[str, Any]:
    """`rtsim bench --model` once (or its JSON already in OUT with --from-json)."""
    out = args.out / "model.json"
    if not args.from_json:
        args.out.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, "-m", "rtsim", "bench", "--repeat", str(args.repeat)]
        for trace in args.model:
            cmd += ["--model", trace]
        cmd += ["--levels", args.levels, "--json", str(out)]
        if args.against:
            cmd += ["--against", args.against]
        if args.verdict:
            cmd.append("--verdict")
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return json.loads(out.read_text())


def render_model(bench: dict[str, Any]) -> str:
    """The model's speed tables (model_bench.markdown) under what, where and when."""
    from rtsim.model_bench import markdown, verdict_note

    host = bench["host"]
    traces = ", ".join(
        f"`{Path(t['trace']).name}` ({max(s['rays'] for s in t['levels'].values()):,} rays)"
        for t in bench["traces"]
    )
    text = (
        f"{bench['date_start'][:10]}, {bench['date_start'][11:16]}-{bench['date_end'][11:16]} "
        f"UTC, on {host['cpu']} ({host['hardware_threads']} hardware threads), load average "
        f"{host['load_average_start']:.1f} at the start and {host['load_average_end']:.1f} at the "
        f"end (other jobs shared the machine: read the CPU times). rtsim-sim git `{bench['git']}`"
        f"{', against ' + Path(bench['against']).name if bench['against'] else ''}. "
        f"{bench['repeat']} rounds of every level in turn on {traces}"
        f"{' with ' + ' '.join('--set ' + s for s in bench['set']) if bench['set'] else ''}; "
        f"per figure, the median over the rounds of the process's CPU time (user + system). "
        f"{verdict_note(bench['verdict'])} Generated by `python scripts/bench_doc.py --model`."
    )
    named = [{**t, "trace": Path(t["trace"]).name} for t in bench["traces"]]  # no host paths
    return text + "\n\n" + markdown(named)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="folder of the runs' JSON files")
    parser.add_argument("--runs", type=int, default=6, help="rtsim bench processes")
    parser.add_argument("--scene", default=None, help="scene (default: rtsim bench's, Sponza)")
    parser.add_argument("--accel", default="bvh2,bvh8,cwbvh8,bvh8:sbvh", help="structures")
    parser.add_argument("--build-threads", type=int, default=2, help="also time N-thread builds")
    parser.add_argument("--repeat", type=int, default=5, help="repetitions per run (median)")
    parser.add_argument("--before", default=None, help="an older rtsim-bench, run after each run")
    parser.add_argument("--before-accel", default="bvh2,bvh8,cwbvh8", help="its structures")
    parser.add_argument("--from-json", action="store_true", help="re-render OUT's JSON files")
    parser.add_argument("--doc", type=Path, default=None, help="write the tables into this doc")
    parser.add_argument("--model", action="append", default=None, help="instead: trace folder to "
                        "time the simulator on (repeatable; rtsim bench --model)")  # fmt: skip
    parser.add_argument("--levels", default="functional,analytic,approx", help="with --model")
    parser.add_argument("--against", default=None, help="with --model: an older rtsim-sim")
    parser.add_argument("--verdict", action="store_true", help="with --model: time default runs")
    args = parser.parse_args()
    if args.model:
        text = render_model(run_model(args))
        print(text)
        if args.doc:
            write_between(args.doc, "bench-model", text)
        return 0
    runs, before = collect(args)
    if not runs:
        raise SystemExit(f"no runs in {args.out}")
    text = render(runs, before, args)
    print(text)
    if args.doc:
        write_between(args.doc, "bench-tracer", text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
