"""Weights: safetensors + JSON sidecar, int8 storage, the shipped models and their size."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

torch = pytest.importorskip("torch")

from physbench.errors import PhysbenchError  # noqa: E402
from physbench.estimators.resnet3d import weights  # noqa: E402
from physbench.estimators.resnet3d.network import NetConfig, build_net  # noqa: E402
from physbench.estimators.resnet3d.training_data import DataSpec  # noqa: E402

TINY = NetConfig(n_outputs=1, widths=(4, 8, 8, 8), resolution=16, frames=6)
TINY_DATA = DataSpec(
    "three_circles", ("mass",), render_resolution=32, resolution=16, frames=6, group=3
)


def test_missing_weights_error_says_how_to_train(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(weights, "SHIPPED", tmp_path)
    with pytest.raises(
        PhysbenchError,
        match=r"no resnet3d weights for scene 'three_circles'.*physbench train --scene "
        r"three_circles --params mass",
    ):
        weights.find("three_circles", ("mass",))


def test_sidecar_without_tensors_is_refused(tmp_path: Path) -> None:
    (tmp_path / "w.json").write_text(json.dumps({"data": {}}))
    with pytest.raises(PhysbenchError, match="need both"):
        weights.load(tmp_path / "w.safetensors")


def test_saved_weights_are_readable_by_others_and_refuse_a_mixed_pair(tmp_path: Path) -> None:
    import os
    import stat

    old = os.umask(0o022)
    try:
        first = weights.save(tmp_path / "w", {"a": torch.ones(3)}, {"run": 1})
    finally:
        os.umask(old)
    for f in (first, first.with_suffix(".json")):
        assert stat.S_IMODE(f.stat().st_mode) == 0o644, f
    tensors, meta = weights.read(first)  # a pair that is not a model's: read, not load
    assert meta["run"] == 1 and tensors["a"].tolist() == [1.0, 1.0, 1.0]
    side = first.with_suffix(".json").read_text()
    weights.save(tmp_path / "w", {"a": torch.zeros(3)}, {"run": 2})
    first.with_suffix(".json").write_text(side)  # as if the second save stopped between the two
    with pytest.raises(PhysbenchError, match=r"describes other tensors .* two saves"):
        weights.read(first)


def test_shipped_sidecars_name_their_tensors() -> None:
    import hashlib

    for w in shipped():
        assert w.meta["sha256"] == hashlib.sha256(w.path.read_bytes()).hexdigest(), w.path


def shipped() -> list[weights.WeightsInfo]:
    return [w for w in weights.available() if w.path.parent == weights.SHIPPED]


def test_shipped_weights_exist_and_are_small() -> None:
    found = shipped()
    assert found, "no weights shipped in physbench/estimators/resnet3d/weights"
    total = sum(w.path.stat().st_size for w in found)
    assert total < 30 * 2**20


def test_int8_storage_round_trips_within_a_step_and_is_a_quarter_of_float32(tmp_path: Path) -> None:
    torch.manual_seed(0)
    state = dict(build_net(TINY).state_dict())
    q = weights.quantize(state)
    assert q["head.weight"].dtype == torch.int8 and q["head.bias"].dtype == torch.float16
    back = weights.dequantize(q)
    assert set(back) == set(state)
    for k, v in state.items():
        step = (
            v.abs().flatten(1).amax(1).view((-1,) + (1,) * (v.dim() - 1)) / 127
            if v.dim() >= 2
            else 1e-3 * v.abs().max()
        )
        assert torch.all((back[k] - v).abs() <= step / 2 + 1e-6), k
    path = weights.save(tmp_path / "w", q, {"storage": weights.INT8, "net": TINY.to_dict()})
    loaded, _ = weights.read(path)
    assert all(loaded[k].dtype == torch.float32 and torch.equal(loaded[k], back[k]) for k in back)
    # On the shipped architecture int8 is about a quarter of float32 (scales and biases add little).
    big = dict(build_net(NetConfig(n_outputs=1)).state_dict())
    f32 = weights.save(tmp_path / "f", big, {})
    i8 = weights.save(tmp_path / "i", weights.quantize(big), {})
    assert i8.stat().st_size < 0.26 * f32.stat().st_size
