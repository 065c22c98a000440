#!/usr/bin/env bash
# The GPU machine's command for issue 29, item 4 (benchmarks/oneshot_gpu.py says what it runs):
#
#   bash benchmarks/gpu_oneshot.sh [oneshot_gpu.py options]
#
# Needs python3 with torch (CUDA) and, in .whl/ ($ONESHOT_WHEELS), wheels of what that machine
# lacks (pymunk, cffi, pycparser, tomli-w: benchmarks/README.md says how to fetch them). Writes
# into $OUT (default out/oneshot): results.json, summary.md, weights_ROW.tar, log.txt.
set -u -o pipefail
export ONESHOT_T0="${ONESHOT_T0:-$(date +%s)}"
OUT="${OUT:-out/oneshot}"
SITE="$PWD/out/oneshot_site"
WHEELS="${ONESHOT_WHEELS:-.whl}"
mkdir -p "$OUT"
cd "$(dirname "$0")/.." || exit 1
{
  if compgen -G "$WHEELS/*.whl" >/dev/null; then
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
      --target "$SITE" "$WHEELS"/*.whl || { echo "installing $WHEELS/*.whl failed"; exit 1; }
  fi
  export PYTHONPATH="$PWD:$SITE${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1 OMP_NUM_THREADS=1
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>&1 | head -2
  echo "cores $(getconf _NPROCESSORS_ONLN); /dev/shm $(df -h /dev/shm | awk 'NR == 2 {print $2}'); $(python3 -V)"
  python3 benchmarks/oneshot_gpu.py --out "$OUT" --runs out/oneshot_runs --site "$SITE" "$@"
} 2>&1 | tee "$OUT/log.txt"
