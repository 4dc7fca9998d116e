#!/usr/bin/env bash
# Instructions per state of the bounce chain (callgrind, the loop without the chain
# subtracted): at N = 4 with fixed parameters, the bench's closed-form baseline and
# Chain::apply in covariance and square-root form, and eval_batch_typed with the operators
# built once (fixed-typed: their typed bodies, no tape); with per-state parameters, covariance
# form, eval_batch_with against eval_batch_typed at N = 2, 4, 5 (one rayon thread).
# Counts repeat exactly, whatever the load.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
(cd "$here" && cargo build --release -q)
bin="$here/target/release/chain-probe"
count() {
  RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$1" 2>&1 | awk '/Collected/ {print $4}'
}
printf '%-26s %8s %8s\n' 'N = 4, fixed parameters' 'instr.' 'ratio'
base=""
for m in base cov sqrt fixed-typed; do
  with=$(count "$m")
  without=$(count "$m-none")
  per=$(( (with - without) / 4096 ))
  [ -n "$base" ] || base=$per
  awk -v m="$m" -v p="$per" -v b="$base" 'BEGIN { printf "%-26s %8d %7.2fx\n", m, p, p / b }'
done
printf '\n%-26s %8s %8s\n' 'per-state parameters' 'instr.' 'with/typed'
for n in 2 4 5; do
  with=$(( ($(count "with-$n") - $(count "with-$n-none")) / 4096 ))
  typed=$(( ($(count "typed-$n") - $(count "typed-$n-none")) / 4096 ))
  awk -v n="$n" -v w="$with" -v t="$typed" \
    'BEGIN { printf "%-26s %8d\n%-26s %8d %7.2fx\n", "eval_batch_with N=" n, w, "eval_batch_typed N=" n, t, w / t }'
done
