"""Cells know what produced them: a resume refuses finished cells made by another scene generator,
another estimator default, another physbench version, or before stamps existed, with one clear
message; ``--allow-stale`` keeps them, ``--fresh`` starts over."""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType
from typing import Any

import pandas as pd
import pytest

from physbench.bench import stamp as stamp_module
from physbench.bench.runner import run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.stamp import StaleCellsError, Stamper
from physbench.bench.tables import without_timings

TOY = {
    "name": "toy",
    "estimators": ["toy", "random"],
    "seeds": 3,
    "iterations": 2,
    "resolution": 16,
    "scenes": [{"name": "toy_scene", "unknowns": ["mass", "elasticity"]}],
}
CELLS = 2 * 2 * 3


def _sweep(out: Path, **kw: Any) -> Any:
    return run_sweep(parse_spec(TOY), out, executor="serial", progress=False, **kw)


def _cells(out: Path) -> dict[Path, dict[str, Any]]:
    return {p: json.loads(p.read_text()) for p in sorted((out / "cells").glob("*.json"))}


def test_cells_are_stamped_once_per_scene_and_seed(tmp_path: Path, toy: ModuleType) -> None:
    _sweep(tmp_path)
    cells = _cells(tmp_path)
    assert len(cells) == CELLS
    for data in cells.values():
        assert "case" not in data and data["config"]["scene"] == "toy_scene"
        assert set(data["stamp"]) == {"scene", "estimator", "physbench"}
    by_estimator = {d["config"]["estimator"]: d["stamp"]["estimator"] for d in cells.values()}
    assert by_estimator["toy"] == {"step": 0.5}  # resolved: the default is recorded
    # the stamps of 12 cells generate the scene once per seed
    cells_now = parse_spec(TOY).cells()
    toy.GENERATED = 0
    stamper = Stamper()
    stamps = [stamper.stamp(c.config) for c in cells_now]
    assert toy.GENERATED == 3 and len({s["scene"] for s in stamps}) == 3


def test_a_changed_scene_generator_is_refused(tmp_path: Path, toy: ModuleType) -> None:
    first = _sweep(tmp_path)
    assert (_sweep(tmp_path).ran, first.ran) == (0, CELLS)  # unchanged: resumes silently
    toy.FRAMES = 9
    before = {p: p.stat().st_mtime_ns for p in (tmp_path / "cells").glob("*.json")}
    with pytest.raises(StaleCellsError) as err:
        _sweep(tmp_path)
    assert str(err.value).startswith(
        f"{tmp_path}: 12 of 12 finished cells were produced by other code or settings than this "
        "run would use:\n"
        "  - scene toy_scene, seeds 0-2: the generated scene differs (its generator or scene "
        "file changed)\n"
        "Resuming would mix their results with new ones. Rerun with --allow-stale"
    ), str(err.value)
    assert "estimator" not in str(err.value)
    # refused before anything ran or was written
    assert {p: p.stat().st_mtime_ns for p in (tmp_path / "cells").glob("*.json")} == before
    kept = _sweep(tmp_path, allow_stale=True)
    assert (kept.ran, kept.skipped) == (0, CELLS)


def test_a_changed_estimator_default_is_refused(tmp_path: Path, toy: ModuleType) -> None:
    _sweep(tmp_path)
    toy.STEP = 0.25
    with pytest.raises(StaleCellsError) as err:
        _sweep(tmp_path)
    message = str(err.value)
    assert message.startswith(f"{tmp_path}: 6 of 12 finished cells were produced by other code")
    assert "  - estimator toy: resolved options step 0.5 -> 0.25\n" in message
    assert "scene" not in message
    kept = _sweep(tmp_path, allow_stale=True)
    assert (kept.ran, kept.skipped) == (0, CELLS)


def test_a_new_physbench_version_is_refused(
    tmp_path: Path, toy: ModuleType, monkeypatch: pytest.MonkeyPatch
) -> None:
    _sweep(tmp_path)
    monkeypatch.setattr(stamp_module, "physbench_version", lambda: "99.0")
    with pytest.raises(StaleCellsError, match=r"12 of 12 .*\n  - physbench .* -> 99\.0\n"):
        _sweep(tmp_path)


def test_failed_cells_retried_are_not_checked(tmp_path: Path, toy: ModuleType) -> None:
    _sweep(tmp_path)
    for path, data in _cells(tmp_path).items():
        if data["config"]["estimator"] == "toy":
            path.write_text(json.dumps({**data, "status": "failed", "stamp": None}))
    with pytest.raises(StaleCellsError, match="6 of 12 finished cells"):
        _sweep(tmp_path)
    assert _sweep(tmp_path, retry_failed=True).ran == 6


def test_cells_from_before_stamps_are_stale_and_still_read(tmp_path: Path, toy: ModuleType) -> None:
    """Cells written before this change: settings under "case", no stamp."""
    want = without_timings(_sweep(tmp_path).table)
    for path, data in _cells(tmp_path).items():
        data["case"] = data.pop("config")
        del data["stamp"]
        path.write_text(json.dumps(data))
    with pytest.raises(StaleCellsError) as err:
        _sweep(tmp_path)
    assert (
        f"{tmp_path}: 12 of 12 finished cells were produced by other code or settings than this "
        "run would use:\n  - 12 cells without a stamp (written before physbench recorded "
        "what produced a cell)\nResuming"
    ) in str(err.value)
    res = _sweep(tmp_path, allow_stale=True)
    assert res.ran == 0
    pd.testing.assert_frame_equal(without_timings(res.table), want, check_exact=True)
