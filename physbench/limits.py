"""Limits on inputs, shared by every place that checks them: the CLI's argument types, sweep
specs and the Python API. Plain numbers, so that building a parser imports nothing else."""

from __future__ import annotations

#: The widest frame in pixels: a (T, C, H, W) float32 sequence at 4096 px already takes GiBs.
MAX_RESOLUTION = 4096
#: Seeds go to numpy, random, torch and optuna; this is the range all of them accept.
MAX_SEED = 2**32 - 1
#: The widest pixel noise (standard deviation on [0, 1] values): beyond it every pixel is clipped
#: to 0 or 1.
MAX_NOISE = 1.0
#: The longest ``--scene``: Linux's PATH_MAX (a longer path cannot name a file).
MAX_SCENE_ARGUMENT = 4096
#: The most local worker processes of a sweep (each a Python interpreter of ~100 MB with its
#: libraries loaded): well above the cores of one machine.
MAX_WORKERS = 512
#: The most scene instances the image-MSE landscape averages (each simulates the scene ~40 times
#: per parameter): a figure's mean is steady long before.
MAX_LANDSCAPE_SEEDS = 100
