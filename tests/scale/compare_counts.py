"""The counts of real oversubscribed runs against their simulation's (tests/scale/validate.sh
--oversubscribed): one line per quantity, exit status 1 when one disagrees.

    compare_counts.py RANKS REAL SIM

REAL: one line of key=value per real run (explore --stats and tests/scale/write_calls.sh);
the median of the runs is compared. SIM: sim_run's output, its line starting "ranks=".
Exact where the count does not depend on timing, within 10 % where it does."""
import statistics
import sys

EXACT = ["tiles", "computing_ranks", "two_level", "writers"]
# Depend on when each rank asks and answers.
TIMED = ["root_blocks", "root_requests", "root_messages", "max_leader_messages", "tiles_min", "tiles_max",
         "given_back", "root_asked_back", "write_calls", "bytes_written"]


def fields(line):
    return {k: float(v) for k, v in (x.split("=", 1) for x in line.split() if "=" in x)}


def main():
    ranks, real_path, sim_path = sys.argv[1:4]
    runs = [fields(line) for line in open(real_path) if line.strip()]
    sim_lines = [line for line in open(sim_path) if line.startswith("ranks=")]
    if not runs or not sim_lines:
        sys.exit(f"compare_counts: no {'real run' if not runs else 'simulation'} to compare ({real_path}, {sim_path})")
    sim = fields(sim_lines[-1])
    failed = False
    for key in EXACT + TIMED:
        missing = [r for r in runs if key not in r]
        if missing or key not in sim:
            sys.exit(f"compare_counts: {key} missing from {'the real runs' if missing else 'the simulation'}")
        real = statistics.median(r[key] for r in runs)
        simulated = sim[key]
        if key in EXACT:
            ok, check, error = real == simulated, "exact", ""
        else:
            error = (simulated - real) / real if real else (0.0 if simulated == 0 else float("inf"))
            ok, check = abs(error) <= 0.10, "10%"
            error = f" ({error:+.1%})"
        failed |= not ok
        low, high = min(r[key] for r in runs), max(r[key] for r in runs)
        spread = "" if len(runs) == 1 else f" [{low:g}, {high:g}]"
        # Whether the simulation falls among the real runs themselves (their own spread).
        among = "" if len(runs) == 1 else f" among_real_runs={'yes' if low <= simulated <= high else 'no'}"
        print(f"ranks={ranks} quantity={key} real={real:g}{spread} simulated={simulated:g} check={check} "
              f"agreement={'yes' if ok else 'NO'}{error}{among}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
