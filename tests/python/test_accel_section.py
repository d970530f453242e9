"""The report's structures table: per-ray work over the rays the model simulated."""

from __future__ import annotations

from typing import Any

from rtsim.report.accel_section import AccelRow


def row(by_kind: dict[str, Any]) -> AccelRow:
    return AccelRow("bvh2", None, {"counts": {"by_kind": by_kind}})  # type: ignore[arg-type]


def test_work_per_ray_leaves_out_rays_traced_only_to_find_bounces() -> None:
    # A diffuse workload traces its primary rays to find the bounces but writes only the
    # diffuse ones: the table must show the diffuse rays' work, not a mix.
    r = row(
        {
            "primary": {"traced": 1000, "written": 0, "steps_per_ray": 3.0},
            "diffuse": {"traced": 400, "written": 400, "steps_per_ray": 10.0},
        }
    )
    assert r.work_per_ray("steps") == 10.0


def test_work_per_ray_weights_written_kinds_by_their_rays() -> None:
    r = row(
        {
            "primary": {"traced": 300, "written": 300, "steps_per_ray": 2.0},
            "shadow": {"traced": 100, "written": 100, "steps_per_ray": 6.0},
        }
    )
    assert r.work_per_ray("steps") == 3.0
    assert row({}).work_per_ray("steps") is None
