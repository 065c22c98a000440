"""The Kaheman pendulum loader on the shipped copy: windows, chained arms, and periods
and damping that agree with the provenance."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from physbench.datasets import load
from physbench.datasets.oscillation import oscillation_centre, oscillation_periods, swing_peaks
from physbench.recording import Recording, Track
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_kaheman_single_pendulum_period_and_damping(check_run, early):
    (run,) = load("pendulum_kaheman")
    check_run(run)
    tr = run.recording.track("arm1")
    assert len(tr) == 5501 and tr.t[-1] == pytest.approx(55.0)
    periods = oscillation_periods(tr.t, tr.angle)
    assert 0.90 < periods[0] < 0.95 and 0.77 < periods[-1] < 0.80  # amplitude-dependent period
    _, amp = swing_peaks(tr.t, tr.angle)
    assert 1.5 < amp[0] < 1.7 and 0.2 < amp[-1] < 0.3
    per_cycle = -np.diff(amp[::2])
    assert per_cycle[:3].mean() > 2.5 * per_cycle[-5:].mean()  # not purely viscous
    assert abs(oscillation_centre(tr.t, tr.angle)) < 0.01
    # the plain model with the authors' geometry follows the first swings
    traj = PymunkSimulator().simulate(replace(run.scene, frames=201))
    assert early(run.recording, "arm1", 2.0).rms(traj)["angle"] < 0.1


def test_kaheman_double_pendulum_windows_are_chained_arms(check_run):
    runs = load("pendulum_kaheman", arms=2, duration=2.0, windows=3)
    assert [r.name for r in runs] == ["2arm/0s", "2arm/2s", "2arm/4s"]
    for run in runs:
        check_run(run)
        s = run.scene
        assert [(j.a, j.b) for j in s.joints] == [("arm1", None), ("arm2", "arm1")]
        traj = PymunkSimulator().simulate(replace(s, frames=2))
        # frame 0 reproduces the recorded first sample exactly: angles and implied positions
        first = Recording(
            {
                b: Track(tr.t[:1], tr.x[:1], tr.y[:1], tr.angle[:1])
                for b, tr in run.recording.tracks.items()
            }
        )
        np.testing.assert_allclose(
            first.residuals(traj, fields=["x", "y", "angle"]), 0.0, atol=1e-9
        )
