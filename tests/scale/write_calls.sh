#!/usr/bin/env bash
# The write calls a command makes to files whose path contains PATTERN, every process of it
# (strace -ff, paths of the descriptors with -y), and their bytes, as one line:
#
#   write_calls=N bytes_written=B
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
strace -ff -qq -y -e trace=write,pwrite64,writev,pwritev,pwritev2 -o "$dir/t" "$@" >/dev/null
cat "$dir"/t.* | grep -F "$pattern" | sed -n 's/.*= \([0-9][0-9]*\)$/\1/p' |
  awk '{ n++; b += $1 } END { printf "write_calls=%d bytes_written=%d\n", n, b }'
