#!/usr/bin/env bash
# Issue 42's GPU lever: the shipped recipe (mdn head, K = 10, draws fed back at 0.35 sigma, u = v = 5, batch 32 x 100
# frames) at the paper's width, 3 x LSTM(1024), beside 512 and the shipped 256 (two seeds), trained at once on one
# lent GPU for $MINUTES minutes each. Run on the device machine from the repository root, with .carry/ carried:
#     python -m training.device.carry pack-cache .carry/aclstm_positions.xz      # here, first
#     bash training/aclstm/gpu_runs.sh                                     # there ($OUT gets the weights and logs)
# then here: python -m training.device.carry unpack-checkpoint DIR/<run>-last runs/<run> last.pt (and -best best.pt).
# Test it on the CPU in a fresh clone (unpack-cache never replaces a cache built from ../shared):
#     DEVICE=cpu MINUTES=0.3 OUT=/tmp/out bash training/aclstm/gpu_runs.sh
set -u
MINUTES=${MINUTES:-7.5}
DEVICE=${DEVICE:-cuda}
PY=${PY:-python3}
export PYTHONUNBUFFERED=1
mkdir -p "$OUT" runs
$PY -m training.device.carry unpack-cache .carry/aclstm_positions.xz || exit 1
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,memory.total --format=csv,noheader
RECIPE="--head mdn --components 10 --draw-temperature 0.35 --layers 3 --batch 32 --window 100 --condition 5 --ground-truth 5"
RUNS="gpu-w1024-s1:1024:1 gpu-w512-s1:512:1 gpu-w256-s1:256:1 gpu-w256-s2:256:2"
for spec in $RUNS; do
  IFS=: read -r run hidden seed <<<"$spec"
  rm -rf "runs/$run"
  $PY -m training.aclstm.train --run "$run" --hidden "$hidden" --seed "$seed" $RECIPE --device "$DEVICE" \
      --minutes "$MINUTES" --checkpoint-minutes 2 > "runs/$run.out" 2>&1 &
done
wait
for spec in $RUNS; do
  IFS=: read -r run hidden seed <<<"$spec"
  echo "== $run"; cat "runs/$run/train.log" 2>/dev/null; tail -c 600 "runs/$run.out"; echo
  [ -f "runs/$run/last.pt" ] || continue
  # What comes back: 8 files of at most 16 MiB, 64 MiB together. The widest run as int8 (its export stores int8).
  int8=""; [ "$hidden" -ge 1024 ] && int8="--int8"
  $PY -m training.device.carry pack-checkpoint "runs/$run/last.pt" "$OUT/$run-last" $int8
  [ "$hidden" -le 256 ] && $PY -m training.device.carry pack-checkpoint "runs/$run/best.pt" "$OUT/$run-best"
done
tar czf "$OUT/logs.tgz" runs/gpu-*/train.log runs/gpu-*/summary.json runs/gpu-*.out 2>/dev/null
ls -la "$OUT"
