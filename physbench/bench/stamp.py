"""What produced a cell, so that a resumed sweep does not mix results of different code.

A cell's key hashes its settings (:class:`~physbench.experiment.RunConfig`); its *stamp* records
what those settings meant when it ran: a hash of the scene as generated for its seed (the
canonical scene TOML), the physbench version, and the estimator's resolved options (defaults
included, so a changed default shows). On resume the runner compares the stored stamp of every
finished cell it would keep with the stamp the cell would get now and refuses to mix them
(:class:`StaleCellsError`) unless told to (``--allow-stale``). Cells written before stamps existed
count as stale.

Stamps are computed once per scene x seed and once per estimator configuration, so checking a
2,000-cell sweep costs a few hundred scene generations, not 2,000 runs.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from physbench.errors import PhysbenchError, counted

if TYPE_CHECKING:
    from physbench.bench.spec import Cell
    from physbench.experiment import RunConfig

#: The stamp fields, in the order a stale report lists their changes.
FIELDS = ("scene", "estimator", "physbench")


class StaleCellsError(PhysbenchError):
    """Finished cells of an output folder were produced by other code or settings."""


def _canonical(obj: Any) -> Any:
    """``obj`` as it reads back from a cell file (tuples become lists, odd values their repr)."""
    return json.loads(json.dumps(obj, sort_keys=True, default=repr))


def physbench_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("physbench")
    except PackageNotFoundError:  # run from a source tree that is not installed
        return "unknown"


class Stamper:
    """Stamps for the cells of one sweep invocation. Caches per scene x seed and per estimator
    configuration; make a new one per invocation, so that changed code is seen."""

    def __init__(self) -> None:
        self._version = physbench_version()
        self._scenes: dict[tuple[str, int], str] = {}
        self._estimators: dict[tuple[str, str], Any] = {}

    def scene(self, name_or_path: str, seed: int) -> str:
        """The hash of the scene TOML text of ``name_or_path`` generated for ``seed`` (or of the
        error that generating it raises: the cell records that error too)."""
        key = (name_or_path, seed)
        if key not in self._scenes:
            from physbench.scene_toml import dumps_scene
            from physbench.scenes import resolve_scene

            try:
                text = dumps_scene(resolve_scene(name_or_path, seed))
            except Exception as exc:  # the cell will fail the same way; its stamp says so
                text = f"error: {type(exc).__name__}: {exc}"
            self._scenes[key] = hashlib.sha256(text.encode()).hexdigest()[:16]
        return self._scenes[key]

    def estimator(self, name: str, options: Mapping[str, Any]) -> Any:
        """The options estimator ``name`` resolves ``options`` to (its ``options`` attribute,
        defaults included)."""
        key = (name, json.dumps(dict(options), sort_keys=True, default=repr))
        if key not in self._estimators:
            from physbench.components import make_estimator

            try:
                resolved: Any = _canonical(dict(make_estimator(name, options).options))
            except Exception as exc:  # the cell will fail the same way
                resolved = f"error: {type(exc).__name__}: {exc}"
            self._estimators[key] = resolved
        return self._estimators[key]

    def stamp(self, config: RunConfig) -> dict[str, Any]:
        """The stamp a cell of ``config`` gets now (JSON-ready)."""
        return {
            "scene": self.scene(config.scene, config.seed),
            "estimator": self.estimator(config.estimator, config.options),
            "physbench": self._version,
        }


@dataclass(frozen=True)
class Stale:
    """A finished cell whose stored stamp (``None``: written before stamps) differs from now."""

    cell: Cell
    stored: Mapping[str, Any] | None
    current: Mapping[str, Any]

    @property
    def changed(self) -> tuple[str, ...]:
        if self.stored is None:
            return ()
        return tuple(f for f in FIELDS if self.stored.get(f) != self.current.get(f))


def find_stale(
    cells: Iterable[Cell], stored: Mapping[str, Mapping[str, Any]], stamps: Mapping[str, Any]
) -> list[Stale]:
    """The ``cells`` whose stored data (by key) carries a stamp other than ``stamps[key]``."""
    out = []
    for c in cells:
        old = stored[c.key].get("stamp")
        if old != stamps[c.key]:
            out.append(Stale(c, old, stamps[c.key]))
    return out


def _seed_ranges(seeds: Iterable[int]) -> str:
    """``[0, 1, 2, 5, 7, 8]`` -> ``"0-2, 5, 7-8"``."""
    parts: list[str] = []
    run: list[int] = []
    for s in sorted(set(seeds)):
        if run and s == run[-1] + 1:
            run.append(s)
            continue
        if run:
            parts.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
        run = [s]
    if run:
        parts.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
    return ", ".join(parts)


def _option_changes(old: Any, new: Any) -> str:
    if not isinstance(old, dict) or not isinstance(new, dict):
        return f"{json.dumps(old)} -> {json.dumps(new)}"
    bits = []
    for k in sorted({*old, *new}):
        if k not in old:
            bits.append(f"{k} new ({json.dumps(new[k])})")
        elif k not in new:
            bits.append(f"{k} gone (was {json.dumps(old[k])})")
        elif old[k] != new[k]:
            bits.append(f"{k} {json.dumps(old[k])} -> {json.dumps(new[k])}")
    return ", ".join(bits)


def describe(stale: Sequence[Stale], finished: int, where: str) -> str:
    """One message: how many cells, what changed for which scenes and estimators, and the way
    out (``--allow-stale`` or ``--fresh``)."""
    lines = [
        f"{where}: {len(stale)} of {finished} finished cells were produced by other code or "
        "settings than this run would use:"
    ]
    unstamped = [s for s in stale if s.stored is None]
    if unstamped:
        lines.append(
            f"  - {counted(len(unstamped), 'cell')} without a stamp (written before physbench "
            "recorded what produced a cell)"
        )
    stamped = [s for s in stale if s.stored is not None]
    scenes: dict[str, list[int]] = {}
    for s in stamped:
        if "scene" in s.changed:
            scenes.setdefault(s.cell.scene, []).append(s.cell.config.seed)
    for scene, seeds in scenes.items():
        lines.append(
            f"  - scene {scene}, seeds {_seed_ranges(seeds)}: the generated scene differs "
            "(its generator or scene file changed)"
        )
    estimators: dict[str, tuple[Any, Any]] = {}
    versions: set[tuple[str, str]] = set()
    for s in stamped:
        was = s.stored or {}
        if "estimator" in s.changed:
            estimators.setdefault(s.cell.label, (was["estimator"], s.current["estimator"]))
        if "physbench" in s.changed:
            versions.add((str(was["physbench"]), str(s.current["physbench"])))
    for label, (old, new) in estimators.items():
        lines.append(f"  - estimator {label}: resolved options {_option_changes(old, new)}")
    for old_v, new_v in sorted(versions):
        lines.append(f"  - physbench {old_v} -> {new_v}")
    lines.append(
        "Resuming would mix their results with new ones. Rerun with --allow-stale to keep them "
        "and resume anyway, or with --fresh to start over."
    )
    return "\n".join(lines)
