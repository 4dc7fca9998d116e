#!/usr/bin/env bash
# Instructions per state of the 4D bounce chain with fixed parameters (callgrind, the loop
# without the chain subtracted): the bench's closed-form baseline, Chain::apply in
# covariance form and in square-root form. Counts repeat exactly, whatever the load.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
(cd "$here" && cargo build --release -q)
bin="$here/target/release/chain-probe"
count() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$1" 2>&1 | awk '/Collected/ {print $4}'
}
printf '%-26s %8s %8s\n' 'N = 4, fixed parameters' 'instr.' 'ratio'
base=""
for m in base cov sqrt; do
  with=$(count "$m")
  without=$(count "$m-none")
  per=$(( (with - without) / 4096 ))
  [ -n "$base" ] || base=$per
  awk -v m="$m" -v p="$per" -v b="$base" 'BEGIN { printf "%-26s %8d %7.2fx\n", m, p, p / b }'
done
