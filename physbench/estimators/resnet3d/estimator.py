"""The learned correction estimator: p(k+1) = p(k) + Δp, Δp = net(observed, simulated)."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator, Step, Task
from physbench.unknowns import Params

if TYPE_CHECKING:
    from physbench.posterior.samples import Posterior


class ResNet3DEstimator(CorrectionEstimator):
    """3D-ResNet correction estimator (paper). Marks one unknown body at a time and batches all
    marked bodies into one forward pass (the loop renders each marked view).

    Options: ``weights`` (a .safetensors path; default: the shipped or ``PHYSBENCH_WEIGHTS``
    weights matching the scene and unknowns), ``threads`` (torch threads for inference, set
    process-wide; 1 keeps parallel runs from oversubscribing the cores, 0 = torch's default),
    ``symmetric`` (also feed the pair swapped and use ``(f(obs, sim) - f(sim, obs)) / 2``: the truth
    becomes an exact fixed point, so with an observation from the model's own renderer the loop
    converges to 1e-7-1e-5 instead of 2e-5-2e-4; off by default because it hurts on blurred
    observations, which the network only ever saw in the observed slot), ``any_renderer`` (accept
    frames of a renderer other than the one the weights were trained on; off by default, since the
    weights were never validated on such frames), ``posterior_samples`` (0: a point only; N: after
    the run, N forward passes with the network's dropout left on, applied to the last iterate,
    give a posterior -- Monte Carlo dropout, the corrector's own uncertainty; it is not calibrated
    by construction, see docs/posterior.md for what was measured).
    """

    name: ClassVar[str] = "resnet3d"
    per_object: ClassVar[bool] = True
    requires: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"torch": "physbench[learn]", "safetensors": "physbench[learn]"}
    )

    def __init__(
        self,
        weights: str | None = None,
        threads: int = 1,
        symmetric: bool = False,
        any_renderer: bool = False,
        posterior_samples: int = 0,
    ) -> None:
        from physbench.estimators.options import int_option

        self.posterior_samples = int_option(
            self.name, "posterior_samples", posterior_samples, low=0
        )
        self.weights_path, self.threads, self.symmetric = weights, threads, symmetric
        self.any_renderer = any_renderer
        self.options = {
            "weights": weights,
            "threads": threads,
            "symmetric": symmetric,
            "any_renderer": any_renderer,
            "posterior_samples": self.posterior_samples,
        }
        self.last: tuple[np.ndarray, dict[str, float]] | None = None
        self.targets: list[tuple[str, list[str], np.ndarray]] | None = None

    def start(self, task: Task, *, seed: int) -> None:
        import torch

        from physbench.estimators.resnet3d import weights
        from physbench.estimators.resnet3d.network import NetConfig, build_net
        from physbench.estimators.resnet3d.training_data import DataSpec

        params = tuple(dict.fromkeys(u.name for u in task.space.unknowns))
        if self.weights_path:
            state, meta = weights.load(self.weights_path)
            trained_for = tuple(sorted(meta["data"]["params"]))
            if trained_for != tuple(sorted(params)):
                raise PhysbenchError(
                    f"weights {self.weights_path!r} were trained for {'+'.join(trained_for)}, "
                    f"the task asks for {'+'.join(sorted(params))}"
                )
        else:
            info = weights.find(task.scene.name, params)
            state, meta = weights.load(info.path)
        self.params = tuple(meta["data"]["params"])
        trained_on = DataSpec.from_dict(meta["data"]).renderer
        rendered_by = None if task.renderer is None else type(task.renderer).name
        if rendered_by not in (None, trained_on) and not self.any_renderer:
            raise PhysbenchError(
                f"resnet3d weights for {task.scene.name} were trained on frames of renderer "
                f"{trained_on!r}; this run renders with {rendered_by!r} (choose --renderer "
                f"{trained_on}, train weights for it with physbench train --renderer, or accept "
                "it with -o any_renderer=true)"
            )
        if self.threads:
            torch.set_num_threads(self.threads)
        torch.manual_seed(seed)
        self.cfg = NetConfig.from_dict(meta["net"])
        self.net = build_net(self.cfg)
        self.net.load_state_dict({k: v.float() for k, v in state.items()})
        self.net.eval()
        self.space = task.space
        self.observed: dict[str, np.ndarray] = dict(task.marked_observation)
        # Per unknown body: its unknown keys in the network's output order and their range widths.
        self.targets: list[tuple[str, list[str], np.ndarray]] = []
        for body in task.space.bodies:
            sub = task.space.subset(body)
            keys = [f"{body}.{p}" for p in self.params]
            missing = [k for k in keys if k not in sub.keys]
            if missing:
                raise PhysbenchError(f"body {body!r} lacks unknowns {missing} the weights predict")
            if body not in self.observed:
                raise PhysbenchError(
                    f"resnet3d needs the observation with {body!r} marked (frames rendered with "
                    f"focus={body!r}); "
                    "give marked_<body> arrays in the observation file"
                )
            by_key = {u.key: u for u in sub.unknowns}
            self.targets.append(
                (body, keys, np.array([by_key[k].high - by_key[k].low for k in keys]))
            )

    def propose(self, step: Step) -> Params:
        import torch

        from physbench.estimators.resnet3d.inputs import make_input

        if self.targets is None:
            raise PhysbenchError("resnet3d: propose() called before start()")
        marked = step.marked
        if not marked:
            raise PhysbenchError(
                "resnet3d corrects one marked object at a time: the loop must pass marked frames"
            )
        x = np.stack(
            [
                make_input(self.observed[body], marked[body], self.cfg.frames, self.cfg.resolution)
                for body, _, _ in self.targets
            ]
        )
        if self.symmetric:
            # Swapped order predicts -Δp; averaging both halves the variance of independent errors.
            x = np.concatenate(
                [
                    x,
                    np.concatenate(
                        [x[:, :, self.cfg.frames :], x[:, :, : self.cfg.frames]], axis=2
                    ),
                ]
            )
        self.last = (x, dict(step.params))
        with torch.no_grad():
            delta = self.net(torch.from_numpy(x)).numpy().astype(float)
        if self.symmetric:
            n = len(self.targets)
            delta = 0.5 * (delta[:n] - delta[n:])
        new = dict(step.params)
        for (_, keys, scale), d in zip(self.targets, delta, strict=True):
            for k, s, dk in zip(keys, scale, d, strict=True):
                new[k] = step.params[k] + dk * s
        return self.space.clip(new)

    def posterior(self) -> Posterior | None:
        """Called once after the run: with ``posterior_samples`` N > 0, N corrections of the last
        iterate with dropout on (the same input each time, a fresh dropout mask per pass); else
        ``None``."""
        import torch

        from physbench.posterior.samples import Posterior

        if not self.posterior_samples or self.last is None:
            return None
        x, params = self.last
        n = len(self.targets)
        if self.symmetric:
            x = x[:n]  # the swapped half would double the cost for the same spread
        self.net.train()  # dropout on; the network has no batch norm, so nothing else changes
        deltas = []
        try:
            with torch.no_grad():
                for _ in range(self.posterior_samples):
                    deltas.append(self.net(torch.from_numpy(x)).numpy().astype(float))
        finally:
            self.net.eval()
        keys = list(self.space.keys)
        samples = np.tile([params[k] for k in keys], (self.posterior_samples, 1))
        col = {k: j for j, k in enumerate(keys)}
        for i, (_, tkeys, scale) in enumerate(self.targets):
            for m, (k, s) in enumerate(zip(tkeys, scale, strict=True)):
                samples[:, col[k]] += np.array([d[i, m] for d in deltas]) * s
        low, high = self.space.low, self.space.high
        return Posterior(
            keys=tuple(keys),
            samples=np.clip(samples, low, high),
            low=tuple(float(v) for v in low),
            high=tuple(float(v) for v in high),
            method="resnet3d MC dropout",
        )


def info() -> dict[str, Any]:
    """Shipped and user weights, for ``physbench plugins``-style listings."""
    from physbench.estimators.resnet3d import weights

    return {f"{w.scene}[{'+'.join(w.params)}]": str(w.path) for w in weights.available()}
