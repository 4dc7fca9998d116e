#!/usr/bin/env bash
# Instructions per call of each kernel (callgrind, loop subtracted), this tree against the
# cov-core of git revision $1 (default: the commit before the layout redesign, 56afa6c^).
# Instruction counts repeat exactly for the same binary, whatever the machine's load.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
rev="${1:-56afa6c^}"
work="$(mktemp -d)"
trap 'git -C "$root" worktree remove --force "$work/old" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git -C "$root" worktree add -f -q "$work/old" "$rev"
for side in old new; do
  mkdir -p "$work/$side-probe/src"
  cp "$here/src/main.rs" "$work/$side-probe/src/"
  core="$root/crates/cov-core"
  [ "$side" = old ] && core="$work/old/crates/cov-core"
  sed "s|path = \"../../crates/cov-core\"|path = \"$core\"|" "$here/Cargo.toml" > "$work/$side-probe/Cargo.toml"
  (cd "$work/$side-probe" && CARGO_TARGET_DIR="$work/$side-target" cargo build --release -q)
done
modes="none c_shear c_scale c_rotate c_rotate_frame c_add_variance c_window2 c_convolve1 c_convolve2 c_integrate1 f_shear f_scale f_rotate f_rotate_frame f_add_variance f_window2 f_convolve1 f_convolve2 f_integrate1"
count() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$work/$1-target/release/kernel-probe" "$2" 2>&1 \
    | awk '/Collected/ {print $4}'
}
declare -A n
for side in old new; do for m in $modes; do n[$side.$m]=$(count "$side" "$m"); done; done
printf '%-16s %10s %10s %8s\n' kernel "$rev" this change
for m in $modes; do
  [ "$m" = none ] && continue
  awk -v m="$m" -v o="${n[old.$m]}" -v o0="${n[old.none]}" -v c="${n[new.$m]}" -v c0="${n[new.none]}" \
    'BEGIN { a = (o - o0) / 25600; b = (c - c0) / 25600; printf "%-16s %10.0f %10.0f %+7.1f%%\n", m, a, b, 100 * (b / a - 1) }'
done
