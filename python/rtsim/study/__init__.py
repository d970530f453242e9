"""Studies: a sweep spec plus an analysis of its table (docs/studies.md).

A `Study` names the runs it needs as sweep specs (dicts of the YAML's shape, built from its
options: `quick` for a small first look), runs them through the sweep engine into one store (so
re-running reuses every finished run), and renders tables and figures as functions of the
study's DataFrame: one row per planned point of its specs, the sweep's tidy columns plus the
study's extra columns from stats.json. Each table lands between the doc markers it owns
(rtsim/doc_markers.py).

    rtsim study --list
    rtsim study NAME [--quick] [--option KEY=VALUE ...] [-o OUT] [--write-docs]

The project's studies are modules of `rtsim.studies`, each with a `STUDY`; a file of your own
with a `STUDY` runs the same way (`rtsim study my_study.py`).
"""

from rtsim.study.core import Figure, Study, StudyRun, Table, run_study

__all__ = ["Figure", "Study", "StudyRun", "Table", "run_study"]
