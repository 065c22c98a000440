"""``npe``: the amortized posterior. A network trained once per scene and unknown set
(``physbench train --posterior``) maps the observation to a posterior in milliseconds, with no
simulation; the loop then refines its median with resnet3d's corrections where those exist."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator
from physbench.estimators.options import int_option

if TYPE_CHECKING:
    from physbench.estimators.base import Step, Task
    from physbench.posterior.samples import Posterior
    from physbench.unknowns import Params


class NPEEstimator(CorrectionEstimator):
    """Neural posterior estimation on the marked views (one body at a time; see
    :mod:`physbench.estimators.npe.features` for the embedding and why it is not the paper's
    3D-ResNet). Each unknown body's posterior comes from its own marked view, and the joint is
    their product: correlations *between* bodies' unknowns (e.g. two masses known only as a ratio)
    are not represented.

    ``start`` computes the posterior; the first ``propose`` returns its median (the loop's first
    simulation is its initial guess, so the median is the second); later ones hand over to
    resnet3d's corrections from the last simulation when resnet3d weights exist for the scene and
    unknowns (``refine=False`` keeps returning the median). Options: ``weights`` (an npe
    .safetensors path; default: the shipped or ``PHYSBENCH_NPE_WEIGHTS`` weights for the scene and
    unknowns), ``samples`` (posterior draws, default 1000), ``threads`` (torch threads, default 1),
    ``refine`` (default true).
    """

    name: ClassVar[str] = "npe"
    per_object: ClassVar[bool] = True
    requires: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"torch": "physbench[learn]", "safetensors": "physbench[learn]"}
    )

    def __init__(
        self, weights: str | None = None, samples: int = 1000, threads: int = 1, refine: bool = True
    ) -> None:
        self.weights_path = weights
        self.samples = int_option("npe", "samples", samples, low=2)
        self.threads = int_option("npe", "threads", threads, low=0)
        if not isinstance(refine, bool):
            raise PhysbenchError(f"npe: refine = {refine!r}: expected true or false")
        self.refine = refine
        self.options = {
            "weights": weights,
            "samples": samples,
            "threads": threads,
            "refine": refine,
        }
        self._posterior: Posterior | None = None

    def start(self, task: Task, *, seed: int) -> None:
        import torch

        from physbench.estimators.npe import weights
        from physbench.estimators.npe.features import (
            DEFAULT_THRESHOLD,
            DISTANCE,
            distance,
            summarize,
        )
        from physbench.estimators.npe.network import sample_unit
        from physbench.posterior.domain import TrainingDomain
        from physbench.posterior.samples import Posterior

        if self.threads:
            torch.set_num_threads(self.threads)
        params = tuple(dict.fromkeys(u.name for u in task.space.unknowns))
        path = self.weights_path or weights.find(task.scene.name, params)
        members, meta = weights.load(path)
        data = meta["data"]
        if sorted(data["params"]) != sorted(params):
            raise PhysbenchError(
                f"npe weights {str(path)!r} were trained for {'+'.join(data['params'])}, the task "
                f"asks for {'+'.join(sorted(params))}"
            )
        rendered_by = None if task.renderer is None else type(task.renderer).name
        if rendered_by not in (None, data["renderer"]):
            raise PhysbenchError(
                f"npe weights {str(path)!r} were trained on frames of renderer "
                f"{data['renderer']!r}; this run renders with {rendered_by!r} (choose --renderer "
                f"{data['renderer']} or train npe weights for it)"
            )
        by_key = {u.key: u for u in task.space.unknowns}
        rng = np.random.default_rng([seed, 23])
        unit = np.empty((self.samples, len(task.space)))
        index = {k: j for j, k in enumerate(task.space.keys)}
        # Every member standardizes with the training set's feature mean and spread.
        mean = members[0].feature_mean.double().numpy()
        std = members[0].feature_std.double().numpy()
        far = 0.0
        for body in task.space.bodies:
            keys = [f"{body}.{p}" for p in data["params"]]
            for k, p in zip(keys, data["params"], strict=True):
                if k not in by_key:
                    raise PhysbenchError(f"body {body!r} lacks the unknown {k!r} the weights give")
                lo, hi = meta["ranges"][p]
                if (by_key[k].low, by_key[k].high) != (lo, hi):
                    # The net's unit space is the training range: another range shifts it.
                    raise PhysbenchError(
                        f"npe weights {str(path)!r} were trained for {p} in [{lo}, {hi}]; the "
                        f"task's {k} ranges over [{by_key[k].low}, {by_key[k].high}]"
                    )
            if body not in task.marked_observation:
                raise PhysbenchError(
                    f"npe needs the observation with {body!r} marked (frames rendered with "
                    f"focus={body!r}); give marked_<body> arrays in the observation file"
                )
            feats = summarize(task.marked_observation[body], int(data["frames"]))
            far = max(far, float(distance(feats, mean, std)))
            draws = sample_unit(members, feats, self.samples, rng)
            for j, k in enumerate(keys):
                unit[:, index[k]] = draws[:, j]
        threshold = float(meta.get("domain", {}).get("threshold", DEFAULT_THRESHOLD))
        self._posterior = Posterior.from_unit(
            task.space,
            unit,
            "npe",
            note="product over bodies of per-body amortized posteriors",
            domain=TrainingDomain(far, threshold, f"{DISTANCE} (the farthest marked view)"),
        )
        self.space = task.space
        self.proposed = 0
        self.corrector: CorrectionEstimator | None = None
        if self.refine:
            self.corrector = _resnet3d(task, seed)

    def propose(self, step: Step) -> Params:
        if self._posterior is None:
            raise PhysbenchError("npe: propose() called before start()")
        self.proposed += 1
        if self.proposed == 1 or self.corrector is None:
            return self.space.clip(self._posterior.median())
        return self.corrector.propose(step)

    def posterior(self) -> Posterior | None:
        return self._posterior


def _resnet3d(task: Task, seed: int) -> CorrectionEstimator | None:
    """resnet3d started on ``task`` when it has weights for the scene and unknowns, else None."""
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator

    corrector = ResNet3DEstimator()
    try:
        corrector.start(task, seed=seed)
    except PhysbenchError:
        return None
    return corrector
