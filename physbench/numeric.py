"""Every number a user hands physbench, checked one way: a command-line flag, a ``run()`` or
``discover_effects()`` keyword, a field of :class:`~physbench.experiment.RunConfig` or of
:class:`~physbench.discover.Settings`, a sweep spec's value.

A :class:`Number` is an accepted range: whole or not, its ends (open or closed, or none), and
always finite (NaN and the infinities are never a setting: a NaN threshold compares false with
everything, so it silently switches off what it guards). The same object parses a flag (it is an
argparse ``type=``, so ``--floor nan`` is refused while parsing) and checks a value from Python
(:meth:`Number.check`), and every refusal names the value and what is accepted. The named ranges
below are those several places share; the limits they use are in :mod:`physbench.limits`.

Only the standard library is imported, so that building the command's parser stays fast.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass

from physbench.errors import PhysbenchError
from physbench.limits import (
    MAX_LANDSCAPE_SEEDS,
    MAX_NOISE,
    MAX_RESOLUTION,
    MAX_SEED,
    MAX_WORKERS,
)


def _g(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


@dataclass(frozen=True)
class Number:
    """The numbers in ``[low, high]`` (``None``: no bound on that side; ``low_open`` /
    ``high_open``: that end excluded), whole numbers only with ``whole``; finite always.
    ``unit`` is said in the refusal. Called with a string, it is an argparse ``type=``."""

    low: float | None = None
    high: float | None = None
    whole: bool = False
    low_open: bool = False
    high_open: bool = False
    unit: str = ""

    def describe(self) -> str:
        """What is accepted, in words: ``a whole number in [0, 4294967295]``, ``a finite number
        >= 0 (m)``."""
        what = "a whole number" if self.whole else "a finite number"
        lo, hi = self.low, self.high
        if lo is not None and hi is not None:
            span = (
                f" in {'(' if self.low_open else '['}{_g(lo)}, {_g(hi)}"
                f"{')' if self.high_open else ']'}"
            )
        elif lo is not None:
            span = f" {'>' if self.low_open else '>='} {_g(lo)}"
        elif hi is not None:
            span = f" {'<' if self.high_open else '<='} {_g(hi)}"
        else:
            span = ""
        return what + span + (f" ({self.unit})" if self.unit else "")

    def accepts(self, value: object) -> bool:
        """Whether ``value`` (a Python number; never a bool) lies in the range."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        if self.whole and not isinstance(value, int):
            return False
        if isinstance(value, float) and not math.isfinite(value):
            return False
        lo, hi = self.low, self.high
        if lo is not None and (value <= lo if self.low_open else value < lo):
            return False
        return not (hi is not None and (value >= hi if self.high_open else value > hi))

    def check(
        self, value: object, name: str, error: type[PhysbenchError] = PhysbenchError
    ) -> int | float:
        """``value`` when the range accepts it (a whole number as ``int``), else ``error``
        naming ``name``, the value and the range; called by the API's and the specs' checks."""
        if not self.accepts(value):
            raise error(f"{name} = {value!r}: expected {self.describe()}")
        return int(value) if self.whole else value  # type: ignore[arg-type]

    def parse(self, text: str) -> int | float:
        """The number ``text`` spells, when the range accepts it; else :class:`ValueError` with
        the sentence of a refusal (``'a' is not a whole number >= 1``)."""
        try:
            value: int | float = int(text) if self.whole else float(text)
        except (ValueError, TypeError):
            raise ValueError(f"{text!r} is not {self.describe()}") from None
        if not self.accepts(value):
            shown = value if self.whole else text.strip()
            raise ValueError(f"{shown} is not {self.describe()}")
        return value

    def __call__(self, text: str) -> int | float:
        """argparse's ``type=``: the refusal becomes ``argument --flag: <sentence>``."""
        try:
            return self.parse(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None


def whole(low: int | None = None, high: int | None = None) -> Number:
    """Whole numbers in ``[low, high]``."""
    return Number(low, high, whole=True)


def finite(
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
) -> Number:
    """Finite numbers between ``low`` and ``high``."""
    return Number(low, high, low_open=low_open, high_open=high_open, unit=unit)


#: Any finite number (a parameter value set by ``--set``, an effect's value).
ANY = finite()
#: Seeds: what numpy, random, torch and optuna all accept.
SEED = whole(0, MAX_SEED)
#: Frame widths in pixels.
RESOLUTION = whole(1, MAX_RESOLUTION)
#: Counts of at least one (iterations, causes, validation groups).
COUNT = whole(1)
#: Counts where 0 means none (threads, evaluation seeds).
COUNT_OR_NONE = whole(0)
#: Local worker processes of a sweep.
WORKERS = whole(1, MAX_WORKERS)
#: Scene instances averaged by the image-MSE landscape (0: no landscape).
LANDSCAPE_SEEDS = whole(0, MAX_LANDSCAPE_SEEDS)
#: Gaussian blur of an observation, in pixels (at most a frame's width).
BLUR = finite(0, MAX_RESOLUTION)
#: Gaussian pixel noise (standard deviation on pixel values in [0, 1]).
NOISE = finite(0, MAX_NOISE)
#: Non-negative finite numbers (a measurement floor, a BIC drop, minutes).
NON_NEGATIVE = finite(0)
#: Positive finite numbers (a threshold, a step).
POSITIVE = finite(0, low_open=True)
#: A share of something that must leave some of it (a gain, a closeness factor).
SHARE = finite(0, 1, high_open=True)
#: A significance level.
LEVEL = finite(0, 1, low_open=True, high_open=True)
#: Seconds into a video.
SECONDS = finite(0, unit="s")
#: A measurement floor, in metres.
FLOOR = finite(0, unit="m")
#: The share of a discovery's data held out.
HOLDOUT = finite(0.05, 0.8)
#: A learning rate.
LEARNING_RATE = finite(0, 1, low_open=True)
#: A ratio of errors that counts as a change (new / baseline).
RATIO = finite(1)
