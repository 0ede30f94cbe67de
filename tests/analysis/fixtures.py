"""Small superball files for testing the analysis scripts.

`make_result` writes, with h5py alone, a file laid out as superball writes them
(src/io/layout.hpp): a complete *result* (netCDF-4/CF layout: coordinate variables at
the root as dimension scales, compressed chunks), or with complete=False the *partial*
file of an interrupted run (one uncompressed chunk per tile, the journal
/progress/tile_done and /progress/tile_checksum, zeros in the tiles not done), so the
scripts can be tested independently of the MPI explorer; tests/analysis/test_analysis.py
checks that `superball info` accepts every kind it makes.  It takes the grid the way a
job file states it (SPEC.md section 4); the tests read expected values back from the
file, never from the fixture's arguments, so they hold for either source.
"""

import itertools
import math
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import stored_chunk, tile_boxes, tile_checksum  # noqa: E402

COORDINATE_NAMES = {"canonical": ("xi", "U", "W"), "physical": ("x", "u", "v", "omega")}
MODEL = {"e_wall": 0.9, "alpha_wall": 0.9, "e_floor": 0.9, "alpha_floor": 0.9}
INVALID, LEFT, MISSED, CAPPED = range(4)
FORMAT_VERSION = 3


def samples(low, high, n):
    """Cell-centred samples of a range, as SPEC.md section 4 defines them."""
    return low + (np.arange(n) + 0.5) * (high - low) / n


def banded_data(shape, max_bounces):
    """Deterministic stand-in for real counts: diagonal bands of N = 0..5, with
    an invalid row along the first axis's start and a few capped points."""
    index_sum = sum(np.indices(shape))
    counts = (index_sum // 3 % 6).astype(np.int64)
    outcome = np.where(counts == 0, MISSED, LEFT)
    first = (0,) + (slice(None),) * (len(shape) - 1)
    outcome[first], counts[first] = INVALID, 0
    capped = index_sum % 17 == 5
    outcome[capped], counts[capped] = CAPPED, max_bounces
    return counts, outcome


def job_text(grid, coordinates, model, max_bounces, output):
    """The job file (TOML, SPEC.md section 4) that describes this result."""
    lines = ["[model]"] + [f"{key} = {value!r}" for key, value in model.items()]
    lines += ["", "[grid]", f'coordinates = "{coordinates}"']
    for name in COORDINATE_NAMES[coordinates]:
        spec = grid[name]
        if isinstance(spec, tuple):
            lines.append(f"{name} = {{ min = {spec[0]!r}, max = {spec[1]!r}, n = {spec[2]} }}")
        else:
            lines.append(f"{name} = {spec!r}")
    lines += ["", "[run]", f"max_bounces = {max_bounces}", f'output = "{output}"', ""]
    return "\n".join(lines)


def tile_shape_for(shape, tiles):
    """A tile shape that cuts `shape` into exactly `tiles` tiles, as near-cubic as can be."""
    best = None
    for tile in itertools.product(*(range(1, n + 1) for n in shape)):
        if math.prod(-(-n // t) for n, t in zip(shape, tile)) == tiles:
            spread = max(tile) / min(tile)
            if best is None or spread < best[0]:
                best = (spread, tile)
    if best is None:
        raise ValueError(f"no tiling of {shape} has exactly {tiles} tiles")
    return list(best[1])


def make_result(path, grid, *, data=None, coordinates="canonical", model=None, max_bounces=1000,
                complete=True, tiles=4, tiles_done=None, g=9.81, radius=0.025, compressed=False):
    """Write a result file (complete) or a partial file (complete=False) and return its path.

    grid: every coordinate of the system, {name: (min, max, n)} for a range or
          {name: value} for a fixed coordinate, as in a job's [grid] table.
    data: (wall_bounces, outcome) arrays of the grid's shape (range axes in
          SPEC order), or a function (shape, max_bounces) returning them; default banded_data.
    complete=False: a partial file of `tiles` tiles, the first `tiles_done` of them done
          (default half) holding the data, the others zero as a run leaves them;
          compressed=True: the tiles done compressed (shuffle + deflate) past the file's
          HDF5 objects, /progress/tile_stored saying where, as a run writes them by default.
    """
    model = dict(MODEL if model is None else model)
    names = COORDINATE_NAMES[coordinates]
    if set(grid) != set(names):
        raise ValueError(f"grid must give exactly {names}, got {sorted(grid)}")
    ranges = [name for name in names if isinstance(grid[name], tuple)]
    shape = tuple(grid[name][2] for name in ranges)
    if data is None:
        data = banded_data
    counts, outcome = data(shape, max_bounces) if callable(data) else data
    counts, outcome = np.asarray(counts), np.asarray(outcome)
    if counts.shape != shape or outcome.shape != shape:
        raise ValueError(f"data of shape {counts.shape}/{outcome.shape}, grid of shape {shape}")
    count_type = np.dtype("<u4") if max_bounces > 65535 else np.dtype("<u2")

    with h5py.File(path, "w", libver=("v110", "latest")) as f:
        if complete:
            storage = {"chunks": True, "compression": "gzip", "compression_opts": 4, "shuffle": True}
        else:
            tile_shape = tile_shape_for(shape, tiles)
            boxes = tile_boxes(shape, tile_shape)
            if tiles_done is None:
                tiles_done = tiles // 2
            done = (np.arange(tiles) < tiles_done).astype(np.uint8)
            counts, outcome = counts.copy(), outcome.copy()
            for t, box in enumerate(boxes):
                if not done[t]:
                    counts[box], outcome[box] = 0, 0
            storage = {"chunks": tuple(tile_shape)}
        if not complete and compressed:
            # Declared as the result's, no chunk written: the tiles go past the end below.
            storage.update(compression="gzip", compression_opts=4, shuffle=True)
            f.create_dataset("wall_bounces", shape=shape, dtype=count_type, **storage)
            f.create_dataset("outcome", shape=shape, dtype="<u1", **storage)
        else:
            f.create_dataset("wall_bounces", data=counts.astype(count_type), **storage)
            f.create_dataset("outcome", data=outcome.astype("<u1"), **storage)
        write_metadata(f, grid, ranges, coordinates, model, max_bounces, path, g, radius, complete)
        if not complete:
            f.attrs["tile_shape"] = np.array(tile_shape, dtype="<u8")
            sums = np.zeros(tiles, dtype="<u8")
            for t, box in enumerate(boxes):
                if done[t] and not compressed:
                    sums[t] = tile_checksum(f["wall_bounces"], f["outcome"], t, tuple(s.start for s in box))
            f.create_dataset("progress/tile_done", data=done)
            f.create_dataset("progress/tile_checksum", data=sums)
            if compressed:
                f.create_dataset("progress/tile_stored", data=np.zeros((tiles, 3), dtype="<u8"))
    if not complete and compressed:
        append_compressed_tiles(path, counts.astype(count_type), outcome.astype("<u1"), tile_shape, done)
    return path


def append_compressed_tiles(path, counts, outcome, tile_shape, done):
    """Appends the done tiles' stored chunks past the end of the partial file at `path`
    (written and closed by h5py, which cuts a file opened for writing to its own end)
    and records where they lie and their checksums in its journal."""
    import xxhash  # Debian's python3-xxhash
    boxes = tile_boxes(counts.shape, tile_shape)
    end = os.path.getsize(path)
    stored = np.zeros((len(boxes), 3), dtype="<u8")
    sums = np.zeros(len(boxes), dtype="<u8")
    chunks = []
    for t, box in enumerate(boxes):
        if not done[t]:
            continue
        c, o = np.zeros(tile_shape, counts.dtype), np.zeros(tile_shape, np.uint8)
        part = tuple(slice(0, b.stop - b.start) for b in box)
        c[part], o[part] = counts[box], outcome[box]
        sc, so = stored_chunk(c), stored_chunk(o)
        stored[t] = (end, len(sc), len(so))
        sums[t] = xxhash.xxh3_64_intdigest(so, seed=xxhash.xxh3_64_intdigest(sc, seed=t))
        chunks.append(sc + so)
        end += len(sc) + len(so)
    with h5py.File(path, "r+") as f:
        f["progress/tile_stored"][...] = stored
        f["progress/tile_checksum"][...] = sums
    with open(path, "ab") as f:
        for chunk in chunks:
            f.write(chunk)


def write_metadata(f, grid, ranges, coordinates, model, max_bounces, path, g, radius, complete):
    """Coordinate variables and root attributes, as superball writes them (src/io/result_metadata.cpp)."""
    for k, name in enumerate(ranges):
        axis = f.create_dataset(name, data=samples(*grid[name]).astype("<f8"))
        axis.make_scale(name)
        f["wall_bounces"].dims[k].attach_scale(axis)
        f["outcome"].dims[k].attach_scale(axis)
    attrs = f.attrs
    for name in COORDINATE_NAMES[coordinates]:
        if not isinstance(grid[name], tuple):
            f.create_dataset(name, data=np.float64(grid[name]))
            attrs[f"fixed_{name}"] = float(grid[name])
    f["outcome"].attrs["flag_values"] = np.arange(4, dtype=np.uint8)
    f["outcome"].attrs["flag_meanings"] = "invalid left missed capped"
    attrs["superball_file"] = "result" if complete else "partial"
    attrs["superball_format"] = np.int64(FORMAT_VERSION)
    attrs["Conventions"] = "CF-1.8"
    attrs["coordinate_system"] = coordinates
    attrs["axis_names"] = ranges
    for key, value in model.items():
        attrs[key] = float(value)
    if coordinates == "physical":
        attrs["g"], attrs["radius"] = float(g), float(radius)
    attrs["max_bounces"] = np.int64(max_bounces)
    attrs["refine"] = np.int64(0)
    text = job_text(grid, coordinates, model, max_bounces, path)
    attrs["job_toml"] = text
    attrs["job_fingerprint"] = "test fixture\n" + text
    attrs["software_version"] = "test fixture"
    attrs["mpi_ranks"] = np.int64(1)
    attrs["wall_seconds"] = 0.0
    attrs["complete"] = np.int64(1 if complete else 0)
