"""The verdict study's tables (rtsim/studies/verdict.py): per design, the knob the verdict names,
its estimated and measured speed-up, the best measured single knob, and the summary figures
(how often the named knob is within 10% of the best, the estimates' median error)."""

from __future__ import annotations

import json
import statistics
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rtsim.study import StudyRun


@dataclass
class Outcome:
    """A design's base run (its stats.json) and each measured knob's speed-up over it."""

    name: str
    base: dict[str, Any]
    measured: dict[str, float] = field(default_factory=dict)  # "key=to" -> speed-up (nan: none)


def knob_str(k: dict[str, Any]) -> str:
    """`key=to` as `--set` reads it (true/false for switches)."""
    to = k["to"]
    return f"{k['key']}={json.dumps(to) if isinstance(to, bool) else to}"


def named_knob(verdict: dict[str, Any]) -> tuple[str, float | None]:
    """The verdict's knob (`relax`, else its first candidate) and its estimate."""
    k = verdict.get("relax") or (verdict.get("top") or [{}])[0]
    if not k.get("key"):
        return "-", None
    return knob_str(k), k.get("speedup")


def best_structural(o: Outcome) -> str:
    """The best measured structural alternative of the design ("-" when none was measured)."""
    keys = {knob_str(k) for k in o.base["verdict"].get("structural") or []}
    measured = {k: g for k, g in o.measured.items() if k in keys and g == g}
    if not measured:
        return "-"
    k, g = max(measured.items(), key=lambda kv: kv[1])
    return f"`{k}` {g:.2f}x"


def _row(o: Outcome, figures: dict[str, Any]) -> str:
    v = o.base["verdict"]
    knob, est = named_knob(v)
    meas = o.measured.get(knob)
    singles = {k: g for k, g in o.measured.items() if " " not in k and g == g}
    best_knob, best = max(singles.items(), key=lambda kv: kv[1])
    within = meas is not None and meas >= best / 1.10
    within_gain = meas is not None and meas - 1 >= 0.9 * (best - 1)
    # What --check-verdict gives: the best measured of the top three and of the best estimated
    # structural alternative (the list is best first).
    top3 = [knob_str(k) for k in (v.get("top") or [])[:3]]
    top3 += [knob_str(k) for k in (v.get("structural") or []) if k.get("speedup")][:1]
    checked_knob, checked = max(
        ((k, o.measured[k]) for k in top3 if k in o.measured and o.measured[k] == o.measured[k]),
        key=lambda kv: kv[1],
        default=("-", float("nan")),
    )
    figures["within_10pct"] += within
    figures["within_10pct_of_gain"] += within_gain
    figures["checked_within_10pct_of_gain"] += checked - 1 >= 0.9 * (best - 1)
    if est is not None and meas:
        figures["errors"].append(abs(est - meas) / meas)
    co = "; ".join(
        f"{' + '.join(c['sets'])}: {c['joint']:.2f}x, measured "
        f"{o.measured.get(' '.join(c['sets']), float('nan')):.2f}x"
        for c in (v.get("co_limits") or [])[:1]
    )
    return (
        f"| {o.name} | {o.base['summary']['rays']:,} | `{knob}` | "
        f"{f'{est:.2f}x' if est is not None else 'not estimated'} | "
        f"{f'{meas:.2f}x' if meas is not None else '-'} | `{best_knob}` {best:.2f}x | "
        f"{'yes' if within else 'no'} / {'yes' if within_gain else 'no'} | "
        f"`{checked_knob}` {checked:.2f}x | {co or '-'} | {best_structural(o)} |"
    )


def table(outcomes: list[Outcome]) -> str:
    """The table and the sentence of its summary figures."""
    figures: dict[str, Any] = {
        "within_10pct": 0,
        "within_10pct_of_gain": 0,
        "checked_within_10pct_of_gain": 0,
        "errors": [],
    }
    rows = [
        "| design | rays | verdict names | estimated | measured | best single knob (measured) "
        "| within 10% (speed-up / gain) | best re-run by --check-verdict "
        "| co-limit (estimated jointly, measured) | best structural alternative (measured) |",
        "|---|---:|---|---:|---:|---|:-:|---|---|---|",
    ]
    rows += [_row(o, figures) for o in outcomes]
    text = "\n".join(rows) + "\n"
    n, errors = len(outcomes), figures["errors"]
    if not errors:
        return text + "\n"
    return text + (
        f"\nThe named knob is within 10% of the best measured single knob (its speed-up at least "
        f"the best's / 1.10) in **{figures['within_10pct']} of {n}** designs, and its gain within "
        f"10% of the best gain (gain at least 0.9 x the best's) in "
        f"**{figures['within_10pct_of_gain']} of {n}**; the best measured of its top three and "
        f"its best estimated structural alternative (what `--check-verdict` re-runs) is within "
        f"10% of the best gain in "
        f"**{figures['checked_within_10pct_of_gain']} of {n}**; median error of the "
        f"{len(errors)} estimates against their measured gain: "
        f"**{100 * statistics.median(errors):.1f}%**.\n"
    )


def note(run: StudyRun, kind: str, outcomes: list[Outcome]) -> str:
    """How it was measured: the command, the trace, the runs."""
    o, m = run.options, run.measured()
    if kind == "unseen":
        what = f"the hairball ({o['hairball_triangles'] // 1000}k triangles) diffuse"
        res = o["unseen_resolution"]
    else:
        what, res = "Sponza diffuse", o["resolution"]
    points = sum(1 + len(x.measured) for x in outcomes)
    return (
        f"\nMeasured by `{run.command}` on {m['host']} ({m['machine']}), {m['date']}: {what} at "
        f"{res}, {points} runs at the approx level (the study's {run.runs} distinct runs, both "
        f"sets, took {run.sim_seconds:.0f} s of rtsim-sim time), one run each (the model is "
        "deterministic).\n"
    )


def structural_table(outcomes: list[Outcome]) -> str:
    """Every estimated structural knob of the designs against its measured speed-up."""
    rows = [
        "| design | structural knob | estimated on | estimated | measured | error |",
        "|---|---|---|---:|---:|---:|",
    ]
    errors, signs = [], 0
    for o in outcomes:
        for k in o.base["verdict"].get("structural") or []:
            est, meas = k.get("speedup"), o.measured.get(knob_str(k), float("nan"))
            if est is None:
                continue
            err = abs(est - meas) / meas if meas == meas else float("nan")
            if err == err:
                errors.append(err)
                signs += (est > 1) == (meas > 1)
            on = "the alternative trace" if k.get("trace") else "the run's trace"
            rows.append(
                f"| {o.name} | `{knob_str(k)}` | {on} | {est:.2f}x | "
                f"{f'{meas:.2f}x' if meas == meas else '-'} | "
                f"{f'{100 * err:.1f}%' if err == err else '-'} |"
            )
    text = "\n".join(rows) + "\n"
    if not errors:
        return text
    within = sum(e <= 0.10 for e in errors)
    return text + (
        f"\nOf the {len(errors)} structural estimates, {within} are within 10% of the measured "
        f"speed-up and {signs} say rightly whether the knob pays (above 1x or not); median "
        f"error **{100 * statistics.median(errors):.1f}%**, largest "
        f"{100 * max(errors):.1f}%.\n"
    )
