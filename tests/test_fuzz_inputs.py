"""Property tests: whatever a user hands physbench as a scene file, a recording or an observation,
loading it either succeeds or raises a :class:`PhysbenchError`, never another exception; every
numeric setting of the API (:class:`~physbench.experiment.RunConfig`,
:class:`~physbench.discover.Settings`) and of a sweep spec is refused or finite (the command-line
flags: tests/commands/test_argument_ranges.py).

``PHYSBENCH_FUZZ_SCALE`` multiplies the number of examples (``nox -s fuzz`` sets it to 10).
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import tempfile
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from physbench.errors import PhysbenchError
from physbench.observation import check_frames, load_observation
from physbench.recording import parse_recordings, read_recordings
from physbench.scene import Scene
from physbench.scene_toml import load_scene, loads_scene, scene_to_dict
from physbench.scenes import resolve_scene

SCALE = int(os.environ.get("PHYSBENCH_FUZZ_SCALE", "1"))
FUZZ = settings(
    max_examples=300 * SCALE,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

BASE = scene_to_dict(resolve_scene("three_circles"))

# Values of every TOML type, with the edges that broke loading before: huge, tiny, non-finite.
scalars = st.one_of(
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.sampled_from([0, 1, -1, 2**62, 0.0, 5e-324, 1e30, -1e30, 1e-7, float("nan"), float("inf")]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.sampled_from(["circle", "box", "polygon", "segment", "test", "a", "b", "world", "mass"]),
    st.booleans(),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=6), inner, max_size=4)
    ),
    max_leaves=12,
)


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix] if prefix else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*prefix, i))
    return out


PATHS = _paths(BASE)
KEYS = sorted({p[-1] for p in PATHS if isinstance(p[-1], str)})


def _copy(node: Any) -> Any:
    if isinstance(node, dict):
        return {k: _copy(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_copy(v) for v in node]
    return node


@st.composite
def mutated_scene_text(draw: st.DrawFn) -> str:
    """A valid scene with a few values replaced, keys dropped or added, or its text damaged."""
    data = _copy(BASE)
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(PATHS))
        parent = data
        try:
            for step in path[:-1]:
                parent = parent[step]
            action = draw(st.sampled_from(["set", "set", "drop", "add", "nest"]))
            leaf = path[-1]
            if action == "set":
                parent[leaf] = draw(values)
            elif action == "drop":
                del parent[leaf]
            elif action == "nest":
                parent[leaf] = [parent[leaf]]
            elif isinstance(parent, dict):
                parent[draw(st.sampled_from(KEYS))] = draw(values)
        except (KeyError, IndexError, TypeError):
            pass  # an earlier mutation removed or replaced this path
    try:
        text = tomli_w.dumps(data)
    except (TypeError, ValueError):  # e.g. a table inside an array of scalars
        text = tomli_w.dumps(BASE)
    how = draw(st.sampled_from(["as is", "as is", "cut", "insert", "deep"]))
    if how == "cut":
        text = text[: draw(st.integers(0, len(text)))]
    elif how == "insert":
        at = draw(st.integers(0, len(text)))
        text = text[:at] + draw(st.text(max_size=20)) + text[at:]
    elif how == "deep":
        depth = draw(st.integers(500, 3000))
        text = f"{draw(st.sampled_from(KEYS))} = {'[' * depth}1{']' * depth}\n" + text
    return text


@FUZZ
@given(mutated_scene_text())
def test_scene_text_loads_or_raises_physbench_error(text: str) -> None:
    try:
        scene = loads_scene(text)
    except PhysbenchError:
        return
    assert isinstance(scene, Scene)


@FUZZ
@given(st.binary(max_size=300))
def test_scene_bytes_load_or_raise_physbench_error(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_bytes(data)
        with contextlib.suppress(PhysbenchError):
            load_scene(path)


HEADER = ["t,body,x,y", "t,body,x,y,angle,run", "t,body,x,y,angle", "body,t,y,x,run"]
cells = st.one_of(
    st.sampled_from(["0", "0.1", "1e308", "-1", "nan", "inf", "", "a", "b", "x", '"', "#"]),
    st.text(max_size=6),
    st.floats().map(repr),
)


@st.composite
def recording_text(draw: st.DrawFn) -> str:
    """Recording CSV: a header (or garbage), comment lines, and rows of random cells."""
    lines = []
    if draw(st.booleans()):
        lines.append(draw(st.sampled_from(["# accuracy: 0.01 m", "# fields: x y", "# fields:"])))
    lines.append(draw(st.one_of(st.sampled_from(HEADER), st.text(max_size=20))))
    for _ in range(draw(st.integers(0, 6))):
        lines.append(",".join(draw(st.lists(cells, min_size=1, max_size=7))))
    text = "\n".join(lines)
    if draw(st.integers(0, 9)) == 0:
        text += "\n0,a," + "9" * 140_000 + ",0"  # a field longer than the csv module allows
    return text


@FUZZ
@given(recording_text(), st.sampled_from([None, ("a", "b")]))
def test_recording_text_parses_or_raises_physbench_error(
    text: str, bodies: tuple[str, ...] | None
) -> None:
    try:
        recs = parse_recordings(text, bodies=bodies)
    except PhysbenchError:
        return
    assert recs


@FUZZ
@given(st.binary(max_size=200))
def test_recording_bytes_read_or_raise_physbench_error(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "rec.csv"
        path.write_bytes(data)
        with contextlib.suppress(PhysbenchError):
            read_recordings(path)


def _filled(shape: tuple[int, ...], dtype: str, fill: float) -> np.ndarray:
    with np.errstate(invalid="ignore"):  # NaN and inf cast to integers: any value will do
        return np.full(shape, fill).astype(dtype)


DTYPES = ["f4", "f8", "f2", "i4", "u1", "?", "c8", "M8[s]", "m8[s]", "U3", "S3", "O"]
arrays = st.one_of(
    st.builds(
        lambda shape, dtype, fill: _filled(shape, dtype, fill),
        st.lists(st.integers(0, 3), min_size=0, max_size=5).map(tuple),
        st.sampled_from([d for d in DTYPES if d != "O"]),
        st.sampled_from([0, 1, 2, -1, 0.5, float("nan"), float("inf")]),
    ),
    st.just(np.zeros(2, dtype=[("a", "f4"), ("b", "i4")])),
    st.sampled_from([np.array("not a scene"), np.array('name = "x"'), np.array(3.0)]),
)


@st.composite
def npz_bytes(draw: st.DrawFn) -> bytes:
    """An ``.npz`` of random arrays under observation keys, an extra non-``.npy`` member, or
    random bytes."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.binary(max_size=200))
    names = draw(
        st.lists(
            st.sampled_from(["frames", "marked_a", "scene_toml", "engine", "effects", "other"]),
            max_size=4,
            unique=True,
        )
    )
    buf = io.BytesIO()
    np.savez(buf, **{n: draw(arrays) for n in names})
    if draw(st.booleans()):
        with zipfile.ZipFile(buf, "a") as z:
            z.writestr(draw(st.sampled_from(["notes.txt", "frames", "x.npy"])), b"hello")
    return buf.getvalue()


@FUZZ
@given(npz_bytes())
def test_observation_file_loads_or_raises_physbench_error(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "obs.npz"
        path.write_bytes(data)
        try:
            obs = load_observation(path)
            check_frames(obs.frames, obs.frames.shape)
        except PhysbenchError:
            pass


# ------------------------------------------------- numeric settings of the API and of sweep specs


def _numeric_fields(cls: type) -> list[str]:
    """The fields of a settings dataclass that hold numbers (read from its annotations, so a new
    one is covered without a change here)."""
    from dataclasses import fields

    return [f.name for f in fields(cls) if any(t in str(f.type) for t in ("int", "float"))]


def _settings_classes() -> list[type]:
    from physbench.discover import Settings
    from physbench.experiment import RunConfig

    return [RunConfig, Settings]


NUMERIC_FIELDS = [(cls, name) for cls in _settings_classes() for name in _numeric_fields(cls)]
#: Values that broke or silently switched off settings before (issue 28: a NaN floor).
API_VALUES = [
    math.nan, math.inf, -math.inf, 1e308, -1e308, 5e-324, 0, 0.0, -0.0, -1, 1, 0.5, 1.5, 2**63,
    -(2**63), 10**30, True, False, "1", None, [math.nan],
]  # fmt: skip


def test_the_numeric_settings_are_found() -> None:
    names = {f"{cls.__name__}.{name}" for cls, name in NUMERIC_FIELDS}
    assert {"RunConfig.blur", "RunConfig.seed", "Settings.floor", "Settings.min_delta_bic"} <= names
    assert len(names) >= 20


def _built_or_refused(cls: type, name: str, value: Any) -> None:
    """``cls(name=value)`` either raises a PhysbenchError or holds a finite number (or None)."""
    try:
        made = cls(**{name: value})
    except PhysbenchError:
        return
    held = getattr(made, name)
    values = held if isinstance(held, list | tuple) else [held]
    for v in values:
        assert v is None or (not isinstance(v, bool) and math.isfinite(v)), (cls, name, value)


@pytest.mark.parametrize(
    ("cls", "name"), NUMERIC_FIELDS, ids=[f"{c.__name__}.{n}" for c, n in NUMERIC_FIELDS]
)
def test_non_finite_settings_are_refused_by_name(cls: type, name: str) -> None:
    for value in (math.nan, math.inf, -math.inf):
        with pytest.raises(PhysbenchError, match=re.escape(name)):
            cls(**{name: value})
    for value in API_VALUES:
        _built_or_refused(cls, name, value)


@FUZZ
@given(
    st.sampled_from(NUMERIC_FIELDS),
    st.one_of(st.sampled_from(API_VALUES), st.floats(), st.integers()),
)
def test_any_numeric_setting_is_refused_or_finite(field: tuple[type, str], value: Any) -> None:
    _built_or_refused(*field, value)


@FUZZ
@given(
    st.sampled_from(["blur", "noise", "resolution", "iterations", "seeds"]),
    st.one_of(st.sampled_from(API_VALUES), st.floats(), st.integers(), st.lists(st.floats())),
)
def test_numeric_spec_axes_are_refused_or_finite(axis: str, value: Any) -> None:
    from physbench.bench.spec import parse_spec

    raw = {"estimators": ["random"], "seeds": 1, "iterations": 1, "scenes": ["three_circles"]}
    try:
        spec = parse_spec({**raw, axis: value})
    except PhysbenchError:
        return
    held = spec.seeds if axis == "seeds" else spec.axes[axis]
    assert all(not isinstance(v, bool) and math.isfinite(v) for v in held)
