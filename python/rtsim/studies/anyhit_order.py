"""The any-hit child order (docs/accel.md, "Any-hit child order"): the work per shadow ray of
each `traversal.anyhit_order` against the closest-hit order the trace walks.

Each scene's camera and shadow rays (a scene without lights gets a sun: `lights: sun`) through a
binary BVH, replayed at the functional level (the one level that runs another order: it checks
every reordered ray's occlusion against the trace and counts its own work) with `largest_box` and
`fixed`; `validation.reordered_anyhit` gives per shadow ray the steps, box and triangle tests in
the run's order and in the trace's (nearest first, the default). Table between the
`anyhit-order` markers of docs/accel.md."""

from __future__ import annotations

from typing import Any

from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import change, markdown, scene

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
            "config": {"set": {"fidelity": "functional"}},
            "grid": {"traversal.anyhit_order": list(ORDERS)},
        }
    ]


def table(run: StudyRun) -> str:
    rows = []
    for s in run.options["scenes"]:
        base = None
        for order in ORDERS:
            row = run.row(scene=s, **{"traversal.anyhit_order": order})
            v = run.stats(row)["validation"]
            r = v["reordered_anyhit"]
            if base is None:
                base = r["trace_order"]
                rows.append([f"`{s}`", "nearest (the trace's)", f"{r['rays']:,}",
                             *(f"{base[k]:.2f}" for k in ("steps", "box_tests", "tri_tests")),
                             "", str(v["hit_mismatches"])])  # fmt: skip
            own = r["own"]
            rows.append(["", order, f"{r['rays']:,}",
                         *(f"{own[k]:.2f}" for k in ("steps", "box_tests", "tri_tests")),
                         change(own["steps"], base["steps"]) if base["steps"] else "n/a",
                         str(v["hit_mismatches"])])  # fmt: skip
    header = ["scene", "any-hit order", "shadow rays", "steps/ray", "box tests/ray",
              "tri tests/ray", "steps vs nearest", "occlusion mismatches"]  # fmt: skip
    note = (
        f"Measured by `{run.command}`: `rtsim trace SCENE --workload primary,shadow "
        f"--resolution {run.options['resolution']}` (bvh2, binned SAH; a sun added to a scene "
        "without lights), then `rtsim-sim --set fidelity=functional --set "
        "traversal.anyhit_order=ORDER`; per shadow ray, from `validation.reordered_anyhit`."
    )
    return note + "\n\n" + markdown(header, "llrrrrrr", rows) + "\n"


STUDY = Study(
    name="anyhit_order",
    about="the any-hit child order: work per shadow ray of largest_box and fixed against nearest",
    specs=specs,
    tables=[Table("accel.md", "anyhit-order", table)],
    options={
        "scenes": ["cornell", "hairball", "sponza"],
        "resolution": "128x96",
        "hairball_triangles": 200000,
    },
    quick={"scenes": ["cornell"], "resolution": "16x12"},
)
