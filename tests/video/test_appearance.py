"""A body's appearance: a detection of another size or colour is not the body."""

from __future__ import annotations

import numpy as np

from physbench.video.appearance import Appearance, Look


def test_another_size_or_colour_is_named_and_shading_is_not() -> None:
    red = Appearance.first(Look(1.0, np.array([180.0, 30.0, 25.0])))
    assert red.mismatch(Look(1.2, np.array([120.0, 20.0, 17.0]))) is None  # in the shade
    assert red.mismatch(Look(3.0, np.array([180.0, 30.0, 25.0]))) == "3.00 times its size"
    skin = Look(1.1, np.array([205.0, 160.0, 130.0]))
    assert red.mismatch(skin).startswith("another colour")  # a hand
    grey = Appearance.first(Look(1.0, np.array([120.0, 120.0, 125.0])))
    assert grey.mismatch(Look(1.0, np.array([30.0, 30.0, 32.0]))).endswith("its brightness")
    for _ in range(30):  # it follows slow changes
        red.update(Look(1.3, np.array([160.0, 35.0, 30.0])))
    assert abs(red.size - 1.3) < 0.02


def test_a_body_of_a_few_pixels_is_judged_by_its_size_alone() -> None:
    # A 3.7 px ball on a brick wall: its first look was 0-3 grey levels, the next 90-170; judged
    # by colour it was rejected in 39 of 41 frames of a filmed projectile.
    speck = Appearance.first(Look(0.9, np.array([3.0, 1.0, -1.0]), pixels=3.7))
    assert speck.mismatch(Look(0.8, np.array([155.0, 131.0, 120.0]), pixels=3.7)) is None
    assert speck.mismatch(Look(9.0, np.array([3.0, 1.0, -1.0]), pixels=3.7)).endswith("its size")
    ball = Appearance.first(Look(0.9, np.array([3.0, 1.0, -1.0]), pixels=400.0))
    assert ball.mismatch(Look(0.8, np.array([155.0, 131.0, 120.0]), pixels=400.0)) is not None
