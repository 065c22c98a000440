"""``python -m physbench``: the same as the ``physbench`` command."""

from physbench.cli import main

raise SystemExit(main())
