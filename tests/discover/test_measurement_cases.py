"""A subset of the measurement benchmark (benchmarks/discover_measurement.py), run live: a recording
distorted by a measurement error and no force must name no physical cause alone, and list a
measurement cause unless it names nothing (a distortion within the noise); a real force of the
same size, with scale and clock fixed by a reference, must be named first
(physbench/discover/synthetic.py: ``measurement_case``, ``judge_measurement``).
"""

from __future__ import annotations

import pytest

from physbench.discover import discover
from physbench.discover.synthetic import (
    DISTORTIONS,
    REAL_FORCES,
    REAL_REFERENCES,
    judge_measurement,
    measurement_case,
)
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
CASES = [
    ("measurement", "projectile", "all", 3, "pymunk"),
    ("measurement", "projectile", "clock", 4, "box2d"),
    ("measurement", "puck_kicked", "rotation", 3, "box2d"),
    ("measurement", "puck_kicked", "scale", 4, "pymunk"),
    ("physical", "projectile", "constant_force", 3, "box2d"),
    ("physical", "projectile", "linear_drag", 4, "pymunk"),
    ("physical", "puck_kicked", "table_tilt", 4, "box2d"),
    ("physical", "puck_kicked", "linear_drag", 3, "pymunk"),
]


def test_the_cases_draw_what_the_benchmark_says():
    sim = PymunkSimulator()
    m = measurement_case("measurement", "projectile", "all", 0, sim)
    assert set(m.case.distortion) == {"calibration_scale", "clock_scale", "axis_rotation"}
    assert 0.01 <= abs(m.case.distortion["calibration_scale"]["scale"] - 1) <= 0.03
    assert 0.3 <= abs(m.case.distortion["axis_rotation"]["angle"]) * 180 / 3.14159 <= 1.0
    assert m.case.truth == {} and m.settings.references == ()
    p = measurement_case("physical", "puck_kicked", "table_tilt", 0, sim)
    assert p.case.distortion == {} and p.settings.references == REAL_REFERENCES
    assert 0.1 <= (p.case.truth["ax"] ** 2 + p.case.truth["ay"] ** 2) ** 0.5 <= 0.3
    assert set(DISTORTIONS) == {"scale", "clock", "rotation", "all"}
    assert set(REAL_FORCES) == {"projectile", "puck_kicked"}


@pytest.mark.parametrize(
    ("kind", "scene", "label", "seed", "engine"), CASES, ids=["/".join(map(str, c)) for c in CASES]
)
def test_measurement_error_or_real_force(kind, scene, label, seed, engine):
    sim = ENGINES[engine]()
    mc = measurement_case(kind, scene, label, seed, sim)
    disc = discover([mc.case.run], sim, settings=mc.settings, diagnose=False)
    got = judge_measurement(mc, disc)
    truth = mc.case.distortion or mc.case.truth
    if kind == "measurement":
        assert got["lists_measurement"] or not disc.causes, f"{truth}: causes {disc.causes}"
        assert not got["physical_alone"], f"{truth}: {got['physical_alone']} named alone"
    else:
        assert got["named_first"], f"{truth}: causes {disc.causes}"
        assert got["magnitude_error"] < 0.15
    assert got["ok"]
