"""Training: the loss falls, checkpoints resume, the learning-rate schedule, fine-tuning."""

from __future__ import annotations

from pathlib import Path

import pytest

torch = pytest.importorskip("torch")

from physbench.errors import PhysbenchError  # noqa: E402
from physbench.estimators.resnet3d import weights  # noqa: E402
from physbench.estimators.resnet3d.network import NetConfig, build_net  # noqa: E402
from physbench.estimators.resnet3d.train import TrainConfig, train  # noqa: E402
from physbench.estimators.resnet3d.training_data import DataSpec, PairMaker  # noqa: E402

TINY = NetConfig(n_outputs=1, widths=(4, 8, 8, 8), resolution=16, frames=6)
TINY_DATA = DataSpec(
    "three_circles", ("mass",), render_resolution=32, resolution=16, frames=6, group=3
)


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


def test_learning_rate_follows_the_samples_or_the_wall_clock_whichever_is_further() -> None:
    from physbench.estimators.resnet3d.train import learning_rate, progress_fraction

    cfg = TrainConfig(samples=1000, minutes=1.0, lr=1e-3)
    assert progress_fraction(cfg, 500, 0.0) == 0.5
    assert progress_fraction(cfg, 100, 45.0) == 0.75
    assert progress_fraction(cfg, 2000, 0.0) == 1.0
    lrs = [learning_rate(cfg, 0, t) for t in (3.0, 10.0, 30.0, 59.0)]
    assert lrs[0] == pytest.approx(1e-3) and lrs[1] > lrs[2] > lrs[3] > 0.04e-3
    assert learning_rate(cfg, 0, 0.0) < 1e-3  # warm-up


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


def test_init_may_change_the_input_size_and_draws_new_instances(tmp_path: Path) -> None:
    from physbench.estimators.resnet3d.train import init_groups

    cfg = TrainConfig(samples=16, batch=8, eval_every=16, val_groups=1, workers=0, threads=1)
    first, meta = train(TINY_DATA, TINY, cfg, tmp_path / "a", progress=False)
    assert meta["training"]["first_group"] == 0 and init_groups(meta) == 16
    # A bigger input (resolution and frames) from the same tensors; lr = 0 keeps them.
    big_net = NetConfig(**{**TINY.to_dict(), "resolution": 32, "frames": 8})
    big_data = DataSpec(
        "three_circles", ("mass",), render_resolution=32, resolution=32, frames=8, group=3
    )
    big, big_meta = train(
        big_data,
        big_net,
        TrainConfig(**{**cfg.__dict__, "lr": 0.0, "init": str(first)}),
        tmp_path / "b",
        progress=False,
    )
    a, b = weights.load(first)[0], weights.load(big)[0]
    assert all(torch.allclose(a[k], b[k], atol=1e-6) for k in a)
    assert big_meta["net"]["resolution"] == 32 and big_meta["net"]["frames"] == 8
    # The curve starts at the weights it was given, measured on this run's validation set.
    assert [h["samples"] for h in big_meta["history"]] == [0, 16]
    assert big_meta["history"][0]["val_mse"] == pytest.approx(big_meta["history"][1]["val_mse"])
    # Its instances come after the 16 groups the first run may have drawn; a chain adds up.
    assert big_meta["training"]["first_group"] == 16 and init_groups(big_meta) == 32


def test_init_groups_reads_only_whole_numbers() -> None:
    from physbench.estimators.resnet3d.train import init_groups

    assert init_groups({}) == 0
    assert init_groups({"training": "x"}) == 0
    assert init_groups({"training": {"samples_seen": 1000}}) == 1000
    assert init_groups({"training": {"samples_seen": 10, "first_group": 5}}) == 15
    assert init_groups({"training": {"samples_seen": True, "first_group": -3}}) == 0
    assert init_groups({"training": {"samples_seen": 2.5}}) == 0


def test_a_time_budget_counts_only_this_sessions_time(tmp_path: Path) -> None:
    import json

    cfg = TrainConfig(samples=48, batch=8, eval_every=48, val_groups=1, workers=0, threads=1)
    train(TINY_DATA, TINY, cfg, tmp_path, progress=False)
    side = tmp_path / "checkpoint.json"
    meta = json.loads(side.read_text())
    side.write_text(json.dumps({**meta, "wall_s": 600.0}))  # as if earlier sessions took 10 min
    resumed = TrainConfig(**{**cfg.__dict__, "samples": 96, "minutes": 1.0})
    _, meta2 = train(TINY_DATA, TINY, resumed, tmp_path, progress=False)
    # A minute of its own: it trains on (the 10 earlier minutes used to end it at once).
    assert [h["samples"] for h in meta2["history"]] == [48, 96]
    assert meta2["history"][-1]["wall_s"] >= 600.0
