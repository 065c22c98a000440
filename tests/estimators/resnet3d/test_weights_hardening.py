"""Bad weights files fail with a PhysbenchError naming the file, never deep inside torch (issue 14):
broken tensors, broken sidecars, layouts no net can take, and bad files in a search folder."""

from __future__ import annotations

import contextlib
import copy
import hashlib
import json
import os
import pickle
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from physbench.errors import PhysbenchError  # noqa: E402
from physbench.estimators.resnet3d import weights  # noqa: E402
from physbench.estimators.resnet3d.network import NetConfig, build_net  # noqa: E402
from physbench.estimators.resnet3d.training_data import DataSpec  # noqa: E402

TINY = NetConfig(n_outputs=1, widths=(4, 8, 8, 8), resolution=16, frames=6)
TINY_DATA = DataSpec(
    "three_circles", ("mass",), render_resolution=32, resolution=16, frames=6, group=3
)


def _valid() -> tuple[bytes, dict[str, Any]]:
    """The bytes and sidecar of a valid tiny int8 weights file, as physbench train writes it."""
    torch.manual_seed(0)
    from safetensors.torch import save as encode

    data = encode(weights.quantize(dict(build_net(TINY).state_dict())))
    meta = {
        "scene": "three_circles",
        "data": TINY_DATA.to_dict(),
        "net": TINY.to_dict(),
        "ranges": {"mass": [2.0, 8.0]},
        "storage": weights.INT8,
        "val_mse": 0.01,
        "sha256": hashlib.sha256(data).hexdigest(),
    }
    return data, json.loads(json.dumps(meta))  # tuples become lists, as in a file


VALID_BYTES, VALID_META = _valid()


def write(
    folder: Path, data: bytes = VALID_BYTES, meta: Any = None, *, side: str | None = None
) -> Path:
    """``folder/w.safetensors`` with ``data`` and a sidecar: ``side`` verbatim, else ``meta``
    (default the valid one) whose sha256, if kept, is set to ``data``'s, as a forger would."""
    path = folder / "w.safetensors"
    path.write_bytes(data)
    if side is None:
        meta = copy.deepcopy(VALID_META if meta is None else meta)
        if isinstance(meta, dict) and "sha256" in meta:
            meta["sha256"] = hashlib.sha256(data).hexdigest()
        side = json.dumps(meta)
    path.with_suffix(".json").write_text(side)
    return path


def with_net(**changes: Any) -> dict[str, Any]:
    meta = copy.deepcopy(VALID_META)
    meta["net"].update(changes)
    return meta


def test_the_valid_file_loads_and_fits_the_net(tmp_path: Path) -> None:
    tensors, meta = weights.load(write(tmp_path))
    build_net(NetConfig.from_dict(meta["net"])).load_state_dict(tensors)


# --- the tensors file --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "data",
    [
        VALID_BYTES[: len(VALID_BYTES) // 2],
        b"",
        b"\xff" * 8 + b'{"a": {"dtype": "F32", "shape": [1], "data_offsets": [0, 4]}}',
        pickle.dumps({"head.weight": [1.0, 2.0]}),
    ],
    ids=["truncated", "zero-byte", "forged-header", "pickle-renamed"],
)
def test_a_file_that_is_not_safetensors_is_named_and_refused(tmp_path: Path, data: bytes) -> None:
    with pytest.raises(PhysbenchError, match=r"w\.safetensors.*not a readable safetensors file"):
        weights.load(write(tmp_path, data))


def _resaved(tensors: dict[str, Any]) -> bytes:
    from safetensors.torch import save as encode

    return encode(tensors)


def test_a_missing_tensor_is_refused_before_load_state_dict(tmp_path: Path) -> None:
    from safetensors.torch import load as decode

    tensors = decode(VALID_BYTES)
    del tensors["head.bias"]
    with pytest.raises(PhysbenchError, match=r"missing tensors \['head\.bias'\]"):
        weights.load(write(tmp_path, _resaved(tensors)))


def test_an_extra_tensor_is_refused_before_load_state_dict(tmp_path: Path) -> None:
    from safetensors.torch import load as decode

    tensors = {**decode(VALID_BYTES), "spare": torch.zeros(2)}
    with pytest.raises(PhysbenchError, match=r"unexpected \['spare'\]"):
        weights.load(write(tmp_path, _resaved(tensors)))


def test_int8_tensors_without_storage_in_the_sidecar_are_refused(tmp_path: Path) -> None:
    meta = copy.deepcopy(VALID_META)
    del meta["storage"]
    with pytest.raises(PhysbenchError, match=r"int8 tensors .* no storage"):
        weights.load(write(tmp_path, meta=meta))


# --- the sidecar -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("side", "match"),
    [
        ("{not json", "not valid JSON"),
        ("", "not valid JSON"),
        ("[1, 2]", "holds a JSON list, expected an object"),
        ("{}", "no 'data' entry"),
    ],
    ids=["invalid", "empty", "list", "empty-object"],
)
def test_a_sidecar_that_is_not_a_weights_record_is_refused(
    tmp_path: Path, side: str, match: str
) -> None:
    with pytest.raises(PhysbenchError, match=match):
        weights.load(write(tmp_path, side=side))


def test_changed_widths_are_refused_with_the_tensor_that_does_not_fit(tmp_path: Path) -> None:
    with pytest.raises(
        PhysbenchError, match=r"tensor 'stem\.0\.weight' has shape \(4, .*expects \(8,"
    ):
        weights.load(write(tmp_path, meta=with_net(widths=[8, 8, 8, 8])))


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"resolution": 0}, r"net\.resolution is 0, expected an integer in 8\.\.512"),
        ({"resolution": 4096}, r"net\.resolution is 4096, expected an integer in 8\.\.512"),
        ({"frames": 1000}, r"net\.frames is 1000, expected an integer in 2\.\.64"),
        ({"widths": "wide"}, r"net\.widths is 'wide', expected a list of 4 integers"),
    ],
    ids=["resolution-0", "resolution-4096", "frames-1000", "widths-text"],
)
def test_a_net_no_input_fits_is_refused(tmp_path: Path, change: dict, match: str) -> None:
    with pytest.raises(PhysbenchError, match=match):
        weights.load(write(tmp_path, meta=with_net(**change)))


def test_a_sidecar_without_storage_or_data_fields_names_the_key(tmp_path: Path) -> None:
    meta = copy.deepcopy(VALID_META)
    del meta["data"]["params"]
    with pytest.raises(PhysbenchError, match=r"data is .*expected an object with the keys params"):
        weights.load(write(tmp_path, meta=meta))


# --- search folders ----------------------------------------------------------------------------


def test_a_bad_file_in_a_search_folder_is_skipped_with_a_warning_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "good").mkdir()
    (tmp_path / "mixed").mkdir()
    good = write(tmp_path / "good")
    bad = write(tmp_path / "mixed", side="{not json")
    other = tmp_path / "mixed" / "other.safetensors"  # a valid file beside it: no error
    other.write_bytes(good.read_bytes())
    other.with_suffix(".json").write_text(good.with_suffix(".json").read_text())
    monkeypatch.setattr(weights, "SHIPPED", tmp_path / "none")
    monkeypatch.setenv("PHYSBENCH_WEIGHTS", f"{tmp_path / 'mixed'}:{tmp_path / 'good'}")
    with pytest.warns(UserWarning, match=rf"skipping weights '{bad}'.*not valid JSON"):
        found = weights.find("three_circles", ("mass",))
    assert found.path == other  # the first folder's valid file
    with pytest.raises(PhysbenchError, match="not valid JSON"):  # asked for by name, it fails
        weights.load(bad)


@pytest.mark.parametrize(
    ("make", "why"),
    [
        (lambda d: None, "which does not exist"),
        (lambda d: d.mkdir(), r"which holds no resnet3d weights \(no NAME.safetensors"),
        (lambda d: d.write_text("x"), "which is not a folder"),
        (
            lambda d: (d.mkdir(), write(d, side="{not json")),
            r"which holds no valid resnet3d weights \('.*w.safetensors': .*not valid JSON",
        ),
    ],
)
def test_a_named_folder_without_valid_weights_is_an_error_not_a_fall_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, make: Any, why: str
) -> None:
    folder = tmp_path / "mine"
    make(folder)
    monkeypatch.setenv("PHYSBENCH_WEIGHTS", str(folder))
    with pytest.raises(PhysbenchError) as exc:  # the shipped weights would have served
        weights.find("three_circles", ("mass",))
    said = str(exc.value)
    assert said.startswith(f"PHYSBENCH_WEIGHTS names {str(folder)!r}, "), said
    assert re.search(why, said) and said.endswith("or take this folder off it"), said


def test_the_cli_says_a_skipped_file_in_one_physbench_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from physbench.cli import main

    write(tmp_path)  # tiny valid weights for three_circles mass, found before the shipped ones
    (tmp_path / "other.safetensors").write_bytes(VALID_BYTES)
    (tmp_path / "other.json").write_text("{not json")
    monkeypatch.setenv("PHYSBENCH_WEIGHTS", str(tmp_path))
    argv = ["run", "--estimator", "resnet3d", "--iterations", "1", "--resolution", "32", "-q"]
    assert main(argv) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"physbench run: warning: skipping weights '{tmp_path / 'other.safetensors'}': "
        f"weights sidecar '{tmp_path / 'other.json'}' is not valid JSON (Expecting "
        "property name enclosed in double quotes: line 1 column 2 (char 1)); expected the object "
        "physbench train writes beside NAME.safetensors"
    ], err


# --- the estimator -----------------------------------------------------------------------------


def _start(path: Path) -> None:
    """The estimator's start on a three_circles task with blank marked observations."""
    from physbench.estimators.base import Task
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.plugins import get_registry
    from physbench.unknowns import ParamSpace

    scene = get_registry().get("scene", "three_circles")(0)
    space = ParamSpace.from_scene(scene, ("mass",))
    blank = np.zeros((scene.frames, 2, 32, 32), np.float32)
    task = Task(
        scene=scene,
        space=space,
        observation=blank,
        initial=space.sample(np.random.default_rng(0)),
        renderer=None,
        iterations=1,
        marked_observation={b: blank for b in space.bodies},
    )
    ResNet3DEstimator(weights=str(path), threads=0).start(task, seed=0)


def test_the_estimator_refuses_a_bad_sidecar_at_start(tmp_path: Path) -> None:
    _start(write(tmp_path))  # the valid file starts
    with pytest.raises(PhysbenchError, match=r"net\.frames is 1000"):
        _start(write(tmp_path, meta=with_net(frames=1000)))


# --- fuzzing -----------------------------------------------------------------------------------


def _paths(value: Any, at: tuple = ()) -> list[tuple]:
    """Every key/index path into a JSON value (the root excluded)."""
    out: list[tuple] = []
    items = (
        value.items()
        if isinstance(value, dict)
        else enumerate(value)
        if isinstance(value, list)
        else ()
    )
    for k, v in items:
        out.append((*at, k))
        out.extend(_paths(v, (*at, k)))
    return out


PATHS = _paths(VALID_META)
JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**40), 2**40),
    st.sampled_from([0, 1, -1, 7, 4096, 10**6]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=4),
    st.lists(st.integers(-3, 600), max_size=5),
    st.just({}),
)
SIDECAR_EDIT = st.tuples(st.sampled_from(PATHS), st.sampled_from(["delete", "replace"]), JUNK)
BYTES_EDIT = st.one_of(
    st.tuples(st.just("truncate"), st.integers(0, len(VALID_BYTES) - 1), st.just(0)),
    st.tuples(st.just("flip"), st.integers(0, len(VALID_BYTES) - 1), st.integers(1, 255)),
)


def _edit_meta(meta: dict[str, Any], path: tuple, op: str, junk: Any) -> None:
    parent: Any = meta
    for k in path[:-1]:
        try:
            parent = parent[k]
        except (KeyError, IndexError, TypeError):
            return  # an earlier edit removed or replaced the way there
    key = path[-1]
    if (isinstance(parent, dict) and key in parent) or (
        isinstance(parent, list) and key < len(parent)
    ):
        if op == "delete":
            del parent[key]
        else:
            parent[key] = junk


def _edit_bytes(data: bytes, edits: list[tuple[str, int, int]]) -> bytes:
    buf = bytearray(data)
    for op, at, x in edits:
        if op == "truncate":
            del buf[at:]
        elif at < len(buf):
            buf[at] ^= x
    return bytes(buf)


@settings(
    max_examples=150 * int(os.environ.get("PHYSBENCH_FUZZ_SCALE", "1")),  # nox -s fuzz: 10x
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    meta_edits=st.lists(SIDECAR_EDIT, max_size=3),
    byte_edits=st.lists(BYTES_EDIT, max_size=2),
    forge_sha=st.booleans(),
)
def test_any_damaged_pair_loads_or_raises_a_physbench_error(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    meta_edits: list[tuple[tuple, str, Any]],
    byte_edits: list[tuple[str, int, int]],
    forge_sha: bool,
) -> None:
    meta = copy.deepcopy(VALID_META)
    for path, op, junk in meta_edits:
        _edit_meta(meta, path, op, junk)
    data = _edit_bytes(VALID_BYTES, byte_edits)
    if forge_sha and isinstance(meta.get("sha256"), str):
        meta["sha256"] = hashlib.sha256(data).hexdigest()  # past the sha check, into parsing
    path = tmp_path / "w.safetensors"
    path.write_bytes(data)
    path.with_suffix(".json").write_text(json.dumps(meta))
    monkeypatch.setattr(weights, "SHIPPED", tmp_path / "none")
    monkeypatch.setenv("PHYSBENCH_WEIGHTS", str(tmp_path))
    with contextlib.suppress(PhysbenchError):
        _start(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a skipped file warns; anything else would be a bug
        try:
            weights.available()
        except UserWarning as w:
            assert "skipping weights" in str(w)
        except PhysbenchError as exc:  # the folder named holds nothing valid
            assert f"PHYSBENCH_WEIGHTS names {str(tmp_path)!r}" in str(exc)
