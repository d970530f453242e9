"""More structures against the BVH's builders (docs/accel.md, the `structures-study` section):
the binary BVH from its sweep, local-ray-termination (lrt), median and SBVH builders, the GK-BVH
(Popov et al. 2009) with its boxes-only variant, BIH and the B-Kd tree, on primary and shadow
rays (a sun added to the scenes without lights), by the method of the `partition` study (its
tables, no mailbox runs)."""

from __future__ import annotations

from rtsim.studies import partition
from rtsim.study import Study, Table

#: The documented run's structures.
ACCELS = [
    "bvh2", "bvh2:sweep", "bvh2:lrt", "bvh2:median", "bvh2:sbvh",
    "gkbvh", "gkbvh:boxes", "bih", "bkd",
]  # fmt: skip

STUDY = Study(
    name="structures",
    about="GK-BVH, B-Kd tree, BIH and the BVH's builders on primary and shadow rays",
    specs=partition.specs,
    tables=[Table("accel.md", "structures-study", partition.tables)],
    # The documented run (docs/accel.md).
    options={
        **partition.OPTIONS,
        "scenes": ["sponza", "hairball"],
        "accels": ACCELS,
        "workloads": ["primary", "shadow"],
        "resolution": "32x24",
        "repeats": 1,
        "mailbox": 0,
        "lights": "sun",
    },
    quick={"scenes": ["cornell"], "accels": ["bvh2", "gkbvh", "bkd"], "resolution": "16x12"},
    extra=partition.STUDY.extra,
    allow_failed=True,  # a run over sim_timeout is a row without model figures
)
