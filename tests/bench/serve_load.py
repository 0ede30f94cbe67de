#!/usr/bin/python3
"""Timings of `superball serve` for docs/commands.md: map tiles of the quickstart view and a
concurrent load of region requests.

  /usr/bin/python3 tests/bench/serve_load.py [--superball BINARY] [--repeat 3] [--threads 2]

Tiles: 256x256 tiles of the quickstart view (jobs/quickstart.toml's window, e = alpha = 0.9,
max_bounces 1000) at zooms 0 to 8 around the structure near the wall, and the worst case, a
tile where every launch bounces to the cap (e = alpha = 1 near the self-retracing motion);
the time at the server (its Server-Timing header: counting plus PNG) and at the client.

Load: 16 clients, each with its own keep-alive connection, send 50 /api/region requests
of 256x256 points (a tile's worth) one after the other, over random parts of the quickstart
window at random zooms; latency per request at the client (p50, p99, max) and at the server
(Server-Timing: counting and writing the JSON), every answer decoded and checked, and the
server's resident memory before, after, after a second load and at its peak. The clients
(Python threads decoding 270 kB of JSON per answer) share the machine's cores with the
server.

Each round starts a fresh server; medians of --repeat rounds, each round's figures too.
"""

import argparse
import http.client
import json
import os
import random
import statistics
import sys
import threading
import time
import urllib.parse

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import Server, superball_binary  # noqa: E402

QUICKSTART = dict(x="xi", x_min=0, x_max=1, y="W", y_min=-3, y_max=3, U=-1, e=0.9, alpha=0.9, max_bounces=1000)
CAPPED = dict(x="xi", x_min=0.2499, x_max=0.2501, y="W", y_min=-1.2501, y_max=-1.2499, U=-0.5, e=1, alpha=1,
              max_bounces=1000)
# Tiles (z, x, y) of the quickstart window: the whole window, then deeper toward the
# structure near xi = 0, W = -2.5.
TILES = [(0, 0, 0), (2, 0, 3), (4, 1, 13), (6, 5, 52), (8, 20, 210)]


def server_ms(headers):
    """Counting + PNG (or JSON) time at the server, from its Server-Timing header."""
    return sum(float(part.split("dur=")[1]) for part in headers["Server-Timing"].split(","))


def tile_times(server, params, tiles, repeat):
    """{tile: ([server ms], [client ms])}, the tiles interleaved within each repetition."""
    out = {t: ([], []) for t in tiles}
    for _ in range(repeat):
        for z, x, y in tiles:
            started = time.monotonic()
            status, headers, body = server.get(f"/tile/{z}/{x}/{y}.png?" + urllib.parse.urlencode(params))
            client = 1e3 * (time.monotonic() - started)
            assert status == 200, body
            out[(z, x, y)][0].append(server_ms(headers))
            out[(z, x, y)][1].append(client)
    return out


def load(server, clients, requests, n, seed):
    """Latencies at the clients (s, sorted), at the server (ms, sorted), errors and wall time
    of `clients` threads sending `requests` region requests each."""
    host, port = urllib.parse.urlsplit(server.url).netloc.split(":")
    latencies, at_server, errors = [], [], []
    lock = threading.Lock()

    def client(k):
        rng = random.Random(seed * 1000 + k)
        conn = http.client.HTTPConnection(host, int(port), timeout=120)
        mine, theirs = [], []
        for _ in range(requests):
            size = 2.0 ** -rng.randint(0, 12)
            x0, y0 = rng.uniform(0, 1 - size), rng.uniform(-3, 3 - 6 * size)
            params = dict(QUICKSTART, x_min=x0, x_max=x0 + size, y_min=y0, y_max=y0 + 6 * size, nx=n, ny=n)
            started = time.monotonic()
            conn.request("GET", "/api/region?" + urllib.parse.urlencode(params))
            r = conn.getresponse()
            body = r.read()
            mine.append(time.monotonic() - started)
            if r.status == 200:
                theirs.append(server_ms(dict(r.getheaders())))
            if r.status != 200:
                errors.append(body)
                continue
            region = json.loads(body)
            if len(region["wall_bounces"]) != n or len(region["wall_bounces"][0]) != n:
                errors.append(b"wrong shape")
        conn.close()
        with lock:
            latencies.extend(mine)
            at_server.extend(theirs)

    threads = [threading.Thread(target=client, args=(k,)) for k in range(clients)]
    started = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return sorted(latencies), sorted(at_server), errors, time.monotonic() - started


def percentile(sorted_values, q):
    return sorted_values[min(len(sorted_values) - 1, int(q * len(sorted_values)))]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--superball", default=None, help="the binary (default: $SUPERBALL or build/release)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--clients", type=int, default=16)
    parser.add_argument("--requests", type=int, default=50)
    parser.add_argument("--n", type=int, default=256, help="points per side of a region request")
    args = parser.parse_args()
    binary = args.superball or superball_binary()

    rounds = []
    for r in range(args.repeat):
        with Server("--threads", str(args.threads), binary=binary) as server:
            tiles = tile_times(server, QUICKSTART, TILES, 3)
            capped = tile_times(server, CAPPED, [(0, 0, 0)], 3)[(0, 0, 0)]
            rss_before = server.rss_kib()[0]
            latencies, at_server, errors, wall = load(server, args.clients, args.requests, args.n, r)
            rss_after = server.rss_kib()[0]
            # A second load: memory flat means it ends where the first did.
            load(server, args.clients, args.requests, args.n, r + 100)
            rss_again, rss_peak = server.rss_kib()
        assert not errors, errors[:3]
        row = {
            "tiles_server_ms": {t: statistics.median(v[0]) for t, v in tiles.items()},
            "tiles_client_ms": {t: statistics.median(v[1]) for t, v in tiles.items()},
            "capped_server_ms": statistics.median(capped[0]),
            "p50_ms": 1e3 * percentile(latencies, 0.5),
            "p99_ms": 1e3 * percentile(latencies, 0.99),
            "max_ms": 1e3 * latencies[-1],
            "server_p50_ms": percentile(at_server, 0.5),
            "server_p99_ms": percentile(at_server, 0.99),
            "requests_per_s": len(latencies) / wall,
            "rss_mib": (rss_before / 1024, rss_after / 1024, rss_again / 1024, rss_peak / 1024),
        }
        rounds.append(row)
        print(f"round {r + 1}: tiles at the server (ms) " +
              ", ".join(f"z{t[0]} {v:.1f}" for t, v in row["tiles_server_ms"].items()) +
              f"; capped tile {row['capped_server_ms']:.0f} ms; load p50 {row['p50_ms']:.1f} ms, p99 "
              f"{row['p99_ms']:.1f} ms, max {row['max_ms']:.1f} ms (at the server p50 {row['server_p50_ms']:.1f}, p99 "
              f"{row['server_p99_ms']:.1f} ms), {row['requests_per_s']:.0f} requests/s; RSS "
              + " -> ".join(f"{m:.1f}" for m in row["rss_mib"][:3]) + f" MiB (peak {row['rss_mib'][3]:.1f})",
              flush=True)

    med = lambda f: statistics.median(f(r) for r in rounds)  # noqa: E731
    print(f"\nmedians of {len(rounds)} rounds ({binary}, --threads {args.threads}):")
    for t in TILES:
        print(f"  quickstart tile {t[0]}/{t[1]}/{t[2]}: {med(lambda r: r['tiles_server_ms'][t]):.1f} ms at the server, "
              f"{med(lambda r: r['tiles_client_ms'][t]):.1f} ms at the client")
    print(f"  tile where every launch is capped at 1000: {med(lambda r: r['capped_server_ms']):.0f} ms at the server")
    print(f"  {args.clients} clients x {args.requests} regions of {args.n}x{args.n}: no error; p50 "
          f"{med(lambda r: r['p50_ms']):.1f} ms, p99 {med(lambda r: r['p99_ms']):.1f} ms, max "
          f"{med(lambda r: r['max_ms']):.1f} ms at the clients; at the server (counting + JSON) p50 "
          f"{med(lambda r: r['server_p50_ms']):.1f} ms, p99 {med(lambda r: r['server_p99_ms']):.1f} ms; "
          f"{med(lambda r: r['requests_per_s']):.0f} requests/s")
    print("  server RSS before / after / after a second load / peak: " +
          " / ".join(f"{med(lambda r, k=k: r['rss_mib'][k]):.1f}" for k in range(4)) + " MiB")


if __name__ == "__main__":
    main()
