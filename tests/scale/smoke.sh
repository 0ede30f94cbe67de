#!/usr/bin/env bash
# Smoke run of the scaling simulation (ctest scale.smoke): tests/scale/simulate.sh on
# tests/scale/smoke.toml at 64 ranks with the build's binaries. Checks the printed line
# and that the schedule simulated ran as designed: every tile computed, rank 0 answering
# blocks (far fewer requests than tiles) and serving node leaders (two levels), every
# compressed byte the ranks sent written by the two writers (one per node), its ratio
# measured on 2 boxes of the job computed by the real binary.
#
#   tests/scale/smoke.sh BUILD_DIR WORK_DIR
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
line=$(SUPERBALL_BUILD_DIR=$build "$root/tests/scale/simulate.sh" --no-build --out "$work" --ranks 64 --ratio-boxes 2 \
  "$root/tests/scale/smoke.toml")
echo "$line"
[[ $line =~ ^job=smoke\ ranks=64\ tile_points=64\ efficiency=(0\.[0-9]+|1\.0+)\ end_to_end=0\.[0-9]+\ predicted_s=[0-9.e+-]+\ rank_mib=[0-9.]+$ ]] ||
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
# Two writers (auto from 64 ranks: one per node): every compressed byte the ranks sent was
# written, by rank 0 or the other node's leader, each writing some; file space granted.
(($(field writers) == 2)) || { echo "smoke: $(field writers) writers, expected one per node (2)" >&2; exit 1; }
/usr/bin/python3 - "$(field payload_bytes)" "$(field written_by_root)" "$(field written_by_writers)" <<'EOF' ||
import sys
sent, root, others = (float(x) for x in sys.argv[1:])
# The payload holds each batch's header (8 bytes, 32 a tile) beside the stored bytes.
sys.exit(0 if sent > 0 and root > 0 and others > 0 and abs(sent - root - others) <= 8 + 32 * 4096 + 64 else 1)
EOF
  { echo "smoke: the ranks sent $(field payload_bytes) compressed bytes, rank 0 wrote $(field written_by_root), the other writer $(field written_by_writers)" >&2; exit 1; }
(($(field root_writes) > 0 && $(field root_grants) > 0)) || { echo "smoke: rank 0 made no write or granted no space" >&2; exit 1; }
# The compression ratio came from the real binary's chunks (chunk_ratio.py).
grep -q '^tile_points=64 boxes=2 .* ratio=' "$work/logs/smoke.64.log" ||
  { echo "smoke: no compression ratio measured for the smoke job" >&2; exit 1; }
