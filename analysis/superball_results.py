"""Shared helpers of the superball analysis scripts.

Reading a result file (SPEC.md section 5) in one place keeps the scripts agreeing
on what its attributes mean, how axes are named and labelled, and how a title
describes a map; the command-line plumbing (errors, exit statuses, figure sizes)
lives here for the same reason.  Only numpy and h5py are imported at module
level so that non-plotting scripts (summary.py) stay light: plotting scripts
get matplotlib through `pyplot()`.
"""

import os
import sys

import h5py
import numpy as np

# Outcome codes of SPEC.md section 3, indexed by code.
OUTCOME_NAMES = ("invalid", "left", "missed", "capped")
INVALID, LEFT, MISSED, CAPPED = range(4)

# Coordinate names in result-file dimension order (SPEC.md sections 2 and 5).
COORDINATE_NAMES = {"canonical": ("xi", "U", "W"), "physical": ("x", "u", "v", "omega")}

# Axis labels: the SPEC name, then its definition or unit.
AXIS_LABELS = {
    "xi": "xi = g x / (2 |u| v)",
    "U": "U = u / v",
    "W": "W = a omega / v",
    "x": "x [m]",
    "u": "u [m/s]",
    "v": "v [m/s]",
    "omega": "omega [rad/s]",
}

# Model attributes shown in titles and summaries, in this order when present.
MODEL_ATTRIBUTES = ("e_wall", "alpha_wall", "e_floor", "alpha_floor", "g", "radius")

# Exit statuses of SPEC.md section 6.
EXIT_BAD_INPUT = 2
EXIT_FAILURE = 1


class ScriptError(Exception):
    """A failure to report in one line and turn into an exit status.

    The default status 2 is SPEC's "bad input"; the message must name what is wrong.
    """

    def __init__(self, message, status=EXIT_BAD_INPUT):
        super().__init__(message)
        self.status = status


def run_script(main):
    """Run a script's `main()` and exit with SPEC's statuses.

    ScriptError becomes its status with the message on stderr; other I/O errors
    (an unwritable output, say) become status 1 with the message rather than a
    traceback.  A closed pipe (`summary.py x.h5 | head`) is not an error.
    """
    prog = os.path.basename(sys.argv[0])
    try:
        status = main()
    except ScriptError as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        status = error.status
    except BrokenPipeError:
        # The reader went away: send what is still buffered nowhere instead of failing at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        status = 0
    except OSError as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        status = EXIT_FAILURE
    sys.exit(status or 0)


def run_superball(command, arguments):
    """Standard output of `superball COMMAND ARGUMENTS` (the binary from $SUPERBALL, else
    `superball` on PATH); a leading COMMAND in ARGUMENTS is dropped. A failure becomes a
    ScriptError with the binary's message and its status (1 or 2)."""
    import shutil
    import subprocess

    binary = os.environ.get("SUPERBALL") or shutil.which("superball")
    if not binary:
        raise ScriptError("cannot find the superball binary: set SUPERBALL or put superball on PATH", EXIT_FAILURE)
    if arguments and arguments[0] == command:
        arguments = arguments[1:]
    argv = [binary, command] + list(arguments)
    process = subprocess.run(argv, capture_output=True, text=True)
    if process.returncode != 0:
        status = process.returncode if process.returncode in (1, 2) else EXIT_FAILURE
        raise ScriptError(f"{' '.join(argv)} failed: {process.stderr.strip()}", status)
    return process.stdout


def warn(message):
    """Print a warning on stderr, prefixed with the script's name."""
    print(f"{os.path.basename(sys.argv[0])}: warning: {message}", file=sys.stderr)


def pyplot():
    """matplotlib.pyplot with the Agg backend (no display needed, same output everywhere)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def parse_size(text):
    """Parse a figure size 'WIDTHxHEIGHT' in pixels (an argparse type)."""
    import argparse

    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size {text!r} is not WIDTHxHEIGHT in pixels, e.g. 1000x700")
    if width < 50 or height < 50:
        raise argparse.ArgumentTypeError(f"size {text!r}: width and height must be at least 50 pixels")
    return width, height


def new_figure(size, dpi, **kwargs):
    """A figure of exactly `size` = (width, height) pixels at `dpi`, with constrained layout.

    Saving without bbox_inches='tight' keeps that pixel size, which the tests rely on.
    """
    plt = pyplot()
    width, height = size
    return plt.figure(figsize=(width / dpi, height / dpi), dpi=dpi, layout="constrained", **kwargs)


def format_number(value):
    """Short text of a number for titles and tables (6 significant digits). A swept
    coefficient's attribute is a text naming its axis ("axis:alpha"), shown as it is."""
    value = decode(value)
    if isinstance(value, str):
        return value
    return f"{value:.6g}"


def join_values(values, equals=" = "):
    """'name = value, ...' of a dict of numbers, for titles and reports."""
    return ", ".join(f"{name}{equals}{format_number(value)}" for name, value in values.items())


def decode(value):
    """An HDF5 attribute as Python text/numbers: bytes and arrays of bytes become str."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "SOU":
            return [decode(item) for item in value.tolist()]
        return value.item() if value.size == 1 else value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def iter_blocks(shape, max_elements):
    """Index tuples of blocks covering an array of `shape`, each at most `max_elements` points.

    Trailing axes are taken whole as long as they fit, then one axis is cut into
    runs, and leading axes go one index at a time.  Blocks follow the storage
    order, so h5py reads contiguous hyperslabs and never the whole array.
    """
    shape = tuple(int(n) for n in shape)
    if any(n == 0 for n in shape):
        return
    max_elements = max(1, int(max_elements))
    whole = 1  # points in the trailing axes taken whole
    cut = len(shape) - 1  # the axis cut into runs
    while cut >= 0 and whole * shape[cut] <= max_elements:
        whole *= shape[cut]
        cut -= 1
    if cut < 0:
        yield tuple(slice(None) for _ in shape)
        return
    run = max(1, max_elements // whole)
    for lead in np.ndindex(*shape[:cut]):
        for start in range(0, shape[cut], run):
            rest = (slice(None),) * (len(shape) - cut - 1)
            yield tuple(lead) + (slice(start, min(start + run, shape[cut])),) + rest


class Result:
    """An open result file (SPEC.md section 5): layout checked, axes and attributes decoded.

    The two big datasets are left on disk (`counts`, `outcomes` are h5py datasets)
    so that callers read only the slices or blocks they need.
    """

    def __init__(self, path):
        self.path = path
        if not os.path.exists(path):
            raise ScriptError(f"result file {path!r} does not exist")
        try:
            self.file = h5py.File(path, "r")
        except OSError as error:
            hint = ""
            if "lock" in str(error).lower():
                hint = "; a run still writing it locks it: wait, or set HDF5_USE_FILE_LOCKING=FALSE to peek"
            raise ScriptError(f"cannot open {path!r} as an HDF5 result ({error}){hint}")
        try:
            self._check_layout()
        except ScriptError:
            self.file.close()
            raise

    def _check_layout(self):
        """Fail early, naming the missing piece, rather than deep inside a plot."""
        for name in ("wall_bounces", "outcome"):
            if not isinstance(self.file.get(name), h5py.Dataset):
                raise ScriptError(f"{self.path}: dataset /{name} is missing (not a superball result?)")
        self.counts = self.file["wall_bounces"]
        self.outcomes = self.file["outcome"]
        if self.counts.shape != self.outcomes.shape:
            raise ScriptError(
                f"{self.path}: /wall_bounces {self.counts.shape} and /outcome {self.outcomes.shape} differ in shape"
            )
        self.attrs = {key: decode(value) for key, value in self.file.attrs.items()}
        self.axis_names = self._axis_names()
        if len(self.axis_names) != self.counts.ndim:
            raise ScriptError(
                f"{self.path}: {self.counts.ndim}-D data but axis_names lists {len(self.axis_names)} "
                f"axes ({', '.join(self.axis_names)})"
            )
        self.axes = {}
        for name, n in zip(self.axis_names, self.counts.shape):
            # A coordinate variable at the root (netCDF layout); /axes/<name> in files of superball 0.1.
            dataset = self.file.get(name)
            if not isinstance(dataset, h5py.Dataset):
                dataset = self.file.get(f"axes/{name}")
            if not isinstance(dataset, h5py.Dataset) or dataset.shape != (n,):
                raise ScriptError(f"{self.path}: /{name} is missing or does not hold {n} samples")
            self.axes[name] = dataset[()].astype(np.float64)

    def _axis_names(self):
        """Names of the dimensions: attribute axis_names, else the /axes group in SPEC order."""
        names = self.attrs.get("axis_names")
        if isinstance(names, str):
            names = names.replace(",", " ").split()
        if names is None:
            present = set(self.file["axes"].keys()) if "axes" in self.file else set()
            names = [n for system in COORDINATE_NAMES.values() for n in system if n in present]
        return [str(n) for n in names]

    def close(self):
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def shape(self):
        return self.counts.shape

    @property
    def coordinates(self):
        """'canonical' or 'physical' (attribute coordinates; inferred from axis names if absent)."""
        value = self.attrs.get("coordinate_system", self.attrs.get("coordinates"))
        if value in COORDINATE_NAMES:
            return value
        physical = any(n in COORDINATE_NAMES["physical"] for n in self.axis_names)
        return "physical" if physical else "canonical"

    @property
    def max_bounces(self):
        return self.attrs.get("max_bounces")

    @property
    def complete(self):
        """True/False from attribute complete, None when the file does not say."""
        value = self.attrs.get("complete")
        return None if value is None else bool(value)

    def model(self):
        """Model coefficients (and g, radius for physical grids) present in the file, in display order."""
        return {key: self.attrs[key] for key in MODEL_ATTRIBUTES if key in self.attrs}

    def fixed(self):
        """Fixed coordinates {name: value} from attributes fixed_<name>, in coordinate order."""
        fixed = {key[len("fixed_"):]: value for key, value in self.attrs.items() if key.startswith("fixed_")}
        order = COORDINATE_NAMES[self.coordinates]
        return dict(sorted(fixed.items(), key=lambda item: order.index(item[0]) if item[0] in order else len(order)))

    def tiles(self):
        """(tiles done, tiles) from /progress/tile_done, or None if the file has no progress record."""
        dataset = self.file.get("progress/tile_done")
        if not isinstance(dataset, h5py.Dataset):
            return None
        done = dataset[()]
        return int(np.count_nonzero(done)), int(done.size)

    def model_text(self):
        """One line with every coefficient and max_bounces, for titles."""
        return f"{join_values(self.model(), '=')}, max_bounces={self.max_bounces}"

    def fixed_text(self):
        """'U = -1, W = 0.5': the coordinates fixed in the job."""
        return join_values(self.fixed())


def axis_label(name):
    """Axis label with the SPEC name and its definition or unit."""
    return AXIS_LABELS.get(name, name)


def warn_if_incomplete(result):
    """Warn that a run did not finish: unfinished tiles hold zeros (outcome invalid)."""
    if result.complete is False:
        tiles = result.tiles()
        detail = f" ({tiles[0]} of {tiles[1]} tiles done)" if tiles else ""
        warn(f"{result.path} is incomplete{detail}: unfinished points show as invalid")
        return True
    return False


def cell_edges(samples):
    """Edges of the cells whose centres are `samples` (uniform, cell-centred as in SPEC section 4).

    Returned as (first edge, last edge) following the samples' order, so a
    decreasing axis keeps its orientation; a single sample gets a unit cell.
    """
    if len(samples) == 1:
        return samples[0] - 0.5, samples[0] + 0.5
    half = 0.5 * (samples[-1] - samples[0]) / (len(samples) - 1)
    return samples[0] - half, samples[-1] + half
