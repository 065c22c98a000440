"""Finding npe weights: a PHYSBENCH_NPE_WEIGHTS folder that holds no npe weights is an error
naming the folder and why, not a silent fall-back to the shipped weights."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.npe import weights

SHIPPED = weights.SHIPPED / "three_circles__mass.safetensors"


@pytest.mark.parametrize(
    ("fill", "why"),
    [
        (None, "which does not exist"),
        ([], r"which holds no npe weights \(no NAME.safetensors"),
        ([("w.json", "{not json")], r"'.*w.safetensors': .*is not valid JSON"),
        ([("w.json", '{"kind": "resnet3d"}')], r"its sidecar's kind is 'resnet3d', not 'npe'"),
    ],
)
def test_a_named_folder_without_npe_weights_is_an_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fill: list | None, why: str
) -> None:
    folder = tmp_path / "mine"
    if fill is not None:
        folder.mkdir()
        for name, text in fill:
            (folder / name).write_text(text)
            shutil.copy(SHIPPED, (folder / name).with_suffix(".safetensors"))
    monkeypatch.setenv("PHYSBENCH_NPE_WEIGHTS", str(folder))
    with pytest.raises(PhysbenchError) as exc:
        weights.find("three_circles", ("mass",))
    said = str(exc.value)
    assert said.startswith(f"PHYSBENCH_NPE_WEIGHTS names {str(folder)!r}, "), said
    assert re.search(why, said) and "`physbench train --posterior`" in said, said


def test_a_named_folder_with_npe_weights_is_searched_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for suffix in (".safetensors", ".json"):
        shutil.copy(SHIPPED.with_suffix(suffix), tmp_path / f"mine{suffix}")
    monkeypatch.setenv("PHYSBENCH_NPE_WEIGHTS", str(tmp_path))
    assert weights.find("three_circles", ("mass",)) == tmp_path / "mine.safetensors"
    monkeypatch.delenv("PHYSBENCH_NPE_WEIGHTS")
    assert weights.find("three_circles", ("mass",)) == SHIPPED
