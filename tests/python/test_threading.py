"""count() releases the GIL: two Python threads counting at once run at the same time (their
calls overlap, which they cannot while one of them holds the GIL), and a pure-Python thread
keeps running while count() counts."""
import os
import threading
import time

import numpy as np


def launches(n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 1, n), rng.uniform(-3, 0, n), rng.uniform(-3, 3, n)


def test_two_threads_count_at_once(superball):
    # About 0.1-0.3 s per call on one core: long enough that calls serialised by a held GIL
    # could not overlap by chance.
    work = [launches(3_000_000, seed) for seed in (1, 2)]
    want = [superball.count(*w, e=0.9, alpha=0.9, threads=1) for w in work]
    barrier = threading.Barrier(2)
    spans, results = [None, None], [None, None]

    def body(i):
        barrier.wait()
        start = time.perf_counter()
        results[i] = superball.count(*work[i], e=0.9, alpha=0.9, threads=1)
        spans[i] = (start, time.perf_counter())

    cpu_before, wall_before = os.times(), time.perf_counter()
    threads = [threading.Thread(target=body, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    wall = time.perf_counter() - wall_before
    cpu_after = os.times()
    cpu = (cpu_after.user - cpu_before.user) + (cpu_after.system - cpu_before.system)
    (a0, a1), (b0, b1) = spans
    overlap = min(a1, b1) - max(a0, b0)
    shorter = min(a1 - a0, b1 - b0)
    # Each call began before the other ended, for most of the shorter one.
    assert overlap > 0.5 * shorter, f"calls did not run at once: {spans}"
    for got, w in zip(results, want):
        np.testing.assert_array_equal(got.wall_bounces, w.wall_bounces)
        np.testing.assert_array_equal(got.outcome, w.outcome)
    print(f"two threads: wall {wall:.3f} s, cpu {cpu:.3f} s (cpu/wall {cpu / wall:.2f}; 2 = both cores busy)")


def test_python_runs_while_count_counts(superball):
    xi, U, W = launches(4_000_000, 3)
    ticks = []
    done = threading.Event()

    def ticker():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=ticker)
    t.start()
    start = time.perf_counter()
    superball.count(xi, U, W, e=0.9, alpha=0.9, threads=1)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert len(during) >= 5, f"the other thread ticked {len(during)} times in {end - start:.3f} s of count()"
