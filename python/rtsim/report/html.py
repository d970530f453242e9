"""The self-contained HTML report of a sweep: figures as embedded PNG, tables as HTML.

Sections: overview, design space (rays/s against each key, speed-up over the baseline, the
Pareto fronts of rays/s against on-chip SRAM, chip area and energy per ray with the best
configurations named), bandwidth (DRAM bytes per ray by data kind, bandwidth over time, cache hit
rates), validation (hit mismatches per run, effects per scene).
"""

from __future__ import annotations

import base64
import io
from datetime import datetime, timezone
from html import escape
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from rtsim.report import figures
from rtsim.report.accel_section import accel_section
from rtsim.report.data import (
    COSTS,
    SweepData,
    area_mm2,
    energy_nj,
    load,
    mrays,
    short_label,
    sram_kib,
)
from rtsim.report.frame_section import frame_section
from rtsim.sweep.store import RunRecord

CSS = """
body { font-family: system-ui, -apple-system, 'Segoe UI', sans-serif; margin: 2em auto;
       max-width: 1400px; padding: 0 1.5em; color: #222; line-height: 1.45; }
h1 { font-size: 1.7em; margin-bottom: 0.2em; } h2 { border-bottom: 2px solid #ddd;
 padding-bottom: 0.2em; margin-top: 2em; } h3 { margin-top: 1.5em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }
th, td { border: 1px solid #ddd; padding: 0.3em 0.6em; text-align: left; vertical-align: top; }
th { background: #f4f4f4; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
.bad { color: #b00; font-weight: bold; } .good { color: #080; }
figure { margin: 1em 0 2em 0; } figure img { max-width: 100%; height: auto; }
figcaption { color: #555; font-size: 0.92em; max-width: 75em; }
.thumbs { display: flex; flex-wrap: wrap; gap: 1em; } .thumbs figure { margin: 0; }
.thumbs img { width: 256px; image-rendering: pixelated; border: 1px solid #ccc; }
pre { background: #f7f7f7; padding: 0.8em; overflow-x: auto; font-size: 0.85em; }
.muted { color: #666; }
"""


def _png(fig: Figure) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=96, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def _figure(fig: Figure | None, alt: str, caption: str) -> str:
    if fig is None:
        return f"<p class='muted'>{escape(alt)}: nothing to plot (no successful runs).</p>"
    return (
        f"<figure><img alt='{escape(alt)}' src='data:image/png;base64,{_png(fig)}'>"
        f"<figcaption>{caption}</figcaption></figure>"
    )


def _table(header: list[str], rows: list[list[Any]], numeric: set[int] | None = None) -> str:
    numeric = numeric or set()
    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = []
        for i, c in enumerate(row):
            cls = " class='num'" if i in numeric else ""
            cells.append(f"<td{cls}>{c}</td>")  # cells are escaped by the caller
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><tr>{head}</tr>{''.join(body)}</table>"


def _overview(data: SweepData) -> str:
    counts = {s: sum(r.status == s for r in data.runs) for s in ("ok", "mismatch", "failed")}
    first = next((r.provenance for r in data.runs if r.provenance), {}) or {}
    sim_seconds = sum(r.wall_seconds or 0 for r in data.runs)
    rows = [
        [
            "runs",
            f"{len(data.runs)}: <span class='good'>{counts['ok']} ok</span>, "
            f"<span class='{'bad' if counts['mismatch'] else ''}'>{counts['mismatch']} hit "
            f"mismatch</span>, <span class='{'bad' if counts['failed'] else ''}'>"
            f"{counts['failed']} failed</span>",
        ],
        ["scenes x workloads", escape(", ".join(g.title for g in data.groups()))],
        ["swept keys", escape(", ".join(data.keys) or "(none)")],
        ["simulation time", f"{sim_seconds:.1f} s summed over runs"],
        [
            "rtsim",
            escape(
                f"{first.get('rtsim_version', data.meta.get('rtsim_version', '?'))} "
                f"(git {first.get('git', '?')})"
            ),
        ],
        ["store", escape(str((data.path / "results.sqlite").resolve()))],
    ]
    # A run too small to answer its question (stats `study_size`, docs/treelets.md), and one whose
    # design its level was measured outside its band on (stats `fidelity_band`, docs/fidelity.md).
    for key, label, what in (
        ("study_warnings", "too small", "runs are too small to answer their question"),
        (
            "fidelity_warnings",
            "outside its band",
            "runs are of designs their level was measured outside its band on (docs/fidelity.md)",
        ),
    ):
        row = _warned_runs(data, key, label, what)
        if row:
            rows.append(row)
    spec = data.meta.get("spec", "")
    return _table(["", ""], rows) + (
        f"<details><summary>sweep spec</summary><pre>{escape(spec)}</pre></details>" if spec else ""
    )


def _warned_runs(data: SweepData, key: str, label: str, what: str) -> list[str] | None:
    """An overview row listing the runs whose summary `key` holds warnings (the first 12)."""
    warned = [r for r in data.runs if r.summary.get(key)]
    if not warned:
        return None
    items = "".join(
        f"<li>{escape(data.label(r))} ({escape(r.scene)} / {escape(r.workload)}): "
        f"{escape('; '.join(r.summary[key]))}</li>"
        for r in warned[:12]
    )
    more = f"<li>and {len(warned) - 12} more</li>" if len(warned) > 12 else ""
    return [
        f"<span class='bad'>{label}</span>",
        f"{len(warned)} of {len(data.runs)} {what}:<ul>{items}{more}</ul>",
    ]


def _scenes(data: SweepData) -> str:
    items = []
    for g in data.groups():
        render = data.trace_render(g.runs[0])
        rays = next((r.summary.get("rays") for r in g.runs if r.summary.get("rays")), None)
        if render is None:
            continue
        img = base64.b64encode(render.read_bytes()).decode()
        items.append(
            f"<figure><img alt='render of {escape(g.title)}' "
            f"src='data:image/png;base64,{img}'><figcaption>{escape(g.title)}"
            f"{f', {rays:,} rays' if rays else ''}</figcaption></figure>"
        )
    return f"<div class='thumbs'>{''.join(items)}</div>" if items else ""


def _num(x: float | None, fmt: str) -> str:
    return "-" if x is None else format(x, fmt)


def _front_table(data: SweepData, fronts: dict[str, list[RunRecord]], cost: str) -> str:
    rows = []
    for title, front in fronts.items():
        best = max(front, key=mrays)
        for i, r in enumerate(front):
            name = escape(data.label(r)) + (" <b>(fastest)</b>" if r is best else "")
            rows.append(
                [
                    escape(title),
                    str(i + 1),
                    name,
                    _num(sram_kib(r), ",.0f"),
                    _num(area_mm2(r), ".2f"),
                    _num(energy_nj(r), ".2f"),
                    f"{mrays(r):.1f}",
                    f"{r.summary.get('dram_bytes_per_ray', 0):.0f}",
                ]
            )
    header = ["scene / workload", "#", "configuration", "SRAM (KiB)", "area (mm²)", "nJ/ray"]
    return f"<p class='muted'>front against {escape(COSTS[cost].name)}</p>" + _table(
        [*header, "Mrays/s", "DRAM B/ray"], rows, {1, 3, 4, 5, 6, 7}
    )


def _baseline_text(data: SweepData) -> str:
    """The baseline the bars are over: each group's own baseline run, by its label (the spec's
    point alone could name a run of another spec in a store holding two)."""
    named = []
    for g in data.groups():
        base = data.baseline_run(g.ok)
        if base is not None:
            named.append(f"{g.title}: {data.label(base)}")
    if named:
        return escape("; ".join(dict.fromkeys(named)))
    if not data.baseline:
        return "the first configuration"
    return escape(" · ".join(short_label(k, v) for k, v in data.baseline.items()))


def _pareto_section(data: SweepData) -> list[str]:
    """A Pareto front of rays/s against each cost (SRAM, area, energy) with its table."""
    captions = {
        "sram": "On-chip SRAM as the area model counts it (stats.json area.sram_bytes): L1 size x "
        "traversal units + L2 + traversal stacks (units x ray contexts x stack entries x entry "
        "bytes) + ray-context state, plus the mailboxes and the ray buffer when they are on.",
        "area": "Chip area from the first-order model of docs/energy_area.md: SRAM (L1s, L2, ray "
        "buffer, stacks, ray contexts) plus the box, triangle and any-hit pipelines, at the "
        "configured technology node (energy.node_nm).",
        "energy": "Energy per ray from the first-order model of docs/energy_area.md: pipelines, "
        "traversal state, L1s, L2, ray buffer, DRAM (by kind) and leakage.",
    }
    out = []
    for cost in ("sram", "area", "energy"):
        fig, fronts = figures.pareto(data, cost)
        out.append(
            _figure(
                fig,
                f"Pareto front of rays/s against {COSTS[cost].name}",
                captions[cost] + " Front points are numbered; the table names them.",
            )
        )
        if fronts:
            out.append(_front_table(data, fronts, cost))
    return out


def _validation(data: SweepData) -> str:
    rows = []
    for g in data.groups():
        for r in g.runs:
            v = (r.stats or {}).get("validation", {})
            hm = v.get("hit_mismatches")
            cls = "bad" if hm else "good"
            status = (
                escape(r.status)
                if r.status == "ok"
                else f"<span class='bad'>{escape(r.status)}</span>"
            )
            rows.append(
                [
                    escape(g.title),
                    escape(data.label(r)),
                    status,
                    f"{v.get('rays_checked', '-'):,}" if v else "-",
                    f"<span class='{cls}'>{hm}</span>" if hm is not None else "-",
                    str(v.get("work_mismatches", "-")),
                ]
            )
    total = sum(
        ((r.stats or {}).get("validation", {}).get("hit_mismatches") or 0) for r in data.runs
    )
    verdict = (
        "<p class='good'>Every simulated hit equals the reference tracer's hit "
        "(0 mismatches in all runs with stats).</p>"
        if total == 0
        else f"<p class='bad'>{total} hit mismatches: the model traced wrong.</p>"
    )
    per_group = []
    for g in data.groups():
        vals = [(r.stats or {}).get("validation", {}) for r in g.runs]
        hm = sum(v.get("hit_mismatches") or 0 for v in vals)
        per_group.append(
            [
                escape(g.title),
                str(len(g.runs)),
                str(sum(bool(v) for v in vals)),
                f"{sum(v.get('rays_checked') or 0 for v in vals):,}",
                f"<span class='{'bad' if hm else 'good'}'>{hm}</span>",
                str(sum(v.get("work_mismatches") or 0 for v in vals)),
            ]
        )
    summary = _table(
        [
            "scene / workload",
            "runs",
            "runs checked",
            "rays checked",
            "hit mismatches",
            "work mismatches",
        ],
        per_group,
        {1, 2, 3, 4, 5},
    )
    every = _table(
        [
            "scene / workload",
            "configuration",
            "status",
            "rays checked",
            "hit mismatches",
            "work mismatches",
        ],
        rows,
        {3, 4, 5},
    )
    return (
        verdict + summary + f"<details><summary>every run ({len(rows)})</summary>{every}</details>"
    )


def _effects(data: SweepData) -> str:
    rows = []
    for g in data.groups():
        stats = next((r.stats for r in g.runs if r.stats), None)
        if not stats:
            continue
        eff = stats.get("effects", [])
        inst = stats.get("instantiated", [])
        on = "<br>".join(
            f"<b>{escape(e['name'])}</b>: {escape(e.get('why', ''))}"
            for e in eff
            if e.get("simulated")
        )
        off = "<br>".join(
            f"{escape(e['name'])}: {escape(e.get('why', ''))}"
            for e in eff
            if not e.get("simulated")
        )
        blocks = "<br>".join(
            f"{'<b>' if b.get('instantiated') else ''}{escape(b['block'])}"
            f"{'</b>' if b.get('instantiated') else ' (not instantiated)'}: "
            f"{escape(b.get('why', ''))}"
            for b in inst
        )
        rows.append([escape(g.title), on, off, blocks])
    return _table(
        [
            "scene / workload",
            "effects simulated (why)",
            "not simulated (why)",
            "model blocks (first run)",
        ],
        rows,
    )


def _agreement_cell(a: dict[str, Any]) -> str:
    """The roofline's lowest ceiling and the analytic binding, in the verdict's names, and
    whether the named knob relaxes each (stats `verdict.agreement`)."""
    if not a:
        return "-"

    def mark(flag: Any) -> str:
        return (
            ""
            if flag is None or not a.get("knob")
            else (" (relaxed)" if flag else " (not relaxed)")
        )

    roof = a.get("roofline_bound")
    parts = [f"{roof}{mark(a.get('roofline_relaxed'))}" if roof else "-"]
    parts.append(f"{a.get('analytic_binding', '-')}{mark(a.get('analytic_relaxed'))}")
    return " / ".join(parts)


def _why_slow(data: SweepData) -> str:
    """Per scene and workload: how many configurations each resource binds, and every run's
    verdict (stats `verdict`: the bottleneck, its evidence, the knob to relax and its estimate)."""
    out = []
    for g in data.groups():
        runs = [r for r in g.ok if (r.stats or {}).get("verdict")]
        if not runs:
            continue
        counts: dict[str, int] = {}
        for r in runs:
            label = str(r.stats["verdict"].get("label", "?"))
            counts[label] = counts.get(label, 0) + 1
        tally = ", ".join(
            f"{escape(k)}: {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])
        )
        rows = []
        for r in sorted(runs, key=lambda r: -r.summary["rays_per_second"]):
            v = r.stats["verdict"]
            relax = v.get("relax") or {}
            speedup = relax.get("speedup")
            rows.append(
                [
                    escape(data.label(r)),
                    f"{r.summary['rays_per_second'] / 1e6:,.2f}",
                    escape(f"{v.get('label', '-')} ({v.get('binding', '?')})"),
                    escape(str((v.get("evidence") or {}).get("text", ""))),
                    escape(f"{relax.get('key')} {relax.get('from')} -> {relax.get('to')}")
                    if relax
                    else "-",
                    f"{speedup:.2f}x" if isinstance(speedup, (int, float)) else "-",
                    escape(_agreement_cell(v.get("agreement") or {})),
                ]
            )
        table = _table(
            [
                "configuration",
                "Mrays/s",
                "bottleneck",
                "its evidence",
                "relax",
                "estimated",
                "roofline ceiling / analytic binding",
            ],
            rows,
            numeric={1, 5},
        )
        out.append(
            f"<h3>{escape(g.title)}</h3><p>Binding resource over {len(runs)} configurations: "
            f"{tally}.</p><details><summary>every run's verdict</summary>{table}</details>"
        )
    if not out:
        return "<p class='muted'>No verdicts (functional runs, or runs with --no-verdict).</p>"
    return "".join(out)


def _failures(data: SweepData) -> str:
    bad = [r for r in data.runs if r.status != "ok"]
    if not bad:
        return "<p class='good'>No failed runs.</p>"
    rows = [
        [
            escape(f"{r.scene} / {r.workload}"),
            escape(data.label(r)),
            escape(r.status),
            f"<pre>{escape(r.error or '')}</pre>",
        ]
        for r in bad
    ]
    return _table(["scene / workload", "configuration", "status", "error"], rows)


def render_report(data: SweepData) -> str:
    name = escape(data.meta.get("name", data.path.name))
    when = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    parts = [
        f"<h1>rtsim sweep report: {name}</h1><p class='muted'>generated {when}</p>",
        _overview(data),
        _scenes(data),
        "<h2>Design space</h2>",
        _figure(
            figures.rays_per_second(data),
            "rays per second against each swept key",
            "Simulated rays per second (Mrays/s at the configured clock) against each swept "
            "key, one line per scene and workload, and per value of the other categorical keys "
            "(e.g. treelets on and off are separate lines, never one median).",
        ),
        _figure(
            figures.speedup(data),
            "speed-up over the baseline configuration",
            f"Simulated rays/s of each configuration over the baseline ({_baseline_text(data)}; "
            "a spec names it with <code>baseline:</code>, docs/sweeps.md), per scene and "
            "workload.",
        ),
        "<h3>Pareto fronts: rays/s against SRAM, area and energy</h3>",
        *_pareto_section(data),
        "<h2>Why is it slow</h2>",
        "<p>Every timed run states its bottleneck with evidence from its cycle accounting and "
        "utilisations, and the knob that relaxes it with the analytic level's estimate of the "
        "gain (docs/model.md, docs/stats.md <code>verdict</code>).</p>",
        _why_slow(data),
        _figure(
            figures.roofline(data),
            "roofline: rays per second against DRAM bytes per ray",
            "Every run a point: simulated Mrays/s against DRAM bytes per ray. Dashed: the DRAM "
            "ceiling of each peak bandwidth in the sweep (peak / bytes per ray); grey bars: each "
            "run's lowest other ceiling of its own config: pipelines, scheduler, L1 and L2 "
            "MSHRs (Little's law), L2 bandwidth (stats <code>roofline.ceilings</code>). "
            "A point on a line is bound by it; a point far below both is latency- or queue-bound, "
            "and its verdict above says by what.",
        ),
        "<h2>Bandwidth</h2>",
        _figure(
            figures.bytes_per_ray(data),
            "DRAM bytes per ray by data kind",
            "DRAM bytes read and written per ray, split by what the bytes are: BVH nodes, "
            "triangles, ray records, hit records, traversal-stack spills.",
        ),
        _figure(
            figures.bandwidth_over_time(data),
            "DRAM bandwidth over time",
            "DRAM bandwidth in buckets of simulated time for three configurations per "
            "scene and workload; dashed lines are each one's peak.",
        ),
        _figure(
            figures.hit_rates(data),
            "cache hit rates per level",
            "L1 (mean over the per-unit L1s) and L2 hit rates against each swept key.",
        ),
        *accel_section(data, _table),
        *frame_section(data, _table),
        "<h2>Validation</h2>",
        "<h3>Hit mismatches per run (must be zero)</h3>",
        _validation(data),
        "<h3>Effects simulated per scene</h3>",
        _effects(data),
        "<h3>Failed runs</h3>",
        _failures(data),
    ]
    return (
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>rtsim: {name}"
        f"</title><style>{CSS}</style></head><body>{''.join(parts)}</body></html>\n"
    )


def write_report(sweep: Path, out: Path) -> Path:
    """Writes the report of the sweep folder to out (atomically) and returns out."""
    html = render_report(load(sweep))
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".tmp")
    tmp.write_text(html)
    tmp.replace(out)
    return out
