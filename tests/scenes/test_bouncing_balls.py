"""bouncing_balls: 2-6 unknown balls drawn from the seed (or given), named and racked in order, on
a table without gravity bounded by four cushions."""

from __future__ import annotations

import pytest

from physbench.scenes import bouncing_balls


def test_counts() -> None:
    counts = {bouncing_balls.generate(seed).meta["n_balls"] for seed in range(40)}
    assert counts == {2, 3, 4, 5, 6}
    for n in range(2, 7):
        scene = bouncing_balls.generate(3, n_balls=n)
        assert [b.name for b in scene.bodies] == ["test", *(f"b{i}" for i in range(n))]
        assert [u.key for u in scene.unknowns] == [f"b{i}.mass" for i in range(n)]
        assert scene.gravity == (0.0, 0.0) and len(scene.statics) == 4
    with pytest.raises(ValueError, match="n_balls"):
        bouncing_balls.generate(0, n_balls=7)
