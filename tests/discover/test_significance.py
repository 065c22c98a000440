"""When a candidate is a cause (physbench/discover/significance.py)."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from physbench.discover import CandidateResult, FitResult, Scored, Settings
from physbench.discover.data import DiscoverError
from physbench.discover.significance import floored_gain, judge, measurement_floor
from physbench.recording import Recording, RecordingError, Track


def scored(heldout: float, ssr: float, k: int, n: int = 100) -> Scored:
    fit = FitResult({}, [f"p{i}" for i in range(k)], {}, ssr, n, 1, 1, "")
    return Scored("m", (), None, fit, heldout, 30)  # type: ignore[arg-type]  # no model needed


def candidate(heldout: float, criterion: float) -> CandidateResult:
    return CandidateResult(1, "e", "e", {}, {}, {}, heldout, 0.0, 0.0, criterion, 0.0, False)


def test_a_cause_must_gain_on_held_out_data_and_lower_the_bic():
    base, current = scored(2.0, 4.0, 3), scored(1.0, 1.0, 4)
    bic = 100 * math.log(1.0 / 100) + 4 * math.log(100)
    assert current.bic == pytest.approx(bic)
    c = judge(candidate(0.8, bic - 20), current, base, Settings())
    assert c.significant and c.note == "" and c.previous is current
    assert c.gain == pytest.approx(0.2) and c.gain_vs_base == pytest.approx(0.6)
    assert c.delta_criterion == pytest.approx(-20)

    small = judge(candidate(0.95, bic - 20), current, base, Settings())
    assert not small.significant and small.note == "held-out gain +5.0% < 10%"
    flat = judge(candidate(0.5, bic - 5), current, base, Settings())
    assert not flat.significant and flat.note == "ΔBIC -5.0 > -10"
    # the thresholds are settings
    assert judge(
        candidate(0.95, bic - 5), current, base, Settings(min_gain=0.04, min_delta_bic=4)
    ).significant


def test_judging_returns_a_new_result():
    c = candidate(0.8, -500.0)
    judged = judge(c, scored(1.0, 1.0, 4), scored(2.0, 4.0, 3), Settings())
    assert judged is not c and c.gain == 0.0 and c.previous is None


def test_a_gain_below_the_datas_accuracy_is_no_evidence():
    # Held-out RMS 1.2 mm -> 0.4 mm is a 67 % gain; against a tracker accurate to 2 mm it is
    # 1 - hypot(0.4, 2) / hypot(1.2, 2) = 13 %, and against 3 mm 6 %: not a cause.
    current, base = scored(1.2e-3, 1.0, 4), scored(1.2e-3, 1.0, 4)
    bic = current.bic - 50
    assert judge(candidate(0.4e-3, bic), current, base, Settings()).significant
    coarse = judge(candidate(0.4e-3, bic), current, base, Settings(floor=3e-3))
    assert not coarse.significant
    assert coarse.note == "held-out gain above the data's accuracy 0.003 +6.3% < 10%"
    assert coarse.gain == pytest.approx(2 / 3)  # the reported gain stays the plain one
    assert floored_gain(0.4e-3, 1.2e-3, 2e-3) == pytest.approx(0.1255, abs=1e-4)
    assert floored_gain(0.4, 1.2, 0.0) == pytest.approx(2 / 3)
    with pytest.raises(DiscoverError, match="floor = -1"):
        Settings(floor=-1)


def test_a_measurement_effect_within_the_datas_accuracy_is_not_a_cause():
    # A sensor offset of 0.9 mm that fits well is the tracker's own bias where the recording
    # states 2.9 mm (a bouncing ball on the second camera), a cause where it states 0.5 mm.
    track = Track(np.arange(3.0), np.zeros(3), np.zeros(3))

    def current(accuracy: float, angle_accuracy: float = 0.0) -> Scored:
        rec = Recording({"b": track}, accuracy=accuracy, angle_accuracy=angle_accuracy)
        problem = SimpleNamespace(runs=[SimpleNamespace(recording=rec)])
        plain = scored(1.0, 1.0, 4)
        return replace(plain, model=SimpleNamespace(problem=problem))  # type: ignore[arg-type]

    bic = scored(1.0, 1.0, 4).bic - 50
    offset = replace(candidate(0.4, bic), shift=(0.9e-3, 0.0))
    base = scored(2.0, 4.0, 3)
    coarse = judge(offset, current(2.9e-3), base, Settings())
    assert not coarse.significant
    assert coarse.note == (
        "it moves a recorded position by 0.0009 m at most, within the data's accuracy "
        "(0.0029 m): the tracker could make it"
    )
    assert judge(offset, current(0.5e-3), base, Settings()).significant
    assert not judge(offset, current(0.5e-3), base, Settings(floor=1e-3)).significant
    # an angle moved by more than the angle accuracy is beyond the data's own error
    turned = replace(offset, shift=(0.9e-3, 0.05))
    assert judge(turned, current(2.9e-3, 0.01), base, Settings()).significant
    assert not judge(turned, current(2.9e-3, 0.1), base, Settings()).significant
    # data that states no accuracy, and effects on the motion, are judged as before
    assert judge(offset, current(0.0), base, Settings()).significant
    assert judge(candidate(0.4, bic), current(2.9e-3), base, Settings()).significant


def test_the_floor_is_the_largest_accuracy_the_recordings_state():
    track = Track(np.arange(3.0), np.zeros(3), np.zeros(3))
    runs = [
        SimpleNamespace(recording=Recording({"b": track}, accuracy=a)) for a in (0.0, 2e-3, 1e-3)
    ]
    problem = SimpleNamespace(runs=[*runs, SimpleNamespace(recording=None)])  # frames: no say
    assert measurement_floor(problem, Settings()) == 2e-3
    assert measurement_floor(problem, Settings(floor=0.0)) == 0.0
    assert measurement_floor(None, Settings()) == 0.0
    with pytest.raises(RecordingError, match=r"accuracy = -0\.1"):
        Recording({"b": track}, accuracy=-0.1)


def test_where_only_angles_were_measured_the_floor_is_the_angle_accuracy() -> None:
    # the residuals of angle-only data are radians: a tracker's metres are not their floor
    track = Track(np.arange(3.0), np.zeros(3), np.zeros(3), np.zeros(3))

    def problem(*fields: tuple[str, ...] | None) -> SimpleNamespace:
        return SimpleNamespace(
            runs=[
                SimpleNamespace(
                    recording=Recording({"b": track}, fields=f, accuracy=1e-3, angle_accuracy=a)
                )
                for f, a in zip(fields, (3e-3, 5e-3), strict=False)
            ]
        )

    assert measurement_floor(problem(("angle",)), Settings()) == 3e-3
    assert measurement_floor(problem(("angle",), ("angle",)), Settings()) == 5e-3
    assert measurement_floor(problem(("angle",), ("x", "y", "angle")), Settings()) == 1e-3
    assert measurement_floor(problem(None), Settings()) == 1e-3  # x, y and angle held
    assert measurement_floor(problem(("angle",)), Settings(floor=0.0)) == 0.0
