"""docs/video.md's files work as printed: every TOML block is a calibration or a scene that
loads, the CSV of point pairs is the same calibration as the [[points]] block, and there is a
scene example for each setup ``physbench scene new`` writes."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from physbench.calibration import loads_calibration, loads_calibration_csv
from physbench.scene_toml import loads_scene
from physbench.scenes.setups import SETUPS

DOC = Path(__file__).resolve().parents[1] / "docs" / "video.md"
TEXT = DOC.read_text(encoding="utf-8")
TOML = re.findall(r"^```toml\n(.*?)^```", TEXT, re.S | re.M)


def test_every_toml_block_loads() -> None:
    scenes = [loads_scene(b, source="docs/video.md") for b in TOML if "[[bodies]]" in b]
    cals = [loads_calibration(b, source="docs/video.md") for b in TOML if "[[bodies]]" not in b]
    assert len(cals) == 4 and len(scenes) == len(SETUPS)
    assert sorted(s.name.removeprefix("my_") for s in scenes) == sorted(SETUPS)
    for s in scenes:
        s.validate()


def test_the_csv_of_points_is_the_points_block() -> None:
    (csv,) = re.findall(r"^```\n(u,v,x,y\n.*?)^```", TEXT, re.S | re.M)
    (points,) = [b for b in TOML if "[[points]]" in b]
    a, b = loads_calibration_csv(csv), loads_calibration(points)
    np.testing.assert_allclose(a.homography, b.homography, rtol=1e-9, atol=1e-12)
