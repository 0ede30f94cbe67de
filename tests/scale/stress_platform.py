#!/usr/bin/python3
"""The platform of a stressed scaling simulation (tests/scale/simulate.sh): cluster.xml with
the network's latencies and bandwidths, the file system's bandwidths (its disk's and one
client's) and its cost per operation (the latency of every operation, and the time the
metadata server takes for each of its own) multiplied by the given factors.

    platform.py CLUSTER.xml OUT.xml LATENCY_FACTOR BANDWIDTH_FACTOR FS_BANDWIDTH_FACTOR METADATA_FACTOR [NODES]

NODES above the cluster's 128 (a multiple of 32): that many nodes, in leaves of 32 under 8
core switches with 4 cables from each leaf to each (the same full bisection: 32 cables up
from 32 nodes).
"""
import re
import sys

UNITS = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9}


def main():
    src, dst = sys.argv[1], sys.argv[2]
    lat, bw, fsbw, meta = (float(x) for x in sys.argv[3:7])
    nodes = int(sys.argv[7]) if len(sys.argv) > 7 else 128
    x = open(src).read()
    if nodes > 128:
        if nodes % 32:
            sys.exit(f"stress_platform: {nodes} nodes: a multiple of 32 above 128")
        x = re.sub(r'radical="0-127"', f'radical="0-{nodes - 1}"', x)
        x = re.sub(r'topo_parameters="[^"]*"', f'topo_parameters="2;32,{nodes // 32};1,8;1,4"', x)

    def rate(f):
        return lambda m: f'{m.group(1)}"{float(m.group(2)) * UNITS[m.group(3)] * f:.6g}Bps"'

    # The links between nodes (bw, lat); the shared memory within a node (loopback_*) stays.
    x = re.sub(r'(\s(?:bw)=)"([0-9.]+)([kMG]?)Bps"', rate(bw), x)
    x = re.sub(r'(\s(?:lat)=)"([0-9.]+)(u?)s"',
               lambda m: f'{m.group(1)}"{float(m.group(2)) * (1e-6 if m.group(3) else 1.0) * lat:.6g}s"', x)
    # The file system: its disk, one client, the cost of an operation.
    x = re.sub(r'(\b(?:read|write)_bw=)"([0-9.]+)([kMG]?)Bps"', rate(fsbw), x)
    x = re.sub(r'(<prop id="client_bw" value=)"([0-9.e+]+)"', lambda m: f'{m.group(1)}"{float(m.group(2)) * fsbw:.6g}"', x)
    x = re.sub(r'(<prop id="op_latency" value=)"([0-9.e+-]+)"', lambda m: f'{m.group(1)}"{float(m.group(2)) * meta:.6g}"', x)
    x = re.sub(r'(<prop id="mds_ops_per_s" value=)"([0-9.e+-]+)"', lambda m: f'{m.group(1)}"{float(m.group(2)) / meta:.6g}"', x)
    with open(dst, "w") as f:
        f.write(x)


if __name__ == "__main__":
    main()
