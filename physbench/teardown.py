"""Ending a process without the interpreter's teardown.

After a command's work is done, Python still frees every module it imported (pandas, pyarrow,
scipy, the estimators' libraries) one object at a time: 0.2-0.3 s for a ``physbench bench``
process and for each of its workers (``benchmarks/sweep_scaling.py`` measures it), time in which
nothing is left to do. :func:`skip_at_exit` ends the process right after the ``atexit`` handlers
instead, so what those handlers do (logging's flush, multiprocessing joining its children,
temporary folders' finalizers) still happens; only the freeing is skipped, which the operating
system does at once.

Only processes physbench owns from start to end use it: the ``physbench`` script, the
``processes`` executor's workers and the workers of the Dask LocalCluster it starts, never an
interpreter that imported physbench as a library, nor the workers of a cluster at ``--address``.
"""

from __future__ import annotations

import atexit
import os
import sys
from collections.abc import Callable


def skip_at_exit(status: Callable[[], int]) -> None:
    """Make this process end with ``status()`` once the ``atexit`` handlers registered after this
    call have run, without the module teardown that would follow; called by the process's owner
    as early as it can, since handlers registered before it are skipped too."""

    def end() -> None:
        for stream in (sys.stdout, sys.stderr):
            try:
                if stream is not None:
                    stream.flush()
            except (OSError, ValueError):  # a reader that left, a closed stream
                pass
        if "logging" in sys.modules:  # its handler is skipped if logging came first
            sys.modules["logging"].shutdown()
        os._exit(status())

    atexit.register(end)
