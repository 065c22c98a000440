"""The 3D-ResNet-18 correction network (paper Fig. "architecture"): BasicBlocks [2, 2, 2, 2] with
3D convolutions over time, dropout instead of batch norm, global average pooling, a linear head.

Input ``(B, C, 2T, H, W)``: observed and simulated sequences concatenated along time (the paper's
``B × 2T × C × Y × X`` with channels moved first, as ``Conv3d`` wants). Output ``(B, P)``: the
normalised correction Δp for the marked object's P unknowns.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

#: The paper's full widths; for users with a GPU.
FULL_WIDTHS = (64, 128, 256, 512)
#: The shipped CPU default (about 10x cheaper per sample than the full widths at the same input).
CPU_WIDTHS = (16, 32, 64, 128)


@dataclass(frozen=True)
class NetConfig:
    """Architecture and input layout; stored in the weights' sidecar."""

    n_outputs: int
    in_channels: int = 2  # paper colour marking: [other objects, marked object]
    widths: tuple[int, int, int, int] = CPU_WIDTHS
    blocks: tuple[int, int, int, int] = (2, 2, 2, 2)
    dropout: float = 0.1
    resolution: int = 32
    frames: int = 15  # per sequence, after temporal subsampling

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> NetConfig:
        d = dict(d)
        for k in ("widths", "blocks"):
            if k in d:
                d[k] = tuple(d[k])
        return cls(**d)


def build_net(cfg: NetConfig) -> Any:
    """A fresh ``torch.nn.Module`` for ``cfg`` (torch imported here, lazily)."""
    import torch
    from torch import nn

    class Block(nn.Module):
        def __init__(self, cin: int, cout: int, stride: int) -> None:
            super().__init__()
            self.conv1 = nn.Conv3d(cin, cout, 3, stride, 1)
            self.conv2 = nn.Conv3d(cout, cout, 3, 1, 1)
            self.drop = nn.Dropout3d(cfg.dropout)
            self.act = nn.ReLU(inplace=True)
            # Average before subsampling the shortcut: a strided 1x1 conv would drop 7 of 8 voxels,
            # and objects here are a few pixels wide, so the shortcut would lose them entirely.
            if stride != 1:
                self.skip: nn.Module = nn.Sequential(
                    nn.AvgPool3d(stride, stride, ceil_mode=True), nn.Conv3d(cin, cout, 1)
                )
            elif cin != cout:
                self.skip = nn.Conv3d(cin, cout, 1)
            else:
                self.skip = nn.Identity()

        def forward(self, x: torch.Tensor) -> torch.Tensor:
            y = self.act(self.conv1(x))
            y = self.drop(self.conv2(y))
            return self.act(y + self.skip(x))

    class ResNet3D(nn.Module):
        def __init__(self) -> None:
            super().__init__()
            w = cfg.widths
            self.stem = nn.Sequential(
                nn.Conv3d(cfg.in_channels, w[0], (3, 5, 5), (1, 2, 2), (1, 2, 2)),
                nn.ReLU(inplace=True),
            )
            layers: list[nn.Module] = []
            cin = w[0]
            for i, (cout, n) in enumerate(zip(w, cfg.blocks, strict=True)):
                for j in range(n):
                    layers.append(Block(cin, cout, 2 if (j == 0 and i > 0) else 1))
                    cin = cout
            self.layers = nn.Sequential(*layers)
            self.head = nn.Linear(cin, cfg.n_outputs)
            for m in self.modules():
                if isinstance(m, nn.Conv3d):
                    nn.init.kaiming_normal_(m.weight, nonlinearity="relu")
                    nn.init.zeros_(m.bias)
            # Without batch norm, scale residual branches down so deep sums start near identity.
            for m in self.layers:
                with torch.no_grad():
                    m.conv2.weight.mul_(0.2)
            nn.init.zeros_(self.head.bias)
            nn.init.normal_(self.head.weight, std=1e-3)

        def forward(self, x: torch.Tensor) -> torch.Tensor:
            x = self.layers(self.stem(x))
            return self.head(x.mean(dim=(2, 3, 4)))

    return ResNet3D()
