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
#                     terms above;
# (those three counting only: compression = 0), and the costs of the compressed write path:
#   INDEX_US_PER_TILE rank 0's time per tile from the last tile counted to the result
#                     renamed (the journal, the index of every tile in place, explore's
#                     "finished ... after the last tile was counted"): the trivial grid
#                     compressed in 65536 tiles of 1024 points and in 256 of 262144;
#   COPY_GBPS         GB/s of payload a writer copies (two copies a byte: bench_copy);
#   HASH_GBPS         GB/s of stored tiles a rank checks on a resume (bench_hash);
#   JOURNAL_US_PER_RUN rank 0's time to write the places and checksums of a run of
#                     consecutive tiles into the journal as it records them (bench_journal:
#                     every tile a run of its own).
#
# How far and how fast a job's data compress is the job's own (tests/scale/chunk_ratio.py
# with codec_speed, run by simulate.sh); as a cross-check, the comment states the
# compression of the benchmark slice of tests/bench (8192^2, e = alpha = 0.9, U = -1, 201 MB
# raw in 256 tiles) as the difference of its compute phases at level 4 and uncompressed.
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
cmake --build build/release -j2 --target superball bench_copy bench_hash bench_journal >/dev/null
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
superball=$root/build/release/src/superball
work=$root/build/scale/calibrate
mkdir -p "$work"

job() {  # job NAME TILE_POINTS MODEL GRID MAX_BOUNCES [COMPRESSION]
  {
    echo "[model]"; echo "$3"; echo "[grid]"; echo 'coordinates = "canonical"'; echo "$4"
    echo "[run]"; echo "max_bounces = $5"; echo "compression = ${6:-0}"; echo "output = \"$work/$1.h5\""
    [[ $2 == 0 ]] || echo "tile_points = $2"
  } >"$work/$1.toml"
}
trivial_grid=$'xi = { min = 1.0, max = 2.0, n = 8192 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 8192 }'
job trivial_big 262144 $'e = 0.9\nalpha = 0.9' "$trivial_grid" 1000
job trivial_small 1024 $'e = 0.9\nalpha = 0.9' "$trivial_grid" 1000
job garwin 0 $'e = 1.0\nalpha = 1.0' $'xi = { min = 0.0, max = 1.0, n = 64 }\nU = { min = -3.0, max = 0.0, n = 64 }\nW = { min = -3.0, max = 3.0, n = 64 }' 20000
slice_grid=$'xi = { min = 0.0, max = 1.0, n = 8192 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 8192 }'
job slice_c0 262144 $'e = 0.9\nalpha = 0.9' "$slice_grid" 1000 0
job slice_c4 262144 $'e = 0.9\nalpha = 0.9' "$slice_grid" 1000 4
job trivial_big_c4 262144 $'e = 0.9\nalpha = 0.9' "$trivial_grid" 1000 4
job trivial_small_c4 1024 $'e = 0.9\nalpha = 0.9' "$trivial_grid" 1000 4

# One run at -n 1: "COMPUTE_SECONDS FINISH_SECONDS" (the compute phase, N / rate to 3
# digits as computed.sh takes it; the time from the last tile counted to the result).
run_once() {
  mpirun -n 1 "$superball" explore "$work/$1.toml" --overwrite 2>&1 | /usr/bin/python3 -c '
import re, sys
t = sys.stdin.read()
n, rate = re.search(r"(\d+) points computed in [0-9.]+ s \(([0-9.e+-]+) points/s\)", t).groups()
v, unit = re.search(r"finished ([0-9.]+) (s|ms|us|µs) after the last tile", t).groups()
scale = 1.0 if unit == "s" else 1e-3 if unit == "ms" else 1e-6
print(f"{int(n) / float(rate):.4g} {float(v) * scale:.4g}")'
}
declare -A times finish
all=(trivial_big trivial_small garwin slice_c0 slice_c4 trivial_big_c4 trivial_small_c4)
for ((r = 0; r < reps; r++)); do
  for j in "${all[@]}"; do
    read -r c f < <(run_once "$j")
    times[$j]+="$c "
    finish[$j]+="$f "
  done
  echo "calibrate: repetition $((r + 1)) of $reps: compute ${times[*]}; finish ${finish[trivial_big_c4]} / ${finish[trivial_small_c4]}" >&2
done
copy=$("$root/build/release/tests/scale/bench_copy" | tail -1)
hash=$("$root/build/release/tests/scale/bench_hash" | tail -1)
journal=$("$root/build/release/tests/scale/bench_journal" | tail -1)
load=$(cut -d' ' -f1-3 /proc/loadavg)
garwin_tiles=$("$superball" explore "$work/garwin.toml" --dry-run | sed -n 's/^tiles: \([0-9]*\) .*/\1/p')
/usr/bin/python3 - "$work" "$garwin_tiles" "${times[trivial_big]}" "${times[trivial_small]}" "${times[garwin]}" \
  "${times[slice_c0]}" "${times[slice_c4]}" "${finish[trivial_big_c4]}" "${finish[trivial_small_c4]}" "$copy" "$load" "$hash" "$journal" <<'EOF' >tests/scale/calibration.env
import statistics, sys, h5py, numpy as np, datetime
work, garwin_tiles = sys.argv[1], int(sys.argv[2])
big, small, garwin, c0, c4, fin_big, fin_small = [[float(x) for x in a.split()] for a in sys.argv[3:10]]
copy_gbps, load, hash_gbps, journal_us = float(sys.argv[10]), sys.argv[11], float(sys.argv[12]), float(sys.argv[13])
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
raw = 8192 * 8192 * 3
compress_mbps = raw / (med(c4) - med(c0)) / 1e6
index_us = (med(fin_small) - med(fin_big)) / (points // 1024 - points // 262144) * 1e6
print(f"# Cost model of tests/scale/simulate.sh, measured by `tests/scale/calibrate.sh {len(big)}` on {datetime.date.today()}")
print(f"# (medians of {len(big)} interleaved runs at -n 1, load average {load} at the end: trivial grid {med(big):.3f} s")
print(f"# with 262144-point tiles, {med(small):.3f} s with 1024-point tiles; Garwin's ball 64^3 {med(garwin):.3f} s for")
print(f"# {n.sum():.4g} bounces; all three uncompressed. Benchmark slice 8192^2 (201 MB raw) {med(c0):.3f} s")
print(f"# uncompressed, {med(c4):.3f} s at level 4. Trivial grid at level 4: finished {med(fin_big) * 1e3:.1f} ms after")
print(f"# the last tile in 256 tiles, {med(fin_small) * 1e3:.1f} ms in 65536. bench_copy: {copy_gbps} GB/s;")
print(f"# bench_hash: {hash_gbps} GB/s; bench_journal: {journal_us} us a run of tiles.")
print(f"# The slice's compression, as the difference of two compute phases: {compress_mbps:.0f} MB/s of raw data;")
print(f"# simulate.sh measures each job's own with codec_speed.)")
print(f"NS_PER_POINT={ns_per_point:.2f}")
print(f"NS_PER_ITERATION={ns_per_iteration:.2f}")
print(f"US_PER_TILE={us_per_tile:.2f}")
print(f"INDEX_US_PER_TILE={index_us:.2f}")
print(f"COPY_GBPS={copy_gbps:.1f}")
print(f"HASH_GBPS={hash_gbps:.1f}")
print(f"JOURNAL_US_PER_RUN={journal_us:.2f}")
EOF
cat tests/scale/calibration.env
