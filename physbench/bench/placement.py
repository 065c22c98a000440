"""Which worker runs which cell: the items an executor has yet to hand out, grouped by what
their first run in a process costs (``affinity``: a cell's estimator and engines, whose
libraries take up to 2 s of CPU to import), and what the executor has learned of each group's
costs while the sweep runs.

A worker keeps to the groups it has run. When none of its own is left it starts a group nobody
has started, or else joins a started one, paying that group's imports, only while that pays: its
first item of the group (imports included) would end before the workers already on the group
could finish what is left. Otherwise it waits; the group's own workers finish it sooner. Joining
every time (the rule before this one) made 16 workers on smoke48 import the slowest estimator's
libraries (nevergrad's, 1.9 s of CPU) to help with its last few cells.

Times are the items' own, measured in the workers (:func:`timed_call`); an estimate a group does
not have yet (no item of it finished) counts as "join".
"""

from __future__ import annotations

import statistics
import time
from collections import deque
from collections.abc import Callable, Hashable, Sequence
from typing import Generic, TypeVar

T = TypeVar("T")
R = TypeVar("R")
#: "No such group" (a group's key may be ``None``: that of every item without ``affinity``).
_NONE = object()


def timed_call(fn: Callable[[T], R], item: T) -> tuple[float, R]:
    """``fn(item)`` and the seconds it took; run in the worker, so that the time is the item's
    own, not its wait in a queue."""
    t0 = time.perf_counter()
    result = fn(item)
    return time.perf_counter() - t0, result


class Pending(Generic[T]):
    """The items an executor has yet to hand out (see the module's docstring), each group in the
    callers' order; asked by the executor each time a worker has room for another item, and told
    how long each item took."""

    def __init__(self, items: Sequence[T], affinity: Callable[[T], Hashable] | None) -> None:
        self._affinity = affinity
        self._groups: dict[Hashable, deque[T]] = {}
        for item in items:
            self._groups.setdefault(self._key(item), deque()).append(item)
        self._started: set[Hashable] = set()
        self._ran: dict[Hashable, set[Hashable]] = {}  # worker -> groups it has taken items of
        self._timed: set[tuple[Hashable, Hashable]] = set()  # (worker, group) with a finished item
        self._firsts: dict[Hashable, list[float]] = {}  # group -> a worker's first item's seconds
        self._others: dict[Hashable, list[float]] = {}  # group -> its other items' seconds

    def _key(self, item: T) -> Hashable:
        return self._affinity(item) if self._affinity is not None else None

    def __len__(self) -> int:
        return sum(len(q) for q in self._groups.values())

    def take(self, worker: Hashable, *, force: bool = False) -> T | None:
        """The next item for ``worker``: one of its own groups' if any is left; else one of a
        group no worker has started, in the callers' order; else one of the started group it
        helps most, if joining pays (``force``: even if not; for when no item is in flight).
        ``None`` when it had better wait."""
        ran = self._ran.setdefault(worker, set())
        key = next((k for k in self._groups if k in ran), _NONE)
        if key is _NONE:
            key = next((k for k in self._groups if k not in self._started), _NONE)
        if key is _NONE:
            key = self._join(force)
        if key is _NONE:
            return None
        ran.add(key)
        self._started.add(key)
        item = self._groups[key].popleft()
        if not self._groups[key]:
            del self._groups[key]
        return item

    def _join(self, force: bool) -> Hashable:
        """The started group whose workers have the most left to do, if a newcomer's first item
        would end before they finish it (or ``force``); else :data:`_NONE`."""
        best: Hashable = _NONE
        most = -1.0
        for key, queue in self._groups.items():
            on = sum(key in ran for ran in self._ran.values())
            typical, extra = self.estimates(key)
            left = len(queue) * (typical if typical is not None else 1.0) / max(on, 1)
            pays = on == 0 or typical is None or extra is None or extra + typical < left
            if (pays or force) and left > most:
                best, most = key, left
        return best

    def estimates(self, key: Hashable) -> tuple[float | None, float | None]:
        """Group ``key``'s median item seconds and the median extra seconds of a worker's first
        item of it, once items of it have finished (``None`` before)."""
        others, firsts = self._others.get(key), self._firsts.get(key)
        typical = statistics.median(others) if others else None
        if typical is None or not firsts:
            return typical, None
        return typical, max(0.0, statistics.median(firsts) - typical)

    def done(self, worker: Hashable, item: T, seconds: float) -> None:
        """``worker`` finished ``item`` in ``seconds`` (its own time, :func:`timed_call`)."""
        key = self._key(item)
        if (worker, key) in self._timed:
            self._others.setdefault(key, []).append(seconds)
        else:
            self._timed.add((worker, key))
            self._firsts.setdefault(key, []).append(seconds)

    def forget(self, worker: Hashable) -> None:
        """``worker`` is gone (its pool broke, it left the cluster): it no longer counts as one
        of its groups' workers."""
        self._ran.pop(worker, None)
        self._timed = {(w, k) for w, k in self._timed if w != worker}

    def put_back(self, item: T) -> None:
        """Return ``item`` to the front of its group: the worker it was taken for was gone."""
        self._groups.setdefault(self._key(item), deque()).appendleft(item)
