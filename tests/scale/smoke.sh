#!/usr/bin/env bash
# Smoke run of the scaling simulation (ctest scale.smoke): tests/scale/simulate.sh on
# tests/scale/smoke.toml at 64 ranks with the build's binaries. Checks the printed line
# and that the schedule simulated ran as designed: every tile computed, rank 0 answering
# blocks (far fewer requests than tiles) and serving node leaders (two levels), every
# compressed byte the ranks sent written by rank 0, its ratio measured on 2 boxes of the
# job computed by the real binary.
#
#   tests/scale/smoke.sh BUILD_DIR WORK_DIR
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
line=$(SUPERBALL_BUILD_DIR=$build "$root/tests/scale/simulate.sh" --no-build --out "$work" --ranks 64 --ratio-boxes 2 \
  "$root/tests/scale/smoke.toml")
echo "$line"
[[ $line =~ ^job=smoke\ ranks=64\ tile_points=64\ efficiency=(0\.[0-9]+|1\.0+)\ end_to_end=0\.[0-9]+\ predicted_s=[0-9.e+-]+$ ]] ||
  { echo "smoke: unexpected line: $line" >&2; exit 1; }
details=$(grep '^ranks=' "$work/logs/smoke.64.log")
echo "$details"
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<"$details"; }
tiles=$(field tiles) requests=$(field root_requests) two_level=$(field two_level)
((tiles == 4096)) || { echo "smoke: $tiles tiles, expected 4096" >&2; exit 1; }
((two_level == 1)) || { echo "smoke: 64 ranks on 2 nodes of 32 should use node leaders" >&2; exit 1; }
((requests > 0 && requests * 4 < tiles)) ||
  { echo "smoke: rank 0 answered $requests requests for $tiles tiles: not blocks" >&2; exit 1; }
(($(field reported) == tiles)) || { echo "smoke: $(field reported) of $tiles tiles reported done" >&2; exit 1; }
# Every compressed byte the ranks sent reached rank 0's writer, in writes of its own.
[[ $(field compressed) == 1 && $(field payload_bytes) == "$(field written_by_root)" && $(field payload_bytes) != 0 ]] ||
  { echo "smoke: the ranks sent $(field payload_bytes) compressed bytes, rank 0 wrote $(field written_by_root)" >&2; exit 1; }
(($(field root_writes) > 0)) || { echo "smoke: rank 0's appender made no write" >&2; exit 1; }
# The compression ratio came from the real binary's chunks (chunk_ratio.py).
grep -q '^tile_points=64 boxes=2 .* ratio=' "$work/logs/smoke.64.log" ||
  { echo "smoke: no compression ratio measured for the smoke job" >&2; exit 1; }
