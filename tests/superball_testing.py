"""Helpers shared by the Python end-to-end tests: where the binary is, the environment
mpirun needs, the processes below mpirun, and how fast the binary under test is."""
import os
import shutil
import subprocess
import tempfile
import unittest

SOURCE = os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


SKIP_RETURN_CODE = 77  # ctest's SKIP_RETURN_CODE for these files (tests/CMakeLists.txt)


def main():
    """unittest.main() with an exit status ctest can read: 1 on a failure, 77 (reported as
    skipped, not passed) when every test of the file skipped; 0 otherwise, after a line
    naming any tests that skipped."""
    import sys
    result = unittest.main(exit=False).result
    if not result.wasSuccessful():
        sys.exit(1)
    reasons = sorted({reason for _, reason in result.skipped})
    if result.skipped:
        print(f"skipped {len(result.skipped)} of {result.testsRun} tests: {'; '.join(reasons)}", file=sys.stderr)
    sys.exit(SKIP_RETURN_CODE if result.testsRun > 0 and len(result.skipped) == result.testsRun else 0)


def superball_binary():
    """The binary under test: $SUPERBALL (set by ctest), else a build of this repository."""
    path = os.environ.get("SUPERBALL")
    if path:
        return os.path.abspath(path)
    for build in ("build/release", "build/native"):
        candidate = os.path.join(SOURCE, build, "src", "superball")
        if os.access(candidate, os.X_OK):
            return candidate
    raise unittest.SkipTest("no superball binary: set SUPERBALL")


def cmake_cache_value(build, name):
    """The value of `name` in the CMake cache of the build tree `build` ("" if unset)."""
    with open(os.path.join(build, "CMakeCache.txt")) as f:
        for line in f:
            if line.startswith(name + ":"):
                return line.split("=", 1)[1].strip()
    return ""


def mpi_env():
    """The environment for mpirun: Open MPI refuses to run as root unless told."""
    env = dict(os.environ)
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


class ExploreCase(unittest.TestCase):
    """A test with a directory of its own that runs `superball explore` under mpirun
    ($SUPERBALL and $MPIEXEC, as ctest sets them)."""
    prefix = "superball-"

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix=self.prefix)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def write_job(self, text, name="job.toml"):
        with open(self.path(name), "w") as f:
            f.write(text)
        return self.path(name)

    def explore(self, job, output, ranks=1, extra=(), expect=0, wrap=()):
        """`mpirun -n RANKS superball explore JOB -o OUTPUT -q EXTRA`, under `wrap` (a
        command that runs the rest) if given; fails the test on another exit status."""
        superball = os.environ.get("SUPERBALL", "superball")
        mpiexec = os.environ.get("MPIEXEC") or "mpirun"
        cmd = [*wrap, mpiexec, "-n", str(ranks), "--oversubscribe", superball, "explore", job, "-o", output, "-q",
               *extra]
        r = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(), timeout=300)
        self.assertEqual(r.returncode, expect, f"{' '.join(cmd)}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}")
        return r


def descendants(pid):
    """Every process below `pid`: Open MPI puts its ranks in process groups of their own,
    so signalling mpirun's group does not reach them."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def rank_of(pid):
    """MPI rank of a process started by mpirun (Open MPI puts it in the environment); None
    for another process."""
    try:
        with open(f"/proc/{pid}/environ", "rb") as f:
            for item in f.read().split(b"\0"):
                if item.startswith(b"OMPI_COMM_WORLD_RANK="):
                    return int(item.split(b"=", 1)[1])
    except OSError:
        pass
    return None


def capped_job(max_bounces, n_xi=2, n_W=2, tile_points=None):
    """A job in which every point bounces to the cap: around the marginally stable
    self-retracing motion (0.25, -0.5, -1.25) of the dissipation-free model. The resume
    journal is written every 0.1 s."""
    run = (f"max_bounces = {max_bounces}" + (f"\ntile_points = {tile_points}" if tile_points else "") +
           "\ncheckpoint_seconds = 0.1")
    return ("[model]\ne = 1.0\nalpha = 1.0\n\n[grid]\n"
            f"xi = {{ min = 0.24, max = 0.26, n = {n_xi} }}\nU = -0.5\nW = {{ min = -1.27, max = -1.23, n = {n_W} }}\n\n"
            f"[run]\n{run}\n")


def killable_job(speed, seconds):
    """No dissipation over the (xi, W) slice at U = -1: about 11000 of its 300^2 points
    bounce to the cap, max_bounces set from `speed` (wall_impacts_per_second) so that two
    ranks take about `seconds`, in tiles of 400 points that each take a fraction of a
    second (a clean stop is quick); the resume journal is written every 0.1 s, so a kill
    part-way leaves tiles recorded done."""
    max_bounces = max(100, int(2 * seconds * speed / 11000))
    return ("[model]\ne = 1.0\nalpha = 1.0\n\n[grid]\n"
            "xi = { min = 0.0, max = 1.0, n = 300 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 300 }\n\n"
            f"[run]\nmax_bounces = {max_bounces}\ntile_points = 400\ncheckpoint_seconds = 0.1\n")


def wall_impacts_per_second(binary, directory):
    """Wall impacts per second of one rank of `binary`, from the summary of a run in which
    every point is capped (max_bounces raised until it takes a quarter of a second). Tests
    that must stop a run part-way size their jobs with it, so that the runs last the same
    few seconds in a release build and under AddressSanitizer. 64 points: enough to fill
    the widest vector kernel (8 lanes) as the jobs it sizes do; with fewer the kernel is
    limited by the latency of one batch, and a job sized by it ends twice too early."""
    job, out = os.path.join(directory, "calibrate.toml"), os.path.join(directory, "calibrate.h5")
    max_bounces = 25000
    while True:
        with open(job, "w") as f:
            f.write(capped_job(max_bounces, n_xi=8, n_W=8))
        r = subprocess.run([binary, "explore", job, "-o", out, "--overwrite"], capture_output=True, text=True,
                           env=mpi_env(), timeout=300)
        assert r.returncode == 0, r.stderr
        seconds = float(r.stderr.split("done: 64 points computed in ")[1].split()[0])
        if seconds >= 0.25 or max_bounces >= 10**9:
            return 64 * max_bounces / max(seconds, 0.01)
        max_bounces *= 4


def tile_boxes(shape, tile_shape):
    """The boxes (tuples of slices) of the tiles of a grid, in tile order (row-major)."""
    import itertools
    per_axis = [range(0, n, t) for n, t in zip(shape, tile_shape)]
    return [tuple(slice(s, min(s + t, n)) for s, t, n in zip(start, tile_shape, shape))
            for start in itertools.product(*per_axis)]


def tile_checksum(dataset_counts, dataset_outcomes, tile, origin):
    """The checksum the partial file records for a tile, computed independently of
    superball: XXH3-64 of the tile's chunk of /wall_bounces, as stored, seeded with the tile's
    number, then of its chunk of /outcome seeded with that."""
    import xxhash  # Debian's python3-xxhash
    counts = dataset_counts.id.read_direct_chunk(origin)[1]
    outcomes = dataset_outcomes.id.read_direct_chunk(origin)[1]
    return xxhash.xxh3_64_intdigest(outcomes, seed=xxhash.xxh3_64_intdigest(counts, seed=tile))


def stored_chunk(values):
    """A chunk as HDF5's shuffle and deflate filters store it, written independently of
    superball (numpy and zlib): the little-endian bytes of the values grouped by
    significance, then a zlib stream."""
    import zlib
    import numpy as np
    data = np.ascontiguousarray(values)
    width = data.dtype.itemsize
    raw = data.astype(data.dtype.newbyteorder("<")).view(np.uint8).reshape(-1, width)
    return zlib.compress(np.ascontiguousarray(raw.T).tobytes(), 6)


def running_journal(partial):
    """The journal (/progress/tile_done) of a partial file that a run is writing, read in
    this process; None while the file does not exist yet or is caught mid-creation. (Tests
    that stop a run part-way poll it; a Python started per look spends most of a short run
    importing h5py.)"""
    import h5py
    try:
        with h5py.File(partial, "r") as f:
            return f["progress/tile_done"][()]
    except (OSError, KeyError):
        return None


def read_partial(path):
    """(counts, outcomes, done flags) of a partial file, read independently of superball:
    an uncompressed file's chunks through h5py, a compressed file's tiles from the bytes
    /progress/tile_stored points at (zlib, then the shuffle undone with numpy). The points
    of tiles not done are zero."""
    import zlib
    import h5py
    import numpy as np
    with h5py.File(path, "r") as f:
        counts_set, outcomes_set = f["wall_bounces"], f["outcome"]
        done = f["progress/tile_done"][()]
        tile_shape = [int(n) for n in f.attrs["tile_shape"]]
        if counts_set.compression is None:
            counts, outcomes = counts_set[()], outcomes_set[()]
        else:
            stored = f["progress/tile_stored"][()]
            counts = np.zeros(counts_set.shape, counts_set.dtype)
            outcomes = np.zeros(outcomes_set.shape, np.uint8)
            width, points = counts_set.dtype.itemsize, int(np.prod(tile_shape))
            with open(path, "rb") as raw:
                for t, box in enumerate(tile_boxes(counts.shape, tile_shape)):
                    if not done[t]:
                        continue
                    at, nc, no = (int(v) for v in stored[t])
                    raw.seek(at)
                    data = raw.read(nc + no)
                    planes = np.frombuffer(zlib.decompress(data[:nc]), np.uint8).reshape(width, points)
                    chunk = np.ascontiguousarray(planes.T).view(f"<u{width}").reshape(tile_shape)
                    codes = np.frombuffer(zlib.decompress(data[nc:]), np.uint8).reshape(tile_shape)
                    part = tuple(slice(0, b.stop - b.start) for b in box)
                    counts[box], outcomes[box] = chunk[part], codes[part]
        for t, box in enumerate(tile_boxes(counts.shape, tile_shape)):
            if not done[t]:
                counts[box], outcomes[box] = 0, 0
    return counts, outcomes, done


def interrupted_run(binary, job, out, reference, done):
    """The partial file (OUT.partial) of an interrupted run of `job`: a run stopped before its
    first tile (--stop-after 0), then the tiles t with done(t) filled with `reference`'s
    values and recorded done with their checksums, as the run would have: uncompressed
    (the job's compression = 0), written to their chunks; compressed, appended past the
    file's end with /progress/tile_stored saying where. Returns its path."""
    import h5py
    import numpy as np
    import xxhash  # Debian's python3-xxhash
    r = subprocess.run([binary, "explore", job, "-o", out, "-q", "--stop-after", "0"], capture_output=True, text=True,
                       env=mpi_env(), timeout=300)
    assert r.returncode == 1, r.stderr
    partial = out + ".partial"
    appended = []
    with h5py.File(reference, "r") as ref, h5py.File(partial, "r+") as f:
        counts, outcomes = f["wall_bounces"], f["outcome"]
        compressed = counts.compression is not None
        flags, sums = f["progress/tile_done"][()], f["progress/tile_checksum"][()]
        tile_shape = [int(n) for n in f.attrs["tile_shape"]]
        if compressed:
            stored, end = f["progress/tile_stored"][()], os.path.getsize(partial)
        for t, box in enumerate(tile_boxes(counts.shape, tile_shape)):
            if not done(t):
                continue
            if compressed:
                # The tile's values in its chunk's layout: full tile shape, zeros past the grid.
                c = np.zeros(tile_shape, dtype=counts.dtype)
                o = np.zeros(tile_shape, dtype=np.uint8)
                part = tuple(slice(0, s.stop - s.start) for s in box)
                c[part], o[part] = ref["wall_bounces"][box], ref["outcome"][box]
                sc, so = stored_chunk(c), stored_chunk(o)
                stored[t] = (end, len(sc), len(so))
                sums[t] = xxhash.xxh3_64_intdigest(so, seed=xxhash.xxh3_64_intdigest(sc, seed=t))
                appended.append(sc + so)
                end += len(sc) + len(so)
            else:
                counts[box] = ref["wall_bounces"][box]
                outcomes[box] = ref["outcome"][box]
                sums[t] = tile_checksum(counts, outcomes, t, tuple(s.start for s in box))
            flags[t] = 1
        if compressed:
            f["progress/tile_stored"][...] = stored
        f["progress/tile_checksum"][...] = sums
        f["progress/tile_done"][...] = flags
    # After h5py has closed the file (it cuts a file opened for writing to its own end).
    with open(partial, "ab") as f:
        for chunk in appended:
            f.write(chunk)
    if compressed:
        # The run resumed and stopped at once, as a stopped run ends: its checks pass over
        # the tiles written here, and the file's HDF5 end is moved past them (as a run's
        # checkpoints do), so that h5py may open it for writing without cutting them off.
        r = subprocess.run([binary, "explore", job, "-o", out, "-q", "--resume", "--stop-after", "0"],
                           capture_output=True, text=True, env=mpi_env(), timeout=300)
        assert r.returncode == 1, r.stderr
    return partial


# Small jobs of every kind of result the outside clients (xarray, netCDF tools, ParaView)
# must read: grids of a few thousand points, each run in well under a second. The axes
# have different lengths, so that a transposed reading cannot pass.
CLIENT_JOBS = {
    "slice": ("[model]\ne = 0.9\nalpha = 0.9\n\n[grid]\n"
              "xi = { min = 0.0, max = 1.0, n = 40 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 30 }\n"),
    "volume": ("[model]\ne = 0.9\nalpha = 0.9\n\n[grid]\n"
               "xi = { min = 0.0, max = 1.0, n = 20 }\nU = { min = -3.0, max = -0.2, n = 12 }\n"
               "W = { min = -3.0, max = 3.0, n = 16 }\n"),
    "physical": ("[model]\ne = 0.9\nalpha = 0.9\ng = 9.81\nradius = 0.025\n\n[grid]\ncoordinates = \"physical\"\n"
                 "x = { min = 0.0, max = 0.2, n = 30 }\nu = { min = -3.0, max = 1.0, n = 20 }\nv = 2.0\nomega = -200.0\n"),
    "swept": ("[model]\ne = 0.9\nalpha = { min = 0.5, max = 1.0, n = 5 }\ne_floor = 0.8\n\n[grid]\n"
              "xi = { min = 0.0, max = 1.0, n = 40 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 30 }\n"),
}


def client_results(directory, kinds, names=None):
    """Results of CLIENT_JOBS[kind] for each of `kinds`, computed by the binary under test
    with two ranks in `directory`; `names` maps a kind to its output's file name (default
    KIND.h5). Returns {kind: absolute path of the result}."""
    binary = superball_binary()
    mpiexec = os.environ.get("MPIEXEC") or "mpirun"
    paths = {}
    for kind in kinds:
        name = (names or {}).get(kind, kind + ".h5")
        job, out = os.path.join(directory, kind + ".toml"), os.path.abspath(os.path.join(directory, name))
        with open(job, "w") as f:
            f.write(CLIENT_JOBS[kind] + "\n[run]\nmax_bounces = 1000\n")
        cmd = [mpiexec, "-n", "2", "--oversubscribe", binary, "explore", job, "-o", out, "-q"]
        r = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(), timeout=300)
        assert r.returncode == 0, f"{' '.join(cmd)}\n{r.stderr}"
        paths[kind] = out
    return paths


class Server:
    """`superball serve ARGS... --port 0` started for a test, on a free loopback port (the
    server picks it and prints its URL); a context manager that stops it with SIGTERM and
    checks that it exits cleanly."""

    def __init__(self, *args, binary=None):
        import select
        self.process = subprocess.Popen([binary or superball_binary(), "serve", "--port", "0", *args],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        ready, _, _ = select.select([self.process.stdout], [], [], 60)
        line = self.process.stdout.readline() if ready else ""
        if "http://" not in line:
            self.process.kill()
            raise AssertionError(f"superball serve printed no URL: {line!r} {self.process.stderr.read()}")
        self.url = line.split()[2]  # "superball serve: URL (Ctrl-C to stop)"

    def get(self, path, timeout=60):
        """(status, headers, body bytes) of GET url + path."""
        import urllib.error
        import urllib.request
        try:
            with urllib.request.urlopen(self.url + path.lstrip("/"), timeout=timeout) as r:
                return r.status, dict(r.headers), r.read()
        except urllib.error.HTTPError as e:
            return e.code, dict(e.headers), e.read()

    def json(self, path, timeout=60):
        """(status, decoded JSON body) of GET url + path."""
        import json
        status, _, body = self.get(path, timeout)
        return status, json.loads(body)

    def rss_kib(self):
        """The server's resident memory now and at its peak (VmRSS, VmHWM), in KiB."""
        with open(f"/proc/{self.process.pid}/status") as f:
            fields = dict(line.split(":", 1) for line in f)
        return int(fields["VmRSS"].split()[0]), int(fields["VmHWM"].split()[0])

    def stop(self):
        import signal
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise AssertionError("superball serve did not stop within 30 s of SIGTERM")
        stderr = self.process.stderr.read()
        self.process.stdout.close()
        self.process.stderr.close()
        return self.process.returncode, stderr

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        code, stderr = self.stop()
        if exc[0] is None:
            assert code == 0, f"superball serve exited with {code}: {stderr}"
