#!/usr/bin/env bash
# Instructions per step with sleeping islands on and off (docs/constraints.md, "Sleeping
# islands"), counted by callgrind (wall-clock is unreliable on a shared machine): each mode runs
# N1 and N2 steps; (I(N2) − I(N1)) / (N2 − N1) is the cost of one step once the scene has settled
# (loading and the first N1 steps cancel).
#
#     validation/sleep_cost.sh [MODEL] [N1] [N2]
#
# Default: tests/data/mjcf/sleep/bin50.xml (50 spheres asleep from step 147), 400 and 600 steps.
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-tests/data/mjcf/sleep/bin50.xml}
n1=${2:-400}
n2=${3:-600}
cargo build --release -j 1 --example sleep_cost >/dev/null 2>&1
bin=${CARGO_TARGET_DIR:-target}/release/examples/sleep_cost
count() {
  local out
  out=$(mktemp)
  valgrind --tool=callgrind --callgrind-out-file="$out" "$bin" "$model" "$1" "$2" >/dev/null 2>&1
  grep -m1 '^summary:' "$out" | awk '{print $2}'
  rm -f "$out"
}
echo "model: $model (instructions per step, callgrind, difference of $n2 and $n1 steps)"
for mode in off on; do
  a=$(count "$mode" "$n1")
  b=$(count "$mode" "$n2")
  printf 'sleep %-4s %12d instructions per step   (%s)\n' "$mode" $(( (b - a) / (n2 - n1) )) "$("$bin" "$model" "$mode" "$n2")"
done
