"""Limits on inputs, shared by every place that checks them: the CLI's argument types, sweep
specs, scenes, recordings and the Python API. Plain numbers, so that building a parser imports
nothing else."""

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

# Scene limits (checked by physbench.scene), which recordings share: a recorded value beyond them
# cannot be compared with any scene, and squaring it overflows.
#: m: the largest |coordinate| of a bound, position, anchor or vertex (and of a recorded position);
#: far beyond any lab set-up.
MAX_COORDINATE = 1e6
#: Hz: the frame rates accepted, from a frame every 10 s to a high-speed camera's 100,000 fps.
FPS = (0.1, 100_000.0)
#: rad/s: the largest initial angular speed (about a million rpm).
MAX_SPIN = 1e5
#: Recorded frames: about an hour of video at 30 fps.
MAX_FRAMES = 100_000
#: s: the latest recorded time: about the longest a scene can simulate (MAX_FRAMES frames at the
#: lowest frame rate: 1e6 s, 11.6 days).
MAX_TIME = MAX_FRAMES / FPS[0]
#: rad: the largest |recorded angle|: a body turning at MAX_SPIN for MAX_TIME (angles may be
#: recorded unwrapped).
MAX_ANGLE = MAX_SPIN * MAX_TIME
