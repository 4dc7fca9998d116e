#!/usr/bin/env bash
# Instructions per state of the 10-operator bounce chain (callgrind; the loop without
# the chain subtracted, divided by the 4,096 states). Per-ray parameters at N = 2, 4, 5:
# the closed-form baseline, the operators applied one by one through Operator::apply
# (covariance and square-root form), and pushed on a Chain built per ray; fixed
# parameters at N = 4: the baseline and one Chain. Counts repeat exactly, whatever the
# load on the machine.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
(cd "$here" && cargo build --release -q)
bin="$here/target/release/chain-probe"
count() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$1" 2>&1 | awk '/Collected/ {print $4}'
}
per() {
  echo $(( ($(count "$1") - $(count "$1-none")) / 4096 ))
}
printf '%-28s %8s %8s %8s\n' 'per-ray parameters' 'N = 2' 'N = 4' 'N = 5'
declare -A base
for m in base apply chain apply-sqrt chain-sqrt; do
  row=""
  for n in 2 4 5; do
    p=$(per "$m-$n")
    [ "$m" = base ] && base[$n]=$p
    row="$row $(awk -v p="$p" -v b="${base[$n]}" 'BEGIN { printf "%8d (%.2fx)", p, p / b }')"
  done
  printf '%-28s%s\n' "$m" "$row"
done
fb=$(per fixed-base-4)
fc=$(per fixed-chain-4)
printf '\n%-28s %8d\n%-28s %8d (%.2fx)\n' 'fixed, N = 4: baseline' "$fb" 'fixed, N = 4: Chain::apply' "$fc" "$(awk -v a="$fc" -v b="$fb" 'BEGIN { print a / b }')"
