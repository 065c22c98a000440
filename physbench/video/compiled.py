"""Loops compiled to machine code with numba, for the tracker's per-frame work on a few thousand
values at a time (a disc's rays, a blob's pixels, a frame's samples).

Written as NumPy calls, such work is dozens of calls on arrays of a few hundred values each; what
costs is each call's dispatch (microseconds), not its arithmetic, and the tracker makes thousands
of them a frame. A loop compiled once does the same arithmetic in one call. Each loop reproduces
the NumPy expressions it replaces operation for operation, in the same floating-point types, so
its results are the same to the bit unless its docstring says otherwise.

:func:`jit` compiles a function on its first call, not on import: ``import physbench.video.track``
does not load numba (half a second), and a command that tracks nothing never pays for it. The
machine code is cached on disk (numba's ``cache=True``: beside the module, or in the user's cache
folder where that is read-only), so only the first call after installing compiles.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from physbench.errors import PhysbenchError


class CompiledError(PhysbenchError, ImportError):
    """numba is not installed, so the tracker's compiled loops cannot run."""


def load_numba() -> Any:
    """The ``numba`` module; :class:`CompiledError` naming the extra to install when missing."""
    try:
        import numba
    except ImportError:
        raise CompiledError(
            "tracking needs numba for its compiled loops: pip install 'physbench[video]' (or pip "
            "install numba)"
        ) from None
    return numba


class _Compiled:
    """A function compiled by numba on its first call (see the module docstring)."""

    def __init__(self, fn: Callable[..., Any]) -> None:
        self.fn = fn
        self.__doc__, self.__name__ = fn.__doc__, fn.__name__
        self._machine: Callable[..., Any] | None = None

    def __call__(self, *args: Any) -> Any:
        if self._machine is None:
            numba = load_numba()
            self._machine = numba.njit(cache=True, nogil=True, boundscheck=False)(self.fn)
        return self._machine(*args)


def jit(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` compiled in nopython mode on its first call, its machine code cached on disk. The
    function may call no other compiled function (each is compiled on its own)."""
    return _Compiled(fn)
