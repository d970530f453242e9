"""``python -m rtsim`` is the ``rtsim`` command."""

from rtsim.cli import main

raise SystemExit(main())
