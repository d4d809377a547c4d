#!/usr/bin/env bash
# The GPU runs of issue 24: checks that planning and perception run on CUDA (the tests that
# skip without a GPU), then PlanBench Blocksworld-600 and the 20-50 block scaling table with
# `--device cuda`, beside the same commands' CPU figures in BENCHMARKS.md, with Slaney &
# Thiebaux's US and GN1 lengths beside ours (`--baselines us,gn1`).
#
# Usage (repository root, on a machine with a CUDA build of torch and a GPU):
#   scripts/gpu_bench.sh [OUT]            # OUT: results folder (default results/gpu)
# Environment:
#   PY      python to run (.venv/bin/python)
#   DATA    PlanBench Blocksworld folder (tamp's default: ../shared/data/planbench/blocksworld)
#   N       random problems per size in the scaling table (20, as BENCHMARKS.md's; 60 s each,
#           so up to 3 x N minutes; N=3 fits a 15-minute device budget with PlanBench)
#   SIZES   block counts of the scaling table (20,30,50)
#   STEPS   which parts to run (check,planbench,scaling)
#   EXTRA   more options for the scaling run, e.g. "--park-free" (BENCHMARKS.md: 19/20 at 50
#           blocks on the CPU with it, 8/20 without)
# Each part writes OUT/<part>/results.json (its config and machine record the device and the
# GPU's name) and the log OUT/<part>.log; the script stops at the first part that fails.
set -euo pipefail

OUT=${1:-results/gpu}
PY=${PY:-.venv/bin/python}
N=${N:-20}
SIZES=${SIZES:-20,30,50}
STEPS=${STEPS:-check,planbench,scaling}
mkdir -p "$OUT"
tamp() { "$PY" -m tamp.cli "$@"; }
wants() { [[ ",$STEPS," == *",$1,"* ]]; }

"$PY" - <<'PY'
import torch
if not torch.cuda.is_available():
    raise SystemExit(f"no CUDA here (torch {torch.__version__}, CUDA {torch.version.cuda})")
print(f"torch {torch.__version__}, CUDA {torch.version.cuda}, {torch.cuda.get_device_name(0)}")
PY

if wants check; then  # the CUDA tests (skipped on CPU machines), then one plan and its record
  "$PY" -m pytest -q -p no:cacheprovider tests/task/test_planner_device.py \
    tests/tamp/cli/test_device_option.py tests/perception/test_perception_device.py \
    2>&1 | tee "$OUT/check.log"
  tamp example --json --device cuda > "$OUT/example_cuda.json"
fi

if wants planbench; then  # BENCHMARKS.md's CPU row: 600/600 valid, 97.7% optimal, 30 s
  data=()
  if [[ -n "${DATA:-}" ]]; then data=(--data "$DATA"); fi
  time tamp bench planbench "${data[@]}" --seeds 1 --threads 1 --device cuda --no-progress \
    --baselines us,gn1 \
    --out "$OUT/planbench_cuda" 2>&1 | tee "$OUT/planbench.log"
fi

if wants scaling; then  # BENCHMARKS.md "Scaling to 50 blocks": the same flags, on the GPU
  time tamp bench random --blocks "$SIZES" --n "$N" --seed 0 --max-nodes 1 --time-limit 60 \
    --max-windows 1000 --one-at-a-time --threads 1 --device cuda --no-progress --baselines us,gn1 \
    ${EXTRA:-} --out "$OUT/scaling_cuda" 2>&1 | tee "$OUT/scaling.log"
fi
echo "wrote $OUT"
