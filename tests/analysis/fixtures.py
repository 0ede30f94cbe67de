"""Small superball result files for testing the analysis scripts.

`make_result` writes a file laid out exactly as SPEC.md section 5 with h5py, so
the scripts can be tested before (and independently of) the MPI explorer.  It
takes the grid the way a job file states it (SPEC.md section 4), so that a
later version can, when no data is imposed, write that job and run
`superball explore` instead; the tests read expected values back from the
file, never from the fixture's arguments, so they hold for either source.
"""

import h5py
import numpy as np

COORDINATE_NAMES = {"canonical": ("xi", "U", "W"), "physical": ("x", "u", "v", "omega")}
MODEL = {"e_wall": 0.9, "alpha_wall": 0.9, "e_floor": 0.9, "alpha_floor": 0.9}
INVALID, LEFT, MISSED, CAPPED = range(4)


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


def make_result(path, grid, *, data=None, coordinates="canonical", model=None, max_bounces=1000,
                complete=True, tiles=4, tiles_done=None, g=9.81, radius=0.025):
    """Write a result file and return its path.

    grid: every coordinate of the system, {name: (min, max, n)} for a range or
          {name: value} for a fixed coordinate, as in a job's [grid] table.
    data: (wall_bounces, outcome) arrays of the grid's shape (range axes in
          SPEC order), or a function (shape, max_bounces) returning them; default banded_data.
    complete / tiles / tiles_done: attribute complete and /progress/tile_done
          (tiles_done: how many of the `tiles` are set; default all if complete).
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
    if tiles_done is None:
        tiles_done = tiles if complete else tiles // 2

    with h5py.File(path, "w") as f:
        count_type = np.uint32 if max_bounces > 65535 else np.uint16
        f.create_dataset("wall_bounces", data=counts.astype(count_type))
        f.create_dataset("outcome", data=outcome.astype(np.uint8))
        for name in ranges:
            f.create_dataset(f"axes/{name}", data=samples(*grid[name]).astype(np.float64))
        f.create_dataset("progress/tile_done", data=(np.arange(tiles) < tiles_done).astype(np.uint8))
        attrs = f.attrs
        attrs["coordinates"] = coordinates
        attrs["axis_names"] = ranges
        for key, value in model.items():
            attrs[key] = float(value)
        if coordinates == "physical":
            attrs["g"], attrs["radius"] = float(g), float(radius)
        for name in names:
            if not isinstance(grid[name], tuple):
                attrs[f"fixed_{name}"] = float(grid[name])
        attrs["max_bounces"] = np.uint32(max_bounces)
        attrs["job_toml"] = job_text(grid, coordinates, model, max_bounces, path)
        attrs["software_version"] = "test fixture"
        attrs["mpi_ranks"] = np.int32(1)
        attrs["wall_seconds"] = 0.0
        attrs["complete"] = np.uint8(1 if complete else 0)
    return path
