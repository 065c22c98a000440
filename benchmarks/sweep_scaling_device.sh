#!/usr/bin/env bash
# Sweep scaling on a bare many-core Linux machine without network: smoke48 with 1, 2, 4, 8 and
# 16 local worker processes, a Dask LocalCluster with 16 (and 8) workers, raw engine episodes
# with 1 and 16 processes; about 4-5 minutes on 16 cores.
#
#   OUT=out/sweep_scaling bash benchmarks/sweep_scaling_device.sh
#
# Needs Python 3.12 as python3 with numpy, pandas, scipy, matplotlib, networkx, pluggy, tqdm,
# filelock, cloudpickle, msgpack, psutil, toolz, sortedcontainers, jinja2 and pyyaml, and in .whl/
# the wheels of the rest (pymunk, pyarrow, the estimators' libraries, dask and distributed). Writes
# OUT/results.json, OUT/summary.md and OUT/log.txt; each run is added to results.json as it ends,
# so a run cut short keeps what it measured.
set -euo pipefail
OUT=${OUT:-out/sweep_scaling}
export SITE=${SITE:-$PWD/out/sweep_site}  # where the wheels are installed (out/ is ignored)
mkdir -p "$OUT"
LOG="$OUT/log.txt"
exec > >(tee -a "$LOG") 2>&1
export PYTHONUNBUFFERED=1
echo "nproc: $(nproc); $(python3 --version); $(date -u +%FT%TZ)"
# Compiled at install, as pip does by default: that machine's image sets PYTHONDONTWRITEBYTECODE=1,
# so with --no-compile every process compiled its libraries from source at each import (the
# first run there: Dask 1.53x the local processes at 16 workers, 1.17x once compiled).
python3 -m pip install -q --no-index --no-deps --no-cache-dir --upgrade \
    --target "$SITE" .whl/*.whl
python3 -m compileall -q -j 0 physbench >/dev/null || true
echo "PYTHONDONTWRITEBYTECODE=${PYTHONDONTWRITEBYTECODE:-unset}"
# physbench's own components register through entry points: give the source tree a dist-info.
python3 - <<'EOF'
import os, pathlib, re, tomllib
meta = tomllib.loads(pathlib.Path("pyproject.toml").read_text())["project"]
version = re.search(r'__version__ = "(.+)"', pathlib.Path("physbench/__init__.py").read_text())[1]
d = pathlib.Path(os.environ["SITE"]) / f"physbench-{version}.dist-info"
d.mkdir(exist_ok=True)
(d / "METADATA").write_text(f"Metadata-Version: 2.1\nName: physbench\nVersion: {version}\n")
eps = meta["entry-points"]["physbench"]
(d / "entry_points.txt").write_text(
    "[physbench]\n" + "".join(f"{k} = {v}\n" for k, v in eps.items())
    + "\n[console_scripts]\nphysbench = physbench.__main__:main\n"
)
EOF
export PYTHONPATH="$PWD:$SITE"
python3 -c "import physbench, pymunk, pyarrow, nevergrad, hyperopt, optuna, distributed; print('imports ok')"
W=${WORKERS:-1 2 4 8 16}
D=${DASK_WORKERS:-16}
SEEDS=${SEEDS:+--seeds $SEEDS}  # fewer seeds for a quick try
S=$SECONDS
# local processes at every count, Dask at 16 (8 added below if there is time)
timeout 270 python3 benchmarks/sweep_scaling.py --repeats 1 --workers $W $SEEDS \
    --executors processes dask --dask-workers $D --raw-workers 1 ${W##* } --out "$OUT" \
    || echo "stopped: $?"
if (( SECONDS - S < 200 )) && [[ -z "${DASK_WORKERS:-}" ]]; then
    timeout 90 python3 benchmarks/sweep_scaling.py --repeats 1 --workers 8 $SEEDS \
        --executors dask --raw-workers --add --out "$OUT" || echo "stopped: $?"
fi
echo "done in $((SECONDS - S)) s"
sleep 1  # let tee write the log out
