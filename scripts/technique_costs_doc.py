#!/usr/bin/env python3
"""Writes docs/energy_area.md's table of what each technique adds (between the
`<!-- technique-costs:begin -->` markers): one small trace per structure, simulated at the
default config with each technique switched on in turn, and each technique block's area and
energy per ray read from stats.json (`area.mm2`, `energy.per_ray_nj`).

    python scripts/technique_costs_doc.py [--sim PATH] [--resolution 64x48]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from rtsim.doc_markers import write_between

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "energy_area.md"

#: (label, structure, compressed leaves, --set assignments, the technique blocks to read).
CASES = [
    ("MIMD, bvh2 (the default)", "bvh2", False, [], ["context_scheduler"]),
    ("cwbvh8 + compressed leaves", "cwbvh8", True, [], ["node_decoder", "leaf_decoder"]),
    ("SIMT, 8 lanes", "bvh2", False, ["traversal.model=simt"], ["simt_control"]),
    ("packets, 8 lanes", "bvh2", False, ["traversal.model=packet"], ["packet_control"]),
    ("Morton sort stage", "bvh2", False, ["dispatch.sort=morton"], ["sort_stage"]),
    ("treelet prefetching", "bvh2", False, ["treelets.prefetch=true"], ["prefetcher"]),
    ("grid with mailboxes, 8 entries", "grid", False, ["mailbox.entries=8"], ["mailbox_compare"]),
    (
        "stack-driven prefetching (TTP)",
        "bvh2",
        False,
        ["traversal.stack_prefetch=2"],
        ["stack_prefetcher"],
    ),
    (
        "SIMT 8 lanes, warp refill, cooperative lanes (CoopRT)",
        "bvh2",
        False,
        ["traversal.model=simt", "traversal.simt.refill=warp", "traversal.simt.cooperative=true"],
        ["cooperation"],
    ),
    (
        "cwbvh8, quantised box tests (AQB8)",
        "cwbvh8",
        False,
        ["traversal.quantized_boxes=true"],
        ["box", "ray_requantizer"],
    ),
]


def trace(root: Path, kind: str, compressed: bool, resolution: str) -> Path:
    out = root / f"{kind}-{int(compressed)}"
    if not out.exists():
        cmd = [sys.executable, "-m", "rtsim", "trace", "sponza", "-o", str(out), "--accel", kind,
               "--workload", "diffuse", "--resolution", resolution, "--bounces", "1"]  # fmt: skip
        if compressed:
            cmd += ["--build-set", "compressed_leaves=true"]
        subprocess.run(cmd, check=True, capture_output=True)
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--sim", default="rtsim-sim")
    p.add_argument("--resolution", default="64x48")
    a = p.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        for label, kind, compressed, sets, blocks in CASES:
            run = root / f"run-{len(rows)}"
            cmd = [a.sim, str(trace(root, kind, compressed, a.resolution)), "-o", str(run),
                   "--no-verdict"]  # fmt: skip
            for s in sets:
                cmd += ["--set", s]
            subprocess.run(cmd, check=True, capture_output=True)
            stats = json.loads((run / "stats.json").read_text())
            total = stats["area"]["total_mm2"]
            nj = stats["energy"]["per_ray_nj"]
            for b in blocks:
                mm2 = stats["area"]["mm2"].get(b, 0.0)
                rows.append(
                    f"| {label} | `{b}` | {mm2:.4f} | {100 * mm2 / total:.1f}% | "
                    f"{nj.get(b) or 0.0:.4f} | {100 * (nj.get(b) or 0.0) / nj['total']:.2f}% |"
                )
    sha = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short=12", "HEAD"],
                         capture_output=True, text=True).stdout.strip()  # fmt: skip
    text = "\n".join(
        [
            f"Measured with `python scripts/technique_costs_doc.py` (Sponza diffuse at "
            f"{a.resolution}, default config otherwise: 8 units x 16 contexts, 7 nm; git {sha}).",
            "",
            "| design | block | mm^2 | of the chip | nJ/ray | of the energy |",
            "|---|---|---:|---:|---:|---:|",
            *rows,
        ]
    )
    write_between(DOC, "technique-costs", text)


if __name__ == "__main__":
    main()
