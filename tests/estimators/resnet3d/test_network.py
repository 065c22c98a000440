"""The 3D ResNet: output shapes and the paper-size parameter count."""

from __future__ import annotations

import pytest

torch = pytest.importorskip("torch")

from physbench.estimators.resnet3d.network import FULL_WIDTHS, NetConfig, build_net  # noqa: E402


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
