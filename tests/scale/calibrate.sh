#!/usr/bin/env bash
# Measures, on this machine, the constants of the cost model of the scaling simulation
# (tests/scale/simulate.sh) and writes them to tests/scale/calibration.env:
#
#   NS_PER_POINT      compute time of a point that makes no wall bounce, and
#   US_PER_TILE       of a tile beyond its points: the trivial grid (8192^2 points, xi in
#                     (1, 2), U = -1, W in (-3, 3): every launch misses the wall) at -n 1
#                     with 262144-point and with 1024-point tiles;
#   NS_PER_ITERATION  compute time per wall bounce, from Garwin's ball (e = alpha = 1) on
#                     a 64^3 volume at max_bounces 20000 at -n 1 (mean 1548 bounces a point,
#                     7.7 % of the points capped: the load of jobs/cluster), less the two
#                     terms above.
#
# Counting only: every job here runs with compression = 0. A tile's compression is charged
# apart, at the speed and ratio scale_costs measures on each job's own sample.
#
# Each figure is the median of REPS (default 5) interleaved repetitions: this machine is
# shared and a single run varies by +-25 %. Explore's own "computed in" time is used (the
# compute phase, without MPI start-up and file creation).
#
#   tests/scale/calibrate.sh [REPS]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
reps=${1:-5}
.ci/install-deps >/dev/null
cmake --preset release >/dev/null
cmake --build build/release -j2 --target superball >/dev/null
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
superball=$root/build/release/src/superball
work=$root/build/scale/calibrate
mkdir -p "$work"

job() {  # job NAME TILE_POINTS MODEL GRID MAX_BOUNCES
  {
    echo "[model]"; echo "$3"; echo "[grid]"; echo 'coordinates = "canonical"'; echo "$4"
    echo "[run]"; echo "max_bounces = $5"; echo "compression = 0"; echo "output = \"$work/$1.h5\""
    [[ $2 == 0 ]] || echo "tile_points = $2"
  } >"$work/$1.toml"
}
trivial_grid=$'xi = { min = 1.0, max = 2.0, n = 8192 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 8192 }'
job trivial_big 262144 $'e = 0.9\nalpha = 0.9' "$trivial_grid" 1000
job trivial_small 1024 $'e = 0.9\nalpha = 0.9' "$trivial_grid" 1000
job garwin 0 $'e = 1.0\nalpha = 1.0' $'xi = { min = 0.0, max = 1.0, n = 64 }\nU = { min = -3.0, max = 0.0, n = 64 }\nW = { min = -3.0, max = 3.0, n = 64 }' 20000

computed() {  # the compute-phase seconds of one run at -n 1
  tests/scale/computed.sh "$superball" "$work/$1.toml" 1 2>/dev/null
}
declare -A times
for ((r = 0; r < reps; r++)); do
  for j in trivial_big trivial_small garwin; do times[$j]+="$(computed $j) "; done
  echo "calibrate: repetition $((r + 1)) of $reps: ${times[trivial_big]} / ${times[trivial_small]} / ${times[garwin]}" >&2
done
garwin_tiles=$("$superball" explore "$work/garwin.toml" --dry-run | sed -n 's/^tiles: \([0-9]*\) .*/\1/p')
/usr/bin/python3 - "$work" "$garwin_tiles" "${times[trivial_big]}" "${times[trivial_small]}" "${times[garwin]}" <<'EOF' >tests/scale/calibration.env
import statistics, sys, h5py, numpy as np, datetime
work, garwin_tiles = sys.argv[1], int(sys.argv[2])
big, small, garwin = [[float(x) for x in a.split()] for a in sys.argv[3:6]]
med = statistics.median
points = 8192 * 8192
tiles_big, tiles_small = points // 262144, points // 1024
us_per_tile = (med(small) - med(big)) / (tiles_small - tiles_big) * 1e6
# Within the noise a tile can seem to cost nothing, never less.
us_per_tile = max(us_per_tile, 0.0)
ns_per_point = (med(big) - tiles_big * us_per_tile * 1e-6) / points * 1e9
with h5py.File(f"{work}/garwin.h5") as f:
    n = f["wall_bounces"][()].astype(np.float64)
ns_per_iteration = (med(garwin) - n.size * ns_per_point * 1e-9 - garwin_tiles * us_per_tile * 1e-6) / n.sum() * 1e9
print(f"# Cost model of tests/scale/simulate.sh, measured by tests/scale/calibrate.sh on {datetime.date.today()}")
print(f"# (medians of {len(big)} runs: trivial grid {med(big):.3f} s with 262144-point tiles, {med(small):.3f} s with")
print(f"# 1024-point tiles; Garwin's ball 64^3 {med(garwin):.3f} s for {n.sum():.4g} bounces; all uncompressed).")
print(f"NS_PER_POINT={ns_per_point:.2f}")
print(f"NS_PER_ITERATION={ns_per_iteration:.2f}")
print(f"US_PER_TILE={us_per_tile:.2f}")
EOF
cat tests/scale/calibration.env
