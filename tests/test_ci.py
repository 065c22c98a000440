"""CI runs exactly the test command that README.md gives."""

from __future__ import annotations

import re
from pathlib import Path

import physbench

REPO = Path(physbench.__file__).parent.parent


def test_ci_runs_the_readme_test_command():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    block = re.search(r"Run the tests .*?```bash\n(.*?)\n```", readme, re.DOTALL)
    assert block, "README.md has no 'Run the tests' code block"
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8").rstrip("\n").splitlines()
    assert ci[-1] == block.group(1)
    assert ci[-1].endswith("&& bash .ci/wheel")
