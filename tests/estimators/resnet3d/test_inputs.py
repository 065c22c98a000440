"""Network inputs: observed and simulated sequences concatenated along time."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.estimators.resnet3d.inputs import make_input, resize, time_indices  # noqa: E402


def test_inputs_concatenate_observed_and_simulated_along_time() -> None:
    obs = np.zeros((30, 2, 64, 64), np.float32)
    sim = np.ones((30, 2, 64, 64), np.float32)
    x = make_input(obs, sim, frames=15, resolution=32)
    assert x.shape == (2, 30, 32, 32) and x.dtype == np.float32
    assert x[:, :15].max() == 0 and x[:, 15:].min() == 1
    assert list(time_indices(30, 15))[:3] == [0, 2, 4] and time_indices(30, 15)[-1] == 29
    block = np.arange(16, dtype=float).reshape(4, 4)
    assert resize(block, 2).tolist() == [[2.5, 4.5], [10.5, 12.5]]


@pytest.mark.parametrize(
    ("shape", "size"), [((30, 2, 64, 64), 32), ((3, 2, 64, 96), 16), ((2, 48, 48), 16)]
)
def test_integer_factor_resize_is_the_block_mean_to_the_last_bit(
    shape: tuple[int, ...], size: int
) -> None:
    frames = np.random.default_rng(0).random(shape, dtype=np.float32)
    h, w = shape[-2:]
    f = h // size
    block_mean = frames.reshape(*shape[:-2], size, f, w // f, f).mean(axis=(-3, -1))
    out = resize(frames, size)
    assert out.dtype == np.float32 and out.shape == block_mean.shape
    assert np.array_equal(out, block_mean)


def test_make_input_writes_into_a_given_slot_and_refuses_a_wrong_one() -> None:
    rng = np.random.default_rng(1)
    obs, sim = rng.random((2, 30, 2, 64, 64), dtype=np.float32)
    batch = np.zeros((2, 2, 30, 32, 32), np.float32)
    x = make_input(obs, sim, frames=15, resolution=32, out=batch[1])
    assert x is batch[1] or np.shares_memory(x, batch)
    assert np.array_equal(batch[1], make_input(obs, sim, frames=15, resolution=32))
    assert not batch[0].any()
    # Every frame at the input's own size: the sequences as they are, observed first.
    full = make_input(obs, sim, frames=30, resolution=64)
    assert np.array_equal(full[:, :30], obs.transpose(1, 0, 2, 3))
    assert np.array_equal(full[:, 30:], sim.transpose(1, 0, 2, 3))
    with pytest.raises(ValueError, match="expected"):
        make_input(obs, sim, frames=15, resolution=32, out=np.zeros((2, 30, 16, 16), np.float32))
