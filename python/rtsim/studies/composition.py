"""How much of the design space composes (docs/capabilities.md, "How much composes"): every
execution model x structure x technique x level an architect would try, each run on a tiny
Cornell box (two levels: the grove), counted as run or refused, and the refused ones by the rule
or message that refused them.

The product: unit kinds mimd, simt (32 lanes, 32 ray contexts) and packet (16 rays); structures
bvh2, bvh4, bvh8, cwbvh8, kdtree, bih, bkd, gkbvh, octree, grid and two levels; no technique or
one of treelets, treelet prefetching (with queues, and without), the restart-trail short stack,
8-bit boxes, mailboxes, ray sorting, stack-driven prefetching (TTP), cooperative lanes (CoopRT),
quantised boxes (AQB8), compressed leaves (a build setting); levels functional, analytic,
approx, detailed and approx with 20% sampling. The specs skip the sweep's run check
(`check_runs: false`), so a combination the simulator refuses is a failed run (a row with its
message: the study allows failed runs), and one whose trace the tracer refuses fails with the
tracer's message. A hit or work mismatch stops the study.

Before and after: the `before` option names the folder of an earlier run of this study made with
another rtsim-sim (`RTSIM_SIM=OLD_RTSIM_SIM rtsim study composition -o DIR`: the runs' ids do not
name the binary, so it needs a folder of its own); its `DIR/study.csv` is counted beside this
run's. The older binary is given this build's config keys: a key it does not know fails its runs,
which then count as refused."""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

from rtsim.study import Study, StudyRun, Table
from rtsim.study.core import StudyError

UNITS: dict[str, dict[str, Any]] = {
    "mimd": {"traversal.model": "mimd"},
    "simt 32": {
        "traversal.model": "simt",
        "traversal.simt.lanes": 32,
        "traversal.ray_contexts": 32,
    },
    "packet 16": {
        "traversal.model": "packet",
        "traversal.packet.lanes": 16,
        "traversal.ray_contexts": 16,
    },
}
STRUCTURES = [
    "bvh2", "bvh4", "bvh8", "cwbvh8", "kdtree", "bih", "bkd", "gkbvh", "octree", "grid",
    "two_level",
]  # fmt: skip
LEAVES = "compressed leaves"  # a build setting: its runs are on a trace built with it
TECHNIQUES: dict[str, dict[str, Any]] = {
    "(none)": {},
    "treelets": {"treelets.enabled": True},
    "treelet prefetching": {"treelets.enabled": True, "treelets.prefetch": True},
    "prefetching, no queues": {"treelets.prefetch": True},
    "restart trail": {"traversal.stack_overflow": "restart_trail"},
    "8-bit boxes": {"traversal.box_precision_bits": 7},
    "mailbox": {"mailbox.entries": 8},
    "ray sorting": {"dispatch.sort": "morton"},
    "stack prefetching (TTP)": {"traversal.stack_prefetch": 2},
    "cooperative lanes (CoopRT)": {"traversal.simt.cooperative": True},
    "quantised boxes (AQB8)": {"traversal.quantized_boxes": True},
    LEAVES: {},
}
LEVELS: dict[str, dict[str, Any]] = {
    "functional": {"fidelity": "functional"},
    "analytic": {"fidelity": "analytic"},
    "approx": {"fidelity": "approx"},
    "detailed": {"fidelity": "detailed"},
    "20% sampling": {"fidelity": "approx", "sampling.fraction": 0.2},
}
SEP = " / "  # between the unit, technique and level of a point's label


def points(techniques: list[str]) -> list[dict[str, Any]]:
    return [
        {"label": SEP.join((u, t, lv)), "set": {**UNITS[u], **TECHNIQUES[t], **LEVELS[lv]}}
        for u in UNITS
        for t in techniques
        for lv in LEVELS
    ]


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """Per structure: its plain trace with every technique but compressed leaves, then the
    trace built with compressed leaves (no model technique)."""
    out = []
    plain = [t for t in TECHNIQUES if t != LEAVES]
    for s in STRUCTURES:
        scene, kind = ("grove", "bvh2") if s == "two_level" else ("cornell", s)
        for name, accel, techniques in (
            (s, kind, plain),
            (f"{s}+cl", {"kind": kind, "build": {"compressed_leaves": True}}, [LEAVES]),
        ):
            out.append(
                {
                    "name": f"composition-{name}",
                    "scenes": [scene],
                    "workloads": [{"name": "scene", "resolution": o["resolution"]}],
                    "accel": [accel],
                    "points": points(techniques),
                    "timeout": o["timeout"],
                    "check_runs": False,
                }
            )
    return out


def cell(row: dict[str, Any]) -> dict[str, Any]:
    """A frame row as a combination: unit, structure, technique, level, and how it went."""
    unit, technique, level = str(row["point"]).split(SEP)
    structure = str(row["part"]).removeprefix("composition-").removesuffix("+cl")
    ok = row["status"] != "failed"
    message = " ".join(str(row.get("error") or "").split())
    return {
        "unit": unit,
        "structure": structure,
        "technique": technique,
        "level": level,
        "ok": ok,
        "clean": ok and not (row.get("hit_mismatches") or row.get("work_mismatches")),
        "by": "tracer" if message.startswith("no trace:") else "simulator",
        "message": message,
    }


def reason(c: dict[str, Any]) -> str:
    """What refused: the tracer, or the setting the simulator's message names and what it needs."""
    m = c["message"]
    if c["by"] == "tracer":
        return f"the tracer: {m.split('error: ', 1)[-1].split(' (')[0]}"
    if "config: '" in m:
        asks, rest = m.split("config: '", 1)[1].split("'", 1)
        needs = rest.split(" needs ", 1)[-1].split(", which")[0].split(":")[0]
        return f"{asks.split('=')[0]} needs {needs}"
    return m.split("error: ", 1)[-1][:100]


def summary(cells: list[dict[str, Any]]) -> dict[str, Any]:
    refused = [c for c in cells if not c["ok"]]

    def by(key: str) -> dict[str, int]:
        return dict(Counter(c[key] for c in refused).most_common())

    return {
        "combinations": len(cells),
        "run": len(cells) - len(refused),
        "refused": len(refused),
        "unclean": sum(1 for c in cells if c["ok"] and not c["clean"]),
        "refused_by_unit": by("unit"),
        "refused_by_level": by("level"),
        "refused_by_technique": by("technique"),
        "refused_by_reason": dict(Counter(reason(c) for c in refused).most_common()),
    }


def before(folder: str) -> dict[str, Any] | None:
    """The summary of an earlier run of this study (its study.csv), or None without one."""
    if not folder:
        return None
    path = Path(folder) / "study.csv"
    if not path.is_file():
        raise StudyError(f"study composition: before={folder}: no study.csv (run the study there)")
    import pandas as pd

    frame = pd.read_csv(path).astype(object)
    rows = frame.where(frame.notna(), None).to_dict("records")
    return summary(ordered([cell(r) for r in rows]))


def ordered(cells: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Unit, structure, technique, level: the product's order (ties in the counts keep it)."""
    order = [list(UNITS), STRUCTURES, list(TECHNIQUES), list(LEVELS)]
    keys = ("unit", "structure", "technique", "level")
    return sorted(cells, key=lambda c: [o.index(c[k]) for o, k in zip(order, keys, strict=True)])


def table(run: StudyRun) -> str:
    after = summary(ordered([cell(r) for r in run.rows()]))
    old = before(run.options["before"])
    cols = [("after", after)] + ([("before", old)] if old else [])
    # Refused runs have no provenance: the git of the runs that ran.
    git = ", ".join(g for g in run.measured()["git"].split(", ") if g != "None")
    lines = [
        f"Measured with `{run.command}` ({after['combinations']:,} combinations: {len(UNITS)} unit "
        f"kinds x {len(STRUCTURES)} structures x {len(TECHNIQUES)} techniques x {len(LEVELS)} "
        "levels, each one `rtsim-sim` run on an "
        f"{run.options['resolution']} trace; after: rtsim-sim git {git}"
        + (f", before: the runs in `{run.options['before']}`" if old else "")
        + ").",
        "",
        "| | " + " | ".join(c for c, _ in cols) + " |",
        "|---|" + "---:|" * len(cols),
        "| combinations run | " + " | ".join(f"{s['run']:,}" for _, s in cols) + " |",
        "| refused | " + " | ".join(f"{s['refused']:,}" for _, s in cols) + " |",
        "| run with a hit or work mismatch | "
        + " | ".join(f"{s['unclean']:,}" for _, s in cols)
        + " |",
    ]
    for title, key in (
        ("unit kind", "refused_by_unit"),
        ("level", "refused_by_level"),
        ("technique", "refused_by_technique"),
    ):
        for n in dict.fromkeys(n for _, s in cols for n in s[key]):
            counts = " | ".join(f"{s[key].get(n, 0):,}" for _, s in cols)
            lines.append(f"| refused, {title} {n} | {counts} |")
    lines += [
        "",
        "What refuses the remaining combinations (after), by the setting the refusal "
        "names and what it needs:",
        "",
        "| refused by | combinations |",
        "|---|---:|",
    ]
    lines += [f"| {k} | {v:,} |" for k, v in after["refused_by_reason"].items()]
    return "\n".join(lines) + "\n"


STUDY = Study(
    name="composition",
    about="how much composes: every unit kind x structure x technique x level, run or refused",
    specs=specs,
    tables=[Table("capabilities.md", "composition-counts", table)],
    options={"resolution": "8x6", "before": "", "timeout": 300},
    # The product is the point of the study; quick keeps it (the runs are tiny).
    quick={},
    allow_failed=True,
)
