"""Posteriors: samples over a run's unknowns, the image likelihood, scoring against truths
(coverage, SBC) and the identifiability probe."""

from physbench.posterior.samples import Posterior

__all__ = ["Posterior"]
