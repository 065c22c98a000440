"""What the data can see of each parameter (physbench/discover/sensitivity.py)."""

from __future__ import annotations

from physbench.discover import Run, Settings
from physbench.discover.pipeline import problem_for, start_model
from physbench.discover.sensitivity import prune_nuisance, visible
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_nuisance_the_data_cannot_see_is_dropped(slide, noisy):
    scene = slide()
    rec = noisy(PymunkSimulator().simulate(scene), fields=("y",))  # tracked in y only
    s = Settings()
    start = start_model(problem_for([Run("r", scene, recording=rec)], "pymunk", s), s)
    assert [p.name for p in start.params] == ["x0", "y0", "vx0", "vy0"]
    assert visible(start, "ball.y0") and not visible(start, "ball.x0")
    pruned = prune_nuisance(start)
    assert [p.name for p in pruned.params] == ["y0", "vy0"]
    assert pruned.values == {k: start.values[k] for k in ("ball.y0", "ball.vy0")}
