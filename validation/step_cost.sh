#!/usr/bin/env bash
# Instructions per step of each integrator on a model, in ABA-equivalents (issue 15 item 4),
# counted by callgrind (wall-clock is unreliable on a shared machine). Each mode runs at N1 and N2
# steps; (I(N2) − I(N1)) / (N2 − N1) is the cost of one step (loading and warm-up cancel).
#
#     [TILT=0.3] validation/step_cost.sh [MODEL] [MODES...]
#
# Default: models/textbook/chain30.xml, modes aba variational rk4 euler implicit; the initial
# state is qpos0 tilted by TILT rad per hinge (see examples/step_cost.rs).
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-models/textbook/chain30.xml}
shift || true
modes=${*:-aba variational rk4 euler implicit}
cargo build --release --example step_cost >/dev/null 2>&1
bin=target/release/examples/step_cost
n1=200
n2=1200
count() {
  local out
  out=$(mktemp)
  valgrind --tool=callgrind --callgrind-out-file="$out" "$bin" "$model" "$1" "$2" "${TILT:-0.3}" >/dev/null 2>&1
  grep -m1 '^summary:' "$out" | awk '{print $2}'
  rm -f "$out"
}
declare -A per
for m in $modes; do
  a=$(count "$m" $n1)
  b=$(count "$m" $n2)
  per[$m]=$(( (b - a) / (n2 - n1) ))
done
aba=${per[aba]:-}
echo "model: $model, tilt ${TILT:-0.3} rad (instructions per step, callgrind, difference of $n2 and $n1 steps)"
for m in $modes; do
  if [ -n "$aba" ]; then
    printf '%-14s %10d instructions  %6.2f ABA-equivalents\n' "$m" "${per[$m]}" "$(echo "${per[$m]} / $aba" | bc -l)"
  else
    printf '%-14s %10d instructions\n' "$m" "${per[$m]}"
  fi
done
