"""``python -m physbench``: the same as the ``physbench`` command."""

import sys

try:
    from physbench.cli import main
except KeyboardInterrupt:  # Ctrl-C while the command is still being imported
    print("physbench: interrupted", file=sys.stderr)
    raise SystemExit(130) from None

raise SystemExit(main())
