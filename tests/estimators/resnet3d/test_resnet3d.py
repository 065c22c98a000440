"""The learned estimator: architecture, training plumbing, safetensors weights, shipped models."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.errors import PhysbenchError  # noqa: E402
from physbench.estimators.resnet3d import weights  # noqa: E402
from physbench.estimators.resnet3d.data import DataSpec, PairMaker  # noqa: E402
from physbench.estimators.resnet3d.inputs import make_input, resize, time_indices  # noqa: E402
from physbench.estimators.resnet3d.model import FULL_WIDTHS, NetConfig, build_net  # noqa: E402
from physbench.estimators.resnet3d.train import TrainConfig, train  # noqa: E402

TINY = NetConfig(n_outputs=1, widths=(4, 8, 8, 8), resolution=16, frames=6)
TINY_DATA = DataSpec(
    "three_circles", ("mass",), render_resolution=32, resolution=16, frames=6, group=3
)


@pytest.mark.parametrize(("n_out", "batch", "frames", "res"), [(1, 2, 6, 16), (2, 3, 15, 32)])
def test_architecture_shapes(n_out: int, batch: int, frames: int, res: int) -> None:
    net = build_net(NetConfig(n_outputs=n_out, widths=(4, 8, 8, 8), resolution=res, frames=frames))
    out = net(torch.zeros(batch, 2, 2 * frames, res, res))
    assert out.shape == (batch, n_out)
    n_blocks = sum(1 for m in net.modules() if type(m).__name__ == "Block")
    assert n_blocks == 8  # ResNet-18: BasicBlocks [2, 2, 2, 2]
    assert not any(isinstance(m, torch.nn.BatchNorm3d) for m in net.modules())
    assert any(isinstance(m, torch.nn.Dropout3d) for m in net.modules())


def test_full_width_is_the_paper_resnet18_size() -> None:
    net = build_net(NetConfig(n_outputs=1, widths=FULL_WIDTHS))
    n = sum(p.numel() for p in net.parameters())
    assert 25e6 < n < 40e6  # 3D ResNet-18 widths 64..512 (~33M weights)


def test_inputs_concatenate_observed_and_simulated_along_time() -> None:
    obs = np.zeros((30, 2, 64, 64), np.float32)
    sim = np.ones((30, 2, 64, 64), np.float32)
    x = make_input(obs, sim, frames=15, resolution=32)
    assert x.shape == (2, 30, 32, 32) and x.dtype == np.float32
    assert x[:, :15].max() == 0 and x[:, 15:].min() == 1
    assert list(time_indices(30, 15))[:3] == [0, 2, 4] and time_indices(30, 15)[-1] == 29
    block = np.arange(16, dtype=float).reshape(4, 4)
    assert resize(block, 2).tolist() == [[2.5, 4.5], [10.5, 12.5]]


def test_pairs_targets_are_range_normalised_differences() -> None:
    maker = PairMaker(TINY_DATA)
    x, y = maker.group(12345)
    assert x.shape[1:] == (2, 12, 16, 16)
    assert y.shape == (x.shape[0], 1) and np.all(np.abs(y) <= 1)
    # Ordered pairs: (i, j) and (j, i) have opposite targets.
    assert np.isclose(y.sum(), 0.0, atol=1e-5)


def test_a_few_steps_on_fixed_pairs_lower_the_loss() -> None:
    torch.set_num_threads(1)  # tiny tensors: more threads only add contention on a busy machine
    torch.manual_seed(0)
    x, y = PairMaker(TINY_DATA).group(777)
    xt, yt = torch.from_numpy(x), torch.from_numpy(y)
    net = build_net(NetConfig(**{**TINY.to_dict(), "dropout": 0.0}))
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    first = None
    for _ in range(60):
        loss = torch.nn.functional.mse_loss(net(xt), yt)
        first = first if first is not None else loss.item()
        opt.zero_grad()
        loss.backward()
        opt.step()
    net.eval()
    final = torch.nn.functional.mse_loss(net(xt), yt).item()
    assert final < 0.2 * first


def test_train_writes_checkpoints_resumes_and_saves_safetensors(tmp_path: Path) -> None:
    cfg = TrainConfig(samples=96, batch=8, eval_every=48, val_groups=1, workers=0, threads=1)
    path, meta = train(TINY_DATA, TINY, cfg, tmp_path, progress=False)
    assert path.suffix == ".safetensors" and path.with_suffix(".json").is_file()
    for key in (
        "data",
        "net",
        "ranges",
        "normalization",
        "training",
        "val_mse",
        "physbench_version",
    ):
        assert key in meta
    assert meta["ranges"] == {"mass": [2.0, 8.0]} or set(meta["ranges"]) == {"mass"}
    assert [h["samples"] for h in meta["history"]] == [48, 96]
    # Resume: a larger budget continues from the checkpoint instead of starting over.
    path2, meta2 = train(
        TINY_DATA, TINY, TrainConfig(**{**cfg.__dict__, "samples": 144}), tmp_path, progress=False
    )
    assert [h["samples"] for h in meta2["history"]] == [48, 96, 144]
    # Weights round-trip through safetensors: same outputs after loading.
    state, side = weights.load(path2)
    net = build_net(NetConfig.from_dict(side["net"]))
    net.load_state_dict({k: v.float() for k, v in state.items()})
    net2 = build_net(NetConfig.from_dict(side["net"]))
    net2.load_state_dict({k: v.float() for k, v in weights.load(path2)[0].items()})
    net.eval()
    net2.eval()
    x = torch.rand(2, 2, 12, 16, 16)
    assert torch.equal(net(x), net2(x))
    assert path2.read_bytes()[8:9] == b"{"  # safetensors header, not a pickle


def test_missing_weights_error_says_how_to_train(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(weights, "SHIPPED", tmp_path)
    with pytest.raises(
        PhysbenchError,
        match=r"no resnet3d weights for scene 'three_circles'.*physbench train --scene three_circles --params mass",
    ):
        weights.find("three_circles", ("mass",))


def test_sidecar_without_tensors_is_refused(tmp_path: Path) -> None:
    (tmp_path / "w.json").write_text(json.dumps({"data": {}}))
    with pytest.raises(PhysbenchError, match="need both"):
        weights.load(tmp_path / "w.safetensors")


def shipped() -> list[weights.WeightsInfo]:
    return [w for w in weights.available() if w.path.parent == weights.SHIPPED]


def test_shipped_weights_exist_and_are_small() -> None:
    found = shipped()
    assert found, "no weights shipped in physbench/estimators/resnet3d/weights"
    total = sum(w.path.stat().st_size for w in found)
    assert total < 30 * 2**20


@pytest.mark.parametrize("info", shipped(), ids=lambda w: f"{w.scene}-{'+'.join(w.params)}")
def test_shipped_weights_beat_the_random_estimator(info: weights.WeightsInfo) -> None:
    from physbench.estimators.random_search import RandomSearch
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.loop import draw_problem, refine
    from physbench.observation import simulate_observation
    from physbench.params import ParamSpace
    from physbench.plugins import create, get_registry

    spec = DataSpec.from_dict(info.meta["data"])
    gen = get_registry().get("scene", spec.scene)
    sim, renderer = create("simulator", "pymunk"), create("renderer", "raster", resolution=64)
    learned, baseline = [], []
    for seed in range(4):
        scene = gen(seed, **spec.scene_options)
        space = ParamSpace.from_scene(scene, spec.params)
        truth, initial = draw_problem(space, seed)
        obs = simulate_observation(scene, truth, sim, renderer, marked=space.bodies)
        for est, out in (
            (ResNet3DEstimator(weights=str(info.path)), learned),
            (RandomSearch(), baseline),
        ):
            h = refine(
                obs, scene, space, sim, renderer, est, iterations=3, seed=seed, initial=initial
            )
            out.append(h.best_nmse)
    assert np.mean(learned) < np.mean(baseline), (learned, baseline)


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
    loaded, _ = weights.load(path)
    assert all(loaded[k].dtype == torch.float32 and torch.equal(loaded[k], back[k]) for k in back)
    # On the shipped architecture int8 is about a quarter of float32 (scales and biases add little).
    big = dict(build_net(NetConfig(n_outputs=1)).state_dict())
    f32 = weights.save(tmp_path / "f", big, {})
    i8 = weights.save(tmp_path / "i", weights.quantize(big), {})
    assert i8.stat().st_size < 0.26 * f32.stat().st_size


def test_blur_augmentation_blurs_the_observed_half_only() -> None:
    sharp = PairMaker(TINY_DATA).group(4321)
    blurred = PairMaker(
        DataSpec(**{**TINY_DATA.__dict__, "blur_max": 3.0, "blur_prob": 1.0})
    ).group(4321)
    frames = TINY_DATA.frames
    assert np.array_equal(sharp[1], blurred[1])  # same simulations, same targets
    assert np.array_equal(
        sharp[0][:, :, frames:], blurred[0][:, :, frames:]
    )  # simulated half untouched
    assert not np.allclose(sharp[0][:, :, :frames], blurred[0][:, :, :frames])

    # Blur smooths: less total variation across the image.
    def tv(x: np.ndarray) -> float:
        return float(np.abs(np.diff(x, axis=-1)).sum() + np.abs(np.diff(x, axis=-2)).sum())

    assert tv(blurred[0][:, :, :frames]) < 0.95 * tv(sharp[0][:, :, :frames])


def test_learning_rate_follows_the_samples_or_the_wall_clock_whichever_is_further() -> None:
    from physbench.estimators.resnet3d.train import learning_rate, progress_fraction

    cfg = TrainConfig(samples=1000, minutes=1.0, lr=1e-3)
    assert progress_fraction(cfg, 500, 0.0) == 0.5
    assert progress_fraction(cfg, 100, 45.0) == 0.75
    assert progress_fraction(cfg, 2000, 0.0) == 1.0
    lrs = [learning_rate(cfg, 0, t) for t in (3.0, 10.0, 30.0, 59.0)]
    assert lrs[0] == pytest.approx(1e-3) and lrs[1] > lrs[2] > lrs[3] > 0.04e-3
    assert learning_rate(cfg, 0, 0.0) < 1e-3  # warm-up


@pytest.mark.parametrize("symmetric", [False, True])
def test_symmetric_option_makes_the_truth_an_exact_fixed_point(symmetric: bool) -> None:
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.loop import draw_problem, refine
    from physbench.observation import simulate_observation
    from physbench.params import ParamSpace
    from physbench.plugins import create, get_registry

    scene = get_registry().get("scene", "three_circles")(3)
    space = ParamSpace.from_scene(scene, ("mass",))
    truth, _ = draw_problem(space, 3)
    sim, renderer = create("simulator", "pymunk"), create("renderer", "raster", resolution=64)
    obs = simulate_observation(scene, truth, sim, renderer, marked=space.bodies)
    # Started at the truth, the simulated frames equal the observed ones.
    h = refine(
        obs,
        scene,
        space,
        sim,
        renderer,
        ResNet3DEstimator(symmetric=symmetric),
        iterations=2,
        seed=3,
        initial=truth,
    )
    moved = max(abs(h.iterations[1].params[k] - truth[k]) for k in truth)
    if symmetric:
        assert moved < 1e-9  # f(o, s) - f(s, o) vanishes when o == s
    else:
        assert moved > 1e-6  # the plain network has a small bias at zero difference


def test_init_fine_tunes_from_weights_and_refuses_another_architecture(tmp_path: Path) -> None:
    cfg = TrainConfig(samples=16, batch=8, eval_every=16, val_groups=1, workers=0, threads=1)
    first, _ = train(TINY_DATA, TINY, cfg, tmp_path / "a", progress=False)
    # lr = 0: nothing moves, so the fine-tuned weights are the ones it started from.
    same, _ = train(
        TINY_DATA,
        TINY,
        TrainConfig(**{**cfg.__dict__, "lr": 0.0, "init": str(first)}),
        tmp_path / "b",
        progress=False,
    )
    a, b = weights.load(first)[0], weights.load(same)[0]
    assert all(torch.allclose(a[k], b[k], atol=1e-6) for k in a)
    other = NetConfig(**{**TINY.to_dict(), "widths": (4, 8, 8, 16)})
    with pytest.raises(PhysbenchError, match="architecture"):
        train(
            TINY_DATA,
            other,
            TrainConfig(**{**cfg.__dict__, "init": str(first)}),
            tmp_path / "c",
            progress=False,
        )
