"""Ending a process without the interpreter's teardown: the status given, the atexit handlers
registered later still run, buffered output still reaches its reader, and no object is freed."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = """
import atexit, sys
from physbench.teardown import skip_at_exit

class Freed:
    def __del__(self):
        sys.stderr.write("freed\\n")
        sys.stderr.flush()

kept = Freed()  # freed by the teardown, if there is one
{register}
atexit.register(lambda: open(sys.argv[1], "w").write("ran"))
sys.stdout.write("buffered")  # not flushed by this script
sys.exit(5)
"""


@pytest.mark.parametrize("skip", [True, False])
def test_ends_after_later_handlers_without_freeing(skip: bool, tmp_path: Path) -> None:
    register = "skip_at_exit(lambda: 3)" if skip else ""
    marker = tmp_path / "marker"
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT.format(register=register), str(marker)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.stdout == "buffered"
    assert marker.read_text() == "ran"
    if skip:
        assert proc.returncode == 3
        assert "freed" not in proc.stderr
    else:  # the control: without it the object is freed and sys.exit's status stands
        assert proc.returncode == 5
        assert "freed" in proc.stderr
