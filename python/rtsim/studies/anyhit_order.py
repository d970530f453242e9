"""The any-hit child order (docs/accel.md, "Any-hit child order"): the work per shadow ray of
each `traversal.anyhit_order` against the closest-hit order the trace walks.

Each scene's camera and shadow rays (a scene without lights gets a sun: `lights: sun`) through
each structure (the binary BVH and the wide ones by default), replayed at `fidelity` (approx by
default; the functional and timed levels step every ray, check a reordered one's occlusion
against the trace and count and time its own walk) with `nearest`, `largest_box` and `fixed`;
`validation.reordered_anyhit` gives per shadow ray the steps, box and triangle tests in the run's
order and in the trace's (nearest first, the default), and the timed runs their speed. Each
runs on every unit kind of `models`: MIMD units walk each ray alone, packet units (16 rays)
walk a shadow packet in the order at every node where only any-hit rays are active. Table
between the `anyhit-order` markers of docs/accel.md."""

from __future__ import annotations

from typing import Any

from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import change, markdown, mismatches, scene

ORDERS = ("largest_box", "fixed")
#: Scenes that bring no light of their own: a sun gives them shadow rays.
LIGHTLESS = ("sponza", "hairball", "teapot_stadium", "bunny")


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    scenes = [
        scene(s, o["hairball_triangles"], **({"lights": "sun"} if s in LIGHTLESS else {}))
        for s in o["scenes"]
    ]
    workload = {"name": "shadow", "rays": ["primary", "shadow"], "resolution": o["resolution"]}
    return [
        {
            "name": "anyhit-order",
            "scenes": scenes,
            "workloads": [workload],
            "accel": list(o["accels"]),
            "config": {"set": {"fidelity": o["fidelity"]}},
            "grid": {
                "traversal.model": list(o["models"]),
                "traversal.anyhit_order": ["nearest", *ORDERS],
            },
        }
    ]


def _row(run: StudyRun, s: str, accel: str, model: str, order: str) -> dict[str, Any]:
    keys = {"traversal.model": model, "traversal.anyhit_order": order}
    return run.row(scene=s, accel=accel, **keys)


def table(run: StudyRun) -> str:
    rows, o = [], run.options
    timed = o["fidelity"] in ("approx", "detailed")
    cases = ((s, a, m) for s in o["scenes"] for a in o["accels"] for m in o["models"])
    for s, accel, model in cases:
        nearest = _row(run, s, accel, model, "nearest")
        base = None
        for order in ORDERS:
            row = _row(run, s, accel, model, order)
            v = run.stats(row)["validation"]
            r = v["reordered_anyhit"]
            if base is None:
                base = r["trace_order"]
                rows.append([f"`{s}`", f"`{accel}`", model, "nearest (the trace's)",
                             f"{r['rays']:,}",
                             *(f"{base[k]:.2f}" for k in ("steps", "box_tests", "tri_tests")),
                             "", *([""] if timed else []),
                             str(mismatches([nearest]))])  # fmt: skip
            own = r["own"]
            ratio = row["mrays_per_second"] / nearest["mrays_per_second"] if timed else 0.0
            speed = [f"{ratio:.3f}x"] if timed else []
            rows.append(["", "", "", order, f"{r['rays']:,}",
                         *(f"{own[k]:.2f}" for k in ("steps", "box_tests", "tri_tests")),
                         change(own["steps"], base["steps"]) if base["steps"] else "n/a",
                         *speed, str(v["hit_mismatches"] + v["work_mismatches"])])  # fmt: skip
    header = ["scene", "structure", "unit", "any-hit order", "shadow rays", "steps/ray",
              "box tests/ray", "tri tests/ray", "steps vs nearest",
              *(["speed vs nearest"] if timed else []), "mismatches"]  # fmt: skip
    m = run.measured()
    note = (
        f"Measured by `{run.command}` on {m['host']} ({m['date']}): `rtsim trace SCENE --workload "
        f"primary,shadow --resolution {o['resolution']} --accel ACCEL` (binned SAH; a sun added "
        f"to a scene without lights), then `rtsim-sim --set fidelity={o['fidelity']} --set "
        "traversal.model=UNIT --set traversal.anyhit_order=ORDER` at the default config "
        "(packet: 16 rays); work per shadow ray, from `validation.reordered_anyhit`; the trace's "
        "row and `steps vs nearest` are each ray walking alone nearest first, for packets too"
        + (
            "; speed: the whole run's rays/s (camera and shadow rays) against the nearest-first "
            "run's"
            if timed
            else ""
        )
        + "; mismatches: hit and work (a reordered any-hit ray: its occlusion against the trace)."
    )
    return note + "\n\n" + markdown(header, "llllrrrrr" + "r" * (2 if timed else 1), rows) + "\n"


STUDY = Study(
    name="anyhit_order",
    about="the any-hit child order: work per shadow ray of largest_box and fixed against nearest",
    specs=specs,
    tables=[Table("accel.md", "anyhit-order", table)],
    options={
        "scenes": ["cornell", "hairball", "sponza"],
        "accels": ["bvh2", "bvh4", "bvh8", "cwbvh8"],
        "models": ["mimd", "packet"],
        "fidelity": "approx",
        "resolution": "64x48",
        "hairball_triangles": 200000,
    },
    quick={"scenes": ["cornell"], "accels": ["bvh2", "bvh8"], "resolution": "16x12"},
)
