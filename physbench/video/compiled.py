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
folder where that is read-only), so only the first call after installing compiles; where neither
is writable, a :class:`CompiledCacheWarning` says so and each process compiles its own.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from physbench.errors import PhysbenchError, PhysbenchWarning


class CompiledError(PhysbenchError, ImportError):
    """numba is not installed, so the tracker's compiled loops cannot run."""


class CompiledCacheWarning(PhysbenchWarning):
    """numba has no writable folder to cache the compiled loops in: each process compiles them."""


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
        _ALL.append(self)

    def machine(self) -> Callable[..., Any]:
        """The numba dispatcher (compiled on its first call). The module's name for the function
        is pointed at it, and so are the names of the compiled functions it calls: numba calls
        a compiled function from compiled code only through its dispatcher."""
        if self._machine is None:
            numba = load_numba()
            try:
                self._machine = numba.njit(cache=True, nogil=True, boundscheck=False)(self.fn)
            except RuntimeError as exc:  # numba found no writable folder for its cache
                _uncached(exc)
                self._machine = numba.njit(nogil=True, boundscheck=False)(self.fn)
            names = self.fn.__globals__
            names[self.__name__] = self._machine  # a recursive call finds it too
            for name in self.fn.__code__.co_names:
                other = names.get(name)
                if isinstance(other, _Compiled):
                    names[name] = other.machine()
        return self._machine

    def __call__(self, *args: Any) -> Any:
        return (self._machine or self.machine())(*args)


#: Every function made with :func:`jit` in the modules imported so far.
_ALL: list[_Compiled] = []

_warned: list[bool] = []


def _uncached(exc: RuntimeError) -> None:
    """Called where numba cannot cache a function's machine code (neither the folder beside
    the module nor the user's cache folder is writable): says so once a process, and how to
    give it a folder; the loops are compiled for this process alone."""
    if not _warned:
        _warned.append(True)
        warnings.warn(
            f"the tracker's compiled loops cannot be kept on disk ({exc}): each process "
            "compiles them again, about a minute; set NUMBA_CACHE_DIR to a writable folder",
            CompiledCacheWarning,
            stacklevel=4,
        )


def cached() -> bool:
    """Whether the machine code of every compiled function imported so far is in numba's disk
    cache (``True`` where that cannot be told). Where it is not, the first call compiles: the
    tracker's loops take about a minute on a slow machine, once after installing."""
    try:
        return all(os.path.exists(f.machine()._cache._cache_file._index_path) for f in _ALL)
    except AttributeError:  # numba's cache is not a public API
        return True


def jit(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` compiled in nopython mode on its first call, its machine code cached on disk. It
    may call other functions of its module made with :func:`jit`, and itself."""
    return _Compiled(fn)


@jit
def pairwise_sum(a: Any, start: int, n: int) -> Any:
    """The sum of ``a[start : start + n]`` as NumPy's ``sum`` adds it, to the bit: pairwise, 8
    running sums over blocks of up to 128 values, halves (cut at a multiple of 8) above. For
    compiled loops whose sums feed the decisions the NumPy expressions they replace fed. The
    halving runs on a stack of its own: numba's cache cannot load a compiled caller of a
    recursive function."""
    if n <= 128:
        return _block_sum(a, start, n)
    # Post-order over the halving tree: each entry a range and how far it has got (0: neither
    # half summed, 1: the first, 2: both), its halves' sums on a stack of values.
    ranges = np.empty((3, 64), np.int64)  # lo, size, state
    lo, size, state = ranges[0], ranges[1], ranges[2]
    values = np.empty(64, a.dtype)
    lo[0], size[0], state[0] = start, n, 0
    depth, held = 1, 0
    while depth:
        top = depth - 1
        if size[top] <= 128:
            values[held] = _block_sum(a, lo[top], size[top])
            held += 1
            depth -= 1
            continue
        half = size[top] // 2
        half -= half % 8
        if state[top] < 2:
            first = state[top] == 0
            lo[depth] = lo[top] if first else lo[top] + half
            size[depth] = half if first else size[top] - half
            state[depth] = 0
            state[top] += 1
            depth += 1
        else:
            held -= 1
            values[held - 1] = values[held - 1] + values[held]
            depth -= 1
    return values[0]


@jit
def _block_sum(a: Any, start: int, n: int) -> Any:
    """:func:`pairwise_sum` of at most 128 values."""
    if n < 8:
        total = np.zeros(1, a.dtype)[0]  # float32 values add up in float32, as in NumPy
        for i in range(start, start + n):
            total += a[i]
        return total
    # Eight running sums, each its own scalar (a slice copied into an array made the loops
    # that call this compile for seconds longer).
    r0, r1, r2, r3 = a[start], a[start + 1], a[start + 2], a[start + 3]
    r4, r5, r6, r7 = a[start + 4], a[start + 5], a[start + 6], a[start + 7]
    i = 8
    while i < n - n % 8:
        j = start + i
        r0, r1, r2, r3 = r0 + a[j], r1 + a[j + 1], r2 + a[j + 2], r3 + a[j + 3]
        r4, r5, r6, r7 = r4 + a[j + 4], r5 + a[j + 5], r6 + a[j + 6], r7 + a[j + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for k in range(start + i, start + n):
        total += a[k]
    return total


@jit
def solve(m: Any, rhs: Any) -> bool:
    """Solves the small system ``m x = rhs`` in place, ``x`` in ``rhs`` and ``m`` its LU
    factors, as OpenBLAS's LAPACK ``dgesv`` solves it for ``np.linalg.solve``: ``dgetf2``'s
    left-looking LU with partial pivoting (each entry less one dot product, the multipliers
    scaled by the pivot's reciprocal, no fused products), then ``dgetrs``. ``False`` (``rhs``
    part way) at an exactly zero pivot, where LAPACK calls ``m`` singular and NumPy raises. Of
    100 systems from shaken walls, textbook elimination matched ``np.linalg.solve`` to the bit
    in 3; this in all."""
    n = len(rhs)
    for j in range(n):
        for i in range(1, n):  # less the products of the rows above: U above, L below
            dot = 0.0
            for t in range(min(i, j)):
                dot += m[i, t] * m[t, j]
            m[i, j] -= dot
        p = j
        for i in range(j + 1, n):
            if abs(m[i, j]) > abs(m[p, j]):
                p = i
        if m[p, j] == 0.0:
            return False
        for t in range(n):
            m[j, t], m[p, t] = m[p, t], m[j, t]
        rhs[j], rhs[p] = rhs[p], rhs[j]
        scale = 1.0 / m[j, j]
        for i in range(j + 1, n):
            m[i, j] *= scale
    for j in range(n):
        for i in range(j + 1, n):
            rhs[i] += -rhs[j] * m[i, j]
    for j in range(n - 1, -1, -1):
        rhs[j] /= m[j, j]
        for i in range(j):
            rhs[i] += -rhs[j] * m[i, j]
    return True
