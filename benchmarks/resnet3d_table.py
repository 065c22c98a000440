"""Issue-4 tables from a `physbench bench benchmarks/resnet3d.toml` run
(:mod:`physbench.bench.resnet3d_table` says what they hold).

    python benchmarks/resnet3d_table.py results/resnet3d > results/resnet3d/table.md
"""

from __future__ import annotations

import argparse

from physbench.bench.resnet3d_table import table


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("folder", nargs="?", default="results/resnet3d", help="the sweep's --out")
    print(table(ap.parse_args().folder))


if __name__ == "__main__":
    main()
