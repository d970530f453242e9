"""Design-space sweeps: a YAML spec (spec.py), traces made once per scene and workload, one
rtsim-sim process per run scheduled on Dask (runner.py, tasks.py), and a SQLite results store
that a killed sweep resumes from (store.py). See docs/sweeps.md."""
