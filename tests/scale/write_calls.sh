#!/usr/bin/env bash
# The write calls a command makes to files whose path contains PATTERN, every process of it
# (strace -ff, paths of the descriptors with -y), their bytes, and how many processes made
# them (a writer's writes come from threads of its own, which strace -ff traces apart: each
# thread is counted as the process that cloned it), as one line:
#
#   write_calls=N bytes_written=B writing_processes=P
#
# The command's stderr passes through; its stdout is dropped. (A few lines of strace rather
# than a library: strace is what counts system calls from outside the program.)
#
#   tests/scale/write_calls.sh PATTERN -- COMMAND [ARGS...]
set -euo pipefail
[[ $# -ge 3 && $2 == -- ]] || { echo "usage: $0 PATTERN -- COMMAND [ARGS...]" >&2; exit 2; }
pattern=$1
shift 2
command -v strace >/dev/null || { echo "write_calls.sh: strace is missing (.ci/install-deps --bench)" >&2; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
strace -ff -qq -y -e trace=write,pwrite64,writev,pwritev,pwritev2,clone,clone3 -o "$dir/t" "$@" >/dev/null
# "thread TID PARENT" for every thread a traced thread started; "write TID BYTES" for every
# write to the files.
for f in "$dir"/t.*; do
  tid=${f##*.}
  grep -E '^clone3?\(.*CLONE_THREAD' "$f" | sed -n "s/.*= \([0-9][0-9]*\)\$/thread \1 $tid/p" || true
  grep -F "$pattern" "$f" | grep -vE '^clone' | sed -n "s/.*= \([0-9][0-9]*\)\$/write $tid \1/p" || true
done | awk '
  $1 == "thread" { parent[$2] = $3; next }
  { tid[++n] = $2; b += $3 }
  END {
    for (i = 1; i <= n; i++) { p = tid[i]; while (p in parent) p = parent[p]; procs[p] = 1 }
    k = 0; for (p in procs) k++
    printf "write_calls=%d bytes_written=%d writing_processes=%d\n", n, b, k
  }'
