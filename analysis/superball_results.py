"""Shared helpers of the superball analysis scripts.

Reading a result file (src/io/layout.hpp) in one place keeps the scripts agreeing
on what its attributes mean, how axes are named and labelled, and how a title
describes a map; the command-line plumbing (errors, exit statuses, figure sizes)
lives here for the same reason.  Only numpy and h5py are imported at module
level so that non-plotting scripts (summary.py) stay light: plotting scripts
get matplotlib through `pyplot()`.
"""

import itertools
import math
import os
import sys
import zlib

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


# The file layout (src/io/layout.hpp): what superball writes and this module reads.
# Format 3: partial files may hold compressed tiles past their HDF5 objects
# (/progress/tile_stored); results are laid out as in format 2, which is still read.
FORMAT_VERSION = 3
OLDEST_RESULT_FORMAT = 2
KIND_RESULT, KIND_PARTIAL = "result", "partial"
COEFFICIENT_NAMES = ("e", "alpha", "e_wall", "alpha_wall", "e_floor", "alpha_floor", "mu", "mu_wall", "mu_floor", "inertia")
# SPEC.md 1b's coefficients (results of superball 0.1.x written before them have none) and
# their defaults: the Cross model of a solid ball.
FRICTION_DEFAULTS = {"mu_wall": math.inf, "mu_floor": math.inf, "inertia": 0.4}
# Limits of a sound file, as the C++ reader's (src/io/result_reader.cpp): beyond 2^40
# points a file is damaged, not big; a job file is a few hundred bytes.
MAX_POINTS = 1 << 40
MAX_TEXT_BYTES = 4096
MAX_JOB_BYTES = 1 << 20
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
# Errors h5py raises on a file whose structure or data HDF5 cannot read.
H5PY_ERRORS = (OSError, KeyError, ValueError, TypeError, RuntimeError, IndexError)


def describe_file(path):
    """What is at `path`, for messages: 'a directory', 'an empty file', 'a text file of ...'."""
    if os.path.isdir(path):
        return "a directory"
    if not os.path.isfile(path):
        return "not a regular file"
    size = os.path.getsize(path)
    if size == 0:
        return "an empty file"
    try:
        with open(path, "rb") as f:
            head = f.read(512)
    except OSError as error:
        return f"a file that cannot be read ({error.strerror})"
    if is_hdf5(path):
        return "an HDF5 file"
    if all(b >= 0x20 or b in b"\n\r\t" for b in head):
        first = head.split(b"\n", 1)[0][:40].decode("utf-8", "backslashreplace")
        return f'a text file of {size} bytes, beginning "{printable(first)}"'
    return f"a binary file of {size} bytes"


def is_hdf5(path):
    """True if the file begins with HDF5's signature (at 0, 512, 1024, ...: after a user block)."""
    with open(path, "rb") as f:
        at = 0
        while at < (1 << 30):
            f.seek(at)
            head = f.read(8)
            if len(head) < 8:
                return False
            if head == HDF5_SIGNATURE:
                return True
            at = 512 if at == 0 else 2 * at
    return False


def printable(text, limit=60):
    """A text of a file, for a message: at most `limit` characters, with control characters
    escaped, so that a damaged file cannot garble a terminal (as the
    C++ reader's messages)."""
    out = []
    for ch in str(text)[:limit]:
        if ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\x{ord(ch):02x}")
        elif not ch.isprintable():
            out.append(ch.encode("unicode_escape").decode("ascii"))
        else:
            out.append(ch)
    return "".join(out) + ("..." if len(str(text)) > limit else "")


GLOBAL_HEAP_SIGNATURE = b"GCOL\x01\x00\x00\x00"


def damaged_global_heap(path, skip):
    """The offset of the first damaged global heap collection of the file, or None.

    HDF5 1.10 keeps variable-length values (texts, DIMENSION_LIST) in global heap
    collections, which have no checksum, and trusts the sizes of their objects: a damaged
    size makes it copy past its buffers when the values are read (a crash or a hang, not
    an error).  Each collection found outside the byte ranges `skip` (raw data, (offset,
    size)) is walked as HDF5 walks it (src/io/hdf5.cpp: damaged_global_heap, the same).
    """
    size = os.path.getsize(path)
    block = 16 << 20
    with open(path, "rb") as f:
        def intact(at):
            f.seek(at)
            header = f.read(16)
            if len(header) < 16:
                return False
            total = int.from_bytes(header[8:16], "little")
            if total < 4096 or total > size - at or total > (1 << 30):
                return False
            f.seek(at)
            heap = f.read(total)
            seen, p = set(), 16
            while p < total and total - p >= 16:
                index = int.from_bytes(heap[p:p + 2], "little")
                length = int.from_bytes(heap[p + 8:p + 16], "little")
                if length > total:
                    return False
                need = 16 + (length + 7) // 8 * 8 if index else length
                if need < 16 or need > total - p or (index and index in seen):
                    return False
                seen.add(index)
                p += need
            return len(heap) == total

        def scan(start, stop):
            pos = start
            while pos < stop:
                f.seek(pos)
                data = f.read(min(block, stop - pos))
                at = data.find(GLOBAL_HEAP_SIGNATURE)
                while at >= 0:
                    if not intact(pos + at):
                        return pos + at
                    at = data.find(GLOBAL_HEAP_SIGNATURE, at + 1)
                if len(data) < block:
                    return None
                pos += block - (len(GLOBAL_HEAP_SIGNATURE) - 1)
            return None

        start = 0
        for offset, length in sorted(skip):
            if offset > start:
                bad = scan(start, min(offset, size))
                if bad is not None:
                    return bad
            start = max(start, offset + length)
        return scan(start, size) if start < size else None


def raw_data_ranges(file):
    """Byte ranges (offset, size) of a file's big raw data, which damaged_global_heap need
    not search: contiguous datasets, chunked ones without filters whose chunks lie one
    after the other (an uncompressed partial file's), and the tiles a compressed partial
    file records done."""
    ranges = []
    try:
        done, stored = file.get("progress/tile_done"), file.get("progress/tile_stored")
        if (isinstance(done, h5py.Dataset) and isinstance(stored, h5py.Dataset) and done.ndim == 1
                and stored.shape == (done.shape[0], 3) and done.shape[0] <= MAX_POINTS):
            flags, where = done[()], stored[()].astype(np.uint64)
            for t in np.flatnonzero(flags == 1):
                ranges.append((int(where[t, 0]), int(where[t, 1]) + int(where[t, 2])))
    except H5PY_ERRORS:
        pass
    for name in ("wall_bounces", "outcome", "progress/tile_done", "progress/tile_checksum", "progress/tile_stored"):
        try:
            dataset = file.get(name)
            if not isinstance(dataset, h5py.Dataset) or 0 in (dataset.shape or (0,)):
                continue
            plist = dataset.id.get_create_plist()
            if plist.get_layout() != h5py.h5d.CHUNKED:
                offset = dataset.id.get_offset()
                if offset is not None:
                    ranges.append((offset, dataset.id.get_storage_size()))
                continue
            if plist.get_nfilters():
                continue
            chunk = plist.get_chunk()
            chunks = math.prod(-(-n // c) for n, c in zip(dataset.shape, chunk))
            if dataset.id.get_num_chunks() != chunks:
                continue
            chunk_bytes = dataset.id.get_type().get_size() * math.prod(chunk)
            first = dataset.id.get_chunk_info_by_coord((0,) * len(chunk)).byte_offset
            last = dataset.id.get_chunk_info_by_coord(tuple((n - 1) // c * c for n, c in zip(dataset.shape, chunk)))
            if last.byte_offset == first + (chunks - 1) * chunk_bytes:
                ranges.append((first, chunks * chunk_bytes))
        except H5PY_ERRORS:
            pass
    return ranges


def shape_text(type_class, shape):
    """What an attribute or dataset holds: 'a text', 'a list of 2 integers', ..."""
    kind = {h5py.h5t.STRING: "text", h5py.h5t.INTEGER: "integer", h5py.h5t.FLOAT: "floating-point number"}.get(
        type_class, "value of another type")
    if shape == ():
        return f"{'an' if kind == 'integer' else 'a'} {kind}"
    if shape is None or 0 in shape:
        return "empty"
    if len(shape) == 1:
        return f"a list of {shape[0]} {kind}s"
    return f"an array ({', '.join(map(str, shape))}) of {kind}s"


class Result:
    """An open superball file, result or partial (src/io/layout.hpp), validated as it is read.

    Opening checks the structure as the C++ reader does (src/io/result_reader.cpp): the
    kind and format, every attribute's type, shape and range, the data's types and shapes,
    the coordinate variables and their dimension scales, a partial file's tiling and
    journal; anything wrong is a ScriptError naming the file and the object.  `read()`
    checks the values it returns (outcome codes, counts against max_bounces, a partial
    file's tiles against their checksums) and reads the points of tiles not yet done as
    invalid; a partial file is announced with a warning.  The two big datasets stay on
    disk (`counts`, `outcomes` are h5py datasets): callers read the blocks they need.
    """

    def __init__(self, path):
        self.path = path
        if not os.path.exists(path):
            raise ScriptError(f"{path}: no such file")
        if not os.path.isfile(path):
            raise ScriptError(f"{path} is {describe_file(path)}, not a superball file")
        try:
            hdf5 = is_hdf5(path)
        except OSError as error:
            raise ScriptError(f"{path} cannot be read ({error.strerror})")
        if not hdf5:
            raise ScriptError(f"{path} is {describe_file(path)}, not a superball result")
        try:
            self.file = h5py.File(path, "r")
        except H5PY_ERRORS as error:
            hint = ""
            if "lock" in str(error).lower():
                hint = "; a run still writing it locks it: wait, or set HDF5_USE_FILE_LOCKING=FALSE to peek"
            raise ScriptError(f"{path} is an HDF5 file that cannot be opened, damaged or truncated ({error}){hint}")
        try:
            # Before any text is read: HDF5 reads variable-length values without checking them.
            bad = damaged_global_heap(path, raw_data_ranges(self.file))
            if bad is not None:
                self.fail(f"the global heap at byte {bad} (where HDF5 keeps texts and dimension-scale lists) is "
                          "damaged: its objects do not fit it")
            self._validate()
        except ScriptError:
            self.file.close()
            raise
        except H5PY_ERRORS as error:
            self.file.close()
            raise ScriptError(f"{path} is damaged: {error}")
        self._verified = np.zeros(self.tile_count, dtype=bool)
        self._checksums_unchecked = False

    # --- structure ----------------------------------------------------------------------

    def fail(self, what):
        raise ScriptError(f"{self.path}: {what}")

    def _attribute(self, name, obj=None):
        """(type class, shape, type) of an attribute, or a refusal naming it if it is missing."""
        obj = self.file if obj is None else obj
        if name not in obj.attrs:
            self.fail(f"attribute {name} is missing")
        attribute = h5py.h5a.open(obj.id, name.encode())
        kind = attribute.get_type()
        space = attribute.get_space().get_simple_extent_type()
        shape = None if space == h5py.h5s.NULL else attribute.shape
        return kind.get_class(), shape, kind

    def _read_attribute(self, name, obj=None):
        return (self.file if obj is None else obj).attrs[name]

    def _text(self, name, max_bytes=MAX_TEXT_BYTES, obj=None):
        type_class, shape, kind = self._attribute(name, obj)
        if type_class != h5py.h5t.STRING or shape != ():
            self.fail(f"attribute {name} is {shape_text(type_class, shape)}, not a text")
        if not kind.is_variable_str() and kind.get_size() > max_bytes:
            self._too_long(name, kind.get_size(), max_bytes)
        value = self._read_attribute(name, obj)
        value = value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)
        value = value.split("\0", 1)[0]
        if len(value.encode("utf-8", "replace")) > max_bytes:
            self._too_long(name, len(value.encode("utf-8", "replace")), max_bytes)
        return value

    def _too_long(self, name, size, max_bytes):
        self.fail(f"attribute {name} holds a text of {size} bytes: accepted at most {max_bytes}")

    def _integer(self, name, low, high):
        type_class, shape, _ = self._attribute(name)
        if type_class != h5py.h5t.INTEGER or shape != ():
            self.fail(f"attribute {name} is {shape_text(type_class, shape)}, not an integer")
        value = int(self._read_attribute(name))
        if not low <= value <= high:
            self.fail(f"attribute {name} = {value} is out of range: accepted {low} to {high}")
        return value

    def _number(self, name):
        type_class, shape, _ = self._attribute(name)
        if type_class not in (h5py.h5t.INTEGER, h5py.h5t.FLOAT) or shape != ():
            self.fail(f"attribute {name} is {shape_text(type_class, shape)}, not a number")
        value = float(self._read_attribute(name))
        if not math.isfinite(value):
            self.fail(f"attribute {name} = {value} is not finite")
        return value

    def _texts(self, name, max_items):
        type_class, shape, kind = self._attribute(name)
        if type_class != h5py.h5t.STRING or shape is None or len(shape) != 1:
            self.fail(f"attribute {name} is {shape_text(type_class, shape)}, not a list of texts")
        if not 1 <= shape[0] <= max_items:
            self.fail(f"attribute {name} lists {shape[0]} items: accepted 1 to {max_items}")
        if not kind.is_variable_str() and kind.get_size() > MAX_TEXT_BYTES:
            self._too_long(name, kind.get_size(), MAX_TEXT_BYTES)
        values = [v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v)
                  for v in self._read_attribute(name).tolist()]
        for value in values:
            if len(value.encode("utf-8", "replace")) > MAX_TEXT_BYTES:
                self._too_long(name, len(value.encode("utf-8", "replace")), MAX_TEXT_BYTES)
        return [v.split("\0", 1)[0] for v in values]

    def _integers(self, name, items):
        type_class, shape, _ = self._attribute(name)
        if type_class != h5py.h5t.INTEGER or shape is None or len(shape) != 1:
            self.fail(f"attribute {name} is {shape_text(type_class, shape)}, not a list of integers")
        if shape[0] != items:
            self.fail(f"attribute {name} lists {shape[0]} integers for {items} dimensions")
        return [int(v) for v in self._read_attribute(name).tolist()]

    def _dataset(self, name):
        dataset = self.file.get(name)
        if not isinstance(dataset, h5py.Dataset):
            self.fail(f"{name} is missing or not a dataset")
        return dataset

    @staticmethod
    def _type(dataset):
        """(type class, bytes, signed, little-endian) of a dataset's elements."""
        kind = dataset.id.get_type()
        type_class = kind.get_class()
        signed = type_class == h5py.h5t.INTEGER and kind.get_sign() == h5py.h5t.SGN_2
        little = type_class not in (h5py.h5t.INTEGER, h5py.h5t.FLOAT) or kind.get_order() == h5py.h5t.ORDER_LE
        return type_class, kind.get_size(), signed, little

    def _allocated(self, dataset, name):
        """Refuses a dataset part of whose data has no storage (HDF5 would read zeros)."""
        plist = dataset.id.get_create_plist()
        size = dataset.id.get_type().get_size()
        if plist.get_layout() == h5py.h5d.CHUNKED:
            chunks = plist.get_chunk()
            expected = int(np.prod([-(-n // c) for n, c in zip(dataset.shape, chunks)], dtype=np.int64))
            whole = dataset.id.get_num_chunks() == expected
        else:
            whole = dataset.id.get_storage_size() == int(np.prod(dataset.shape, dtype=np.int64)) * size
        if not whole:
            self.fail(f"{name} lacks storage for part of its data: the file is incomplete or damaged")

    def _validate(self):
        attrs = self.file.attrs
        if "superball_file" not in attrs:
            if "superball_format" in attrs or "coordinate_system" in attrs:
                self.fail("attribute superball_file is missing")  # a file of this layout, damaged
            if "job_toml" in attrs and "software_version" in attrs:
                try:
                    version = decode(attrs["software_version"])
                except H5PY_ERRORS:
                    version = "?"
                self.fail(f"written by superball {printable(version)} in the layout before netCDF conventions, which this "
                          "version does not read; run the job again with this version")
            self.fail("an HDF5 file that is not a superball result (no attribute superball_file)")
        self.kind = self._text("superball_file")
        if self.kind not in (KIND_RESULT, KIND_PARTIAL):
            self.fail(f'attribute superball_file = "{printable(self.kind)}" is neither "result" nor "partial"')
        version = self._integer("superball_format", 0, 2**63 - 1)
        if version != FORMAT_VERSION and not (self.kind == KIND_RESULT and OLDEST_RESULT_FORMAT <= version < FORMAT_VERSION):
            if self.kind == KIND_RESULT:
                self.fail(f"attribute superball_format = {version}: this version of superball reads results of format "
                          f"{OLDEST_RESULT_FORMAT} to {FORMAT_VERSION}; read the file with the version that wrote it")
            self.fail(f"attribute superball_format = {version}: a partial file of format {version} is resumed by the "
                      f"version that wrote it, this one resumes format {FORMAT_VERSION} only")

        self.coordinates = self._text("coordinate_system")
        if self.coordinates not in COORDINATE_NAMES:
            self.fail(f'attribute coordinate_system = "{printable(self.coordinates)}" is neither canonical nor physical')
        coordinates = COORDINATE_NAMES[self.coordinates]
        self.axis_names = self._texts("axis_names", 4)
        last = -1
        for i, name in enumerate(self.axis_names):
            if name not in coordinates and name not in COEFFICIENT_NAMES:
                self.fail(f'attribute axis_names names "{printable(name)}", which is neither a {self.coordinates} coordinate '
                          f"({', '.join(coordinates)}) nor a model coefficient ({', '.join(COEFFICIENT_NAMES)})")
            if name in self.axis_names[:i]:
                self.fail(f'attribute axis_names names "{name}" twice')
            order = coordinates.index(name) if name in coordinates else -1
            if order < last:
                self.fail(f"attribute axis_names lists ({', '.join(map(printable, self.axis_names))}) out of order: swept "
                          f"coefficients first, then {', '.join(coordinates)}")
            last = max(last, order)
        self._fixed = {c: self._number(f"fixed_{c}") for c in coordinates if c not in self.axis_names}
        if len(coordinates) - len(self._fixed) > 3:
            self.fail(f"attribute axis_names lists {len(coordinates) - len(self._fixed)} {self.coordinates} "
                      "coordinates: a grid has at most 3 ranges")

        self.max_bounces = self._integer("max_bounces", 1, 2**32 - 1)
        self.software_version = self._text("software_version")
        self.job_toml = self._text("job_toml", MAX_JOB_BYTES)
        self._text("job_fingerprint", MAX_JOB_BYTES)
        self._integer("mpi_ranks", 0, 1 << 40)
        # Provenance (CF/ACDD), in files of builds that record it: optional, as in the C++ reader.
        self.provenance = {}
        for name, limit in (("history", MAX_JOB_BYTES), ("source", MAX_TEXT_BYTES),
                            ("date_created", MAX_TEXT_BYTES), ("build", MAX_TEXT_BYTES)):
            if name in attrs:
                self.provenance[name] = self._text(name, limit)
        for name, high in (("mpi_hosts", 1 << 40), ("threads", 1 << 20)):
            if name in attrs:
                self.provenance[name] = self._integer(name, 1, high)
        if self._number("wall_seconds") < 0:
            self.fail(f"attribute wall_seconds = {self._number('wall_seconds')} is negative")
        complete = self._integer("complete", 0, 1) == 1
        if self.kind == KIND_RESULT and not complete:
            self.fail("attribute complete = 0 contradicts superball_file = result (a result is written complete)")
        if self.kind == KIND_PARTIAL and complete:
            self.fail("attribute complete = 1 contradicts superball_file = partial (a run in progress)")
        self._model = {}
        swept = set()
        for key in ("e_wall", "alpha_wall", "e_floor", "alpha_floor") + tuple(FRICTION_DEFAULTS):
            if key in FRICTION_DEFAULTS and key not in attrs:
                continue
            if key in attrs and self._attribute(key)[0] == h5py.h5t.STRING:
                value = self._text(key)
                axis = value[5:] if value.startswith("axis:") else ""
                if axis not in self.axis_names or axis not in (key, key.split("_")[0]):
                    self.fail(f'attribute {key} = "{printable(value)}" names no axis of the file that sweeps {key}')
                swept.add(axis)
                self._model[key] = value
                continue
            value = self._number(key)
            if key.startswith("mu"):
                ok, accepted = value >= 0, "0 <= mu <= inf"
            elif key == "inertia":
                ok, accepted = 0 < value <= 2 / 3, "0 < inertia <= 2/3"
            elif key.startswith("e"):
                ok, accepted = 0 < value <= 1, "0 < e <= 1"
            else:
                ok, accepted = -1 <= value <= 1, "-1 <= alpha <= 1"
            if not ok:
                self.fail(f"attribute {key} = {format_number(value)} is out of range: accepted {accepted}")
            # Titles name SPEC.md 1b's coefficients only where they are not the defaults.
            if FRICTION_DEFAULTS.get(key) != value:
                self._model[key] = value
        for name in self.axis_names:
            if name in COEFFICIENT_NAMES and name not in swept:
                self.fail(f'attribute axis_names names the coefficient {name}, but no coefficient attribute says '
                          f'"axis:{name}"')
        if self.coordinates == "physical":
            for key in ("g", "radius"):
                value = self._number(key)
                if not value > 0:
                    self.fail(f"attribute {key} = {format_number(value)} is out of range: accepted > 0")
                self._model[key] = value

        if self.kind == KIND_RESULT and "progress" in self.file:
            journal = " (/progress), which only a run in progress has"
            flags = self.file.get("progress/tile_done")
            if isinstance(flags, h5py.Dataset) and flags.dtype.kind in "ui" and flags.ndim == 1:
                flags = flags[()]
                journal = f", /progress/tile_done, recording {int(np.count_nonzero(flags == 1))} of {flags.size} tiles done"
            self.fail("superball_file = result and complete = 1 say the run is complete, but the file holds a "
                      f"resume journal{journal}: the file contradicts itself")
        self._validate_data()
        if self.kind == KIND_PARTIAL:
            self._validate_partial()
        else:
            self.tile_shape, self.tile_count, self.tiles_done, self._done = None, 1, 1, None

    def _validate_data(self):
        self.counts = self._dataset("/wall_bounces")
        self.outcomes = self._dataset("/outcome")
        partial = self.kind == KIND_PARTIAL
        type_class, size, signed, little = self._type(self.counts)
        if type_class != h5py.h5t.INTEGER or signed or size not in (2, 4) or not (little or not partial):
            detail = f" of {8 * size} bits, {'signed' if signed else 'unsigned'}" if type_class == h5py.h5t.INTEGER else ""
            self.fail(f"/wall_bounces holds {shape_text(type_class, self.counts.shape)}{detail}: accepted unsigned 16- "
                      f"or 32-bit integers{' (little-endian)' if partial else ''}")
        type_class, size, signed, _ = self._type(self.outcomes)
        if type_class != h5py.h5t.INTEGER or signed or size != 1:
            detail = f" of {8 * size} bits, {'signed' if signed else 'unsigned'}" if type_class == h5py.h5t.INTEGER else ""
            self.fail(f"/outcome holds {shape_text(type_class, self.outcomes.shape)}{detail}: accepted unsigned 8-bit "
                      "integers")
        shape, names = self.counts.shape, self.axis_names
        if shape is None or len(shape) != len(names):
            dims = "a scalar" if not shape else f"({', '.join(map(str, shape))})"
            self.fail(f"/wall_bounces has {len(shape or ())} dimensions {dims} but axis_names lists {len(names)} axes "
                      f"({', '.join(names)})")
        if self.outcomes.shape != shape:
            self.fail(f"/outcome {self.outcomes.shape} and /wall_bounces {shape} differ in shape")
        if 0 in shape:
            self.fail(f"/wall_bounces {shape} is empty")
        if math.prod(shape) > MAX_POINTS:
            self.fail(f"/wall_bounces {shape} has more than 2^40 points")
        if self.max_bounces > 65535 and self.counts.dtype.itemsize == 2:
            self.fail(f"max_bounces = {self.max_bounces} does not fit the 16-bit counts of /wall_bounces")
        if not partial:  # a compressed partial file's chunks are indexed when it becomes the result
            self._allocated(self.counts, "/wall_bounces")
            self._allocated(self.outcomes, "/outcome")

        scales = {name: self._scales(dataset, name) for name, dataset in
                  (("/wall_bounces", self.counts), ("/outcome", self.outcomes))}
        self.axes = {}
        for k, (name, n) in enumerate(zip(names, shape)):
            variable = f"/{name}"
            dataset = self._dataset(variable)
            type_class = self._type(dataset)[0]
            if type_class != h5py.h5t.FLOAT or dataset.shape != (n,):
                self.fail(f"{variable} holds {shape_text(type_class, dataset.shape)}, not {n} floating-point samples "
                          f"(dimension {k} of the data)")
            self._allocated(dataset, variable)
            samples = dataset[()].astype(np.float64)
            bad = np.flatnonzero(~np.isfinite(samples))
            if bad.size:
                self.fail(f"{variable} holds {samples[bad[0]]} at {bad[0]}: samples must be finite")
            bad = np.flatnonzero(~(np.diff(samples) > 0))
            if bad.size:
                i = int(bad[0]) + 1
                self.fail(f"{variable} is not increasing at {i} ({samples[i]} after {samples[i - 1]})")
            self.axes[name] = samples
            if "CLASS" not in dataset.attrs or self._text("CLASS", 64, dataset) != "DIMENSION_SCALE":
                self.fail(f'{variable} is not a dimension scale (its attribute CLASS is not "DIMENSION_SCALE")')
            address = h5py.h5o.get_info(dataset.id).addr
            for data_name, attached in scales.items():
                if address not in attached[k]:
                    self.fail(f"{variable} is not attached to dimension {k} of {data_name}, which axis_names says is "
                              f"{name}")
        for name, value in self._fixed.items():
            variable = f"/{name}"
            dataset = self._dataset(variable)
            type_class = self._type(dataset)[0]
            if type_class != h5py.h5t.FLOAT or dataset.shape != ():
                self.fail(f"{variable} holds {shape_text(type_class, dataset.shape)}, not one floating-point number "
                          f"(the fixed coordinate {name})")
            self._allocated(dataset, variable)
            stored = float(dataset[()])
            if stored != value:
                self.fail(f"{variable} = {stored!r} contradicts attribute fixed_{name} = {value!r}")

    def _scales(self, dataset, name):
        """Addresses of the scales attached to each dimension (attribute DIMENSION_LIST), its type checked first."""
        if "DIMENSION_LIST" not in dataset.attrs:
            self.fail(f"{name} has 0 dimension scales attached (attribute DIMENSION_LIST) for its {dataset.ndim} "
                      "dimensions")
        kind = h5py.h5a.open(dataset.id, b"DIMENSION_LIST").get_type()
        if (kind.get_class() != h5py.h5t.VLEN or not kind.get_super().equal(h5py.h5t.STD_REF_OBJ)
                or dataset.attrs.get_id("DIMENSION_LIST").shape != (dataset.ndim,)):
            self.fail(f"{name}: attribute DIMENSION_LIST is not a list of object references per dimension")
        def address(ref):
            try:
                return h5py.h5o.get_info(self.file[ref].id).addr
            except H5PY_ERRORS:
                return None  # a reference to nothing (the object was deleted) is attached to nothing

        return [{address(ref) for ref in refs} for refs in dataset.attrs["DIMENSION_LIST"]]

    def _validate_partial(self):
        shape = self.counts.shape
        self.tile_shape = self._integers("tile_shape", len(shape))
        if any(not 1 <= t <= n for t, n in zip(self.tile_shape, shape)):
            self.fail(f"attribute tile_shape = ({', '.join(map(str, self.tile_shape))}) does not fit the data "
                      f"({', '.join(map(str, shape))})")
        self._tiles_per_axis = [-(-n // t) for n, t in zip(shape, self.tile_shape)]
        self.tile_count = math.prod(self._tiles_per_axis)
        # One chunk per tile: uncompressed, each tile written straight to its chunk;
        # compressed, shuffle + deflate as in the result, the chunks appended past the HDF5
        # objects (listed in /progress/tile_stored) and not indexed yet.
        pipelines = []
        for name, dataset in (("/wall_bounces", self.counts), ("/outcome", self.outcomes)):
            plist = dataset.id.get_create_plist()
            chunks = plist.get_chunk() if plist.get_layout() == h5py.h5d.CHUNKED else None
            filters = [plist.get_filter(i)[0] for i in range(plist.get_nfilters())]
            level = None
            if filters == [h5py.h5z.FILTER_SHUFFLE, h5py.h5z.FILTER_DEFLATE]:
                values = plist.get_filter(1)[2]
                level = int(values[0]) if len(values) else 0
            pipelines.append(filters)
            if (chunks is None or list(chunks) != self.tile_shape or
                    not (filters == [] or (level is not None and 1 <= level <= 9))):
                stored = "unchunked" if chunks is None else f"in chunks of ({', '.join(map(str, chunks))})"
                if chunks is not None and filters:
                    stored += f" through {len(filters)} filters"
                self.fail(f"{name} is stored {stored}, not in chunks of tile_shape ({', '.join(map(str, self.tile_shape))}), "
                          "uncompressed or through shuffle and deflate alike for both datasets, as a partial file is")
            if not filters:
                self._allocated(dataset, name)
            elif dataset.id.get_num_chunks():
                self.fail(f"{name} holds chunks ({dataset.id.get_num_chunks()}), which a compressed partial file never "
                          "does: its tiles are in /progress/tile_stored until the run completes; the file is damaged")
        self._compressed = bool(pipelines[0])
        if pipelines[0] != pipelines[1]:
            self.fail("/outcome is stored otherwise than /wall_bounces, not in chunks of tile_shape "
                      f"({', '.join(map(str, self.tile_shape))}), uncompressed or through shuffle and deflate alike for "
                      "both datasets, as a partial file is")
        journal = {}
        names = [("/progress/tile_done", 1, (self.tile_count,)), ("/progress/tile_checksum", 8, (self.tile_count,))]
        if self._compressed:
            names.append(("/progress/tile_stored", 8, (self.tile_count, 3)))
        for name, size, want in names:
            dataset = self._dataset(name)
            type_class, bytes_, signed, little = self._type(dataset)
            if (type_class != h5py.h5t.INTEGER or signed or bytes_ != size or not little
                    or dataset.shape != want):
                self.fail(f"{name} holds {shape_text(type_class, dataset.shape)} but tile_shape "
                          f"({', '.join(map(str, self.tile_shape))}) makes {self.tile_count} tiles: accepted "
                          f"({', '.join(map(str, want))}) unsigned {8 * size}-bit integers")
            self._allocated(dataset, name)
            journal[name] = dataset[()]
        self._done = journal["/progress/tile_done"].astype(np.uint8)
        self._checksums = journal["/progress/tile_checksum"].astype(np.uint64)
        bad = np.flatnonzero(self._done > 1)
        if bad.size:
            self.fail(f"/progress/tile_done holds {self._done[bad[0]]} for tile {bad[0]}: accepted 0 or 1")
        self.tiles_done = int(np.count_nonzero(self._done))
        self._stored = None
        if self._compressed:
            self._stored = journal["/progress/tile_stored"].astype(np.uint64)
            size = os.path.getsize(self.path)
            chunk_bytes = math.prod(self.tile_shape) * self.counts.dtype.itemsize
            for t in np.flatnonzero(self._done == 1):
                at, nc, no = (int(v) for v in self._stored[t])
                if nc == 0 or no == 0 or nc > chunk_bytes + chunk_bytes // 2 + 64 or no > chunk_bytes or at + nc + no > size:
                    self.fail(f"/progress/tile_stored places done tile {t} at bytes {at} to {at + nc} (+{no}), which a "
                              f"file of {size} bytes cannot hold: the file is truncated or damaged")

    # --- values ---------------------------------------------------------------------------

    def read(self, index):
        """(counts, outcomes) at `index` (a tuple of one int or slice per dimension), as numpy
        arrays, checked: the points of tiles not done (partial files) read as 0 bounces, outcome
        invalid; an outcome code outside 0-3, a count its outcome does not allow, a damaged tile
        or unreadable data is a ScriptError naming the object and the point or tile."""
        index = tuple(index)
        # Per dimension, the file indices the block holds; kept: the dimensions not indexed by an int.
        positions = [np.arange(n)[i] if isinstance(i, slice) else np.array([int(i) % n])
                     for i, n in zip(index, self.shape)]
        expanded = tuple(len(p) for p in positions)
        kept = tuple(len(p) for p, i in zip(positions, index) if isinstance(i, slice))
        if self.kind == KIND_PARTIAL and self._compressed:
            self._verify_tiles(positions)
            counts_full, outcomes_full = self._read_stored(positions)
            counts, outcomes = counts_full.reshape(kept), outcomes_full.reshape(kept)
        else:
            try:
                counts = np.asarray(self.counts[index])
                outcomes = np.asarray(self.outcomes[index])
            except H5PY_ERRORS as error:
                self.fail(f"/wall_bounces or /outcome cannot be read at {index_text(index)} ({error}); the file is damaged")
            counts_full, outcomes_full = counts.reshape(expanded), outcomes.reshape(expanded).copy()
        if self.kind == KIND_PARTIAL:
            self._verify_tiles(positions)
            tiles = [p // t for p, t in zip(positions, self.tile_shape)]
            flat = np.ravel_multi_index(np.ix_(*tiles), self._tiles_per_axis)
            missing = self._done[flat] == 0
            if missing.any():
                counts_full = np.where(missing, 0, counts_full).astype(counts.dtype)
                outcomes_full[missing] = INVALID
        else:
            missing = None
        self._check_values(counts_full, outcomes_full, positions, missing)
        return counts_full.reshape(counts.shape), outcomes_full.reshape(outcomes.shape)

    def _check_values(self, counts, outcomes, positions, missing):
        def where(flags):
            at = np.unravel_index(int(np.argmax(flags)), flags.shape)
            return f"({', '.join(str(int(p[i])) for p, i in zip(positions, at))})"

        bad = outcomes > CAPPED
        if bad.any():
            at = np.unravel_index(int(np.argmax(bad)), bad.shape)
            self.fail(f"/outcome holds {int(outcomes[at])} at {where(bad)}: outcome codes are 0 to 3 "
                      f"(invalid left missed capped); the file is damaged")
        bad = np.where(outcomes == INVALID, counts != 0,
                       np.where(outcomes == CAPPED, counts != self.max_bounces, counts > self.max_bounces))
        if missing is not None:
            bad &= ~missing
        if bad.any():
            at = np.unravel_index(int(np.argmax(bad)), bad.shape)
            code = int(outcomes[at])
            allowed = {INVALID: "0", CAPPED: f"exactly max_bounces = {self.max_bounces}"}.get(
                code, f"at most max_bounces = {self.max_bounces}")
            self.fail(f"/wall_bounces holds {int(counts[at])} at {where(bad)} with outcome {code} "
                      f"({OUTCOME_NAMES[code]}), which allows {allowed}; the file is damaged")

    def _read_stored(self, positions):
        """A compressed partial file's values at `positions` (file indices per dimension):
        each done tile the block meets decompressed from its stored chunks (zlib, then the
        shuffle undone), the others zeros."""
        counts = np.zeros(tuple(len(p) for p in positions), dtype=self.counts.dtype)
        outcomes = np.zeros(counts.shape, dtype=np.uint8)
        tiles = [np.unique(p // t) for p, t in zip(positions, self.tile_shape)]
        points = math.prod(self.tile_shape)
        width = self.counts.dtype.itemsize
        with open(self.path, "rb") as f:
            for coords in itertools.product(*tiles):
                tile = int(np.ravel_multi_index(coords, self._tiles_per_axis))
                if self._done[tile] == 0:
                    continue
                at, nc, no = (int(v) for v in self._stored[tile])
                f.seek(at)
                stored = f.read(nc + no)
                try:
                    shuffled = np.frombuffer(zlib.decompress(stored[:nc]), dtype=np.uint8)
                    codes = np.frombuffer(zlib.decompress(stored[nc:]), dtype=np.uint8)
                except zlib.error:
                    shuffled = codes = np.zeros(0, dtype=np.uint8)
                if shuffled.size != points * width or codes.size != points:
                    self.fail(f"tile {tile} is recorded done in /progress/tile_done, but its stored chunks (at byte {at}) "
                              "do not decompress to one tile: the file is damaged")
                chunk = np.ascontiguousarray(shuffled.reshape(width, points).T).view(f"<u{width}").reshape(self.tile_shape)
                here = [np.flatnonzero(p // t == c) for p, t, c in zip(positions, self.tile_shape, coords)]
                local = [p[h] - c * t for p, h, t, c in zip(positions, here, self.tile_shape, coords)]
                counts[np.ix_(*here)] = chunk[np.ix_(*local)]
                outcomes[np.ix_(*here)] = codes.reshape(self.tile_shape)[np.ix_(*local)]
        return counts, outcomes

    def _verify_tiles(self, positions):
        """Checks each done tile the block meets, once, against /progress/tile_checksum."""
        tiles = [np.unique(p // t) for p, t in zip(positions, self.tile_shape)]
        for coords in itertools.product(*tiles):
            tile = int(np.ravel_multi_index(coords, self._tiles_per_axis))
            if self._done[tile] == 0 or self._verified[tile]:
                continue
            origin = tuple(int(c) * t for c, t in zip(coords, self.tile_shape))
            if self._compressed:
                checksum = stored_tile_checksum(self.path, tile, *(int(v) for v in self._stored[tile]))
            else:
                checksum = tile_checksum(self.counts, self.outcomes, tile, origin)
            if checksum is None:
                if not self._checksums_unchecked:
                    warn(f"python3-xxhash is not installed: the tiles of {self.path} are not checked against their "
                         "checksums")
                    self._checksums_unchecked = True
                return
            if checksum != int(self._checksums[tile]):
                spans = ", ".join(f"{name} {o}..{min(o + t, n) - 1}" for name, o, t, n in
                                  zip(self.axis_names, origin, self.tile_shape, self.shape))
                self.fail(f"tile {tile} ({spans}) is recorded done in /progress/tile_done, but its data in "
                          "/wall_bounces and /outcome no longer match /progress/tile_checksum: the file is damaged")
            self._verified[tile] = True

    # --- what the file says ----------------------------------------------------------------

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
    def complete(self):
        """True for a result, False for the partial file of a run not finished."""
        return self.kind == KIND_RESULT

    def model(self):
        """Model coefficients (a number, or "axis:<name>" when swept) and g, radius for physical grids, in display order."""
        return dict(self._model)

    def fixed(self):
        """Fixed coordinates {name: value}, in coordinate order."""
        return dict(self._fixed)

    def tiles(self):
        """(tiles done, tiles) of a partial file, None for a result (complete: it has no journal)."""
        return (self.tiles_done, self.tile_count) if self.kind == KIND_PARTIAL else None

    def model_text(self):
        """One line with every coefficient and max_bounces, for titles."""
        return f"{join_values(self.model(), '=')}, max_bounces={self.max_bounces}"

    def fixed_text(self):
        """'U = -1, W = 0.5': the coordinates fixed in the job."""
        return join_values(self.fixed())


def index_text(index):
    """An index tuple as text: [3, 0:10, :]."""
    def one(i):
        if not isinstance(i, slice):
            return str(i)
        text = f"{'' if i.start is None else i.start}:{'' if i.stop is None else i.stop}"
        return text + (f":{i.step}" if i.step not in (None, 1) else "")
    return "[" + ", ".join(one(i) for i in index) + "]"


def tile_checksum(counts, outcomes, tile, origin):
    """The checksum a partial file records for a tile (src/io/partial_file.hpp): XXH3-64 of
    the tile's chunk of /wall_bounces as stored, seeded with the tile's number, then of its
    chunk of /outcome seeded with that.  None when python3-xxhash is not installed."""
    try:
        import xxhash  # Debian's python3-xxhash
    except ImportError:
        return None
    try:
        stored_counts = counts.id.read_direct_chunk(origin)[1]
        stored_outcomes = outcomes.id.read_direct_chunk(origin)[1]
    except H5PY_ERRORS:
        return -1  # a chunk that cannot be read matches no checksum
    return xxhash.xxh3_64_intdigest(stored_outcomes, seed=xxhash.xxh3_64_intdigest(stored_counts, seed=tile))


def stored_tile_checksum(path, tile, at, counts_bytes, outcomes_bytes):
    """The checksum a compressed partial file records for a tile: as tile_checksum, of its
    stored (compressed) chunks at byte `at`.  None when python3-xxhash is not installed."""
    try:
        import xxhash  # Debian's python3-xxhash
    except ImportError:
        return None
    with open(path, "rb") as f:
        f.seek(at)
        stored = f.read(counts_bytes + outcomes_bytes)
    if len(stored) != counts_bytes + outcomes_bytes:
        return -1
    return xxhash.xxh3_64_intdigest(stored[counts_bytes:],
                                    seed=xxhash.xxh3_64_intdigest(stored[:counts_bytes], seed=tile))


def warn_if_incomplete(result):
    """Warn that a file is the partial file of a run not finished (its points not computed
    read as invalid). Scripts call it once the data are read, so that a damaged file gets
    one message, the error, and nothing before it."""
    if not result.complete:
        warn(f"{result.path} is the partial file of an incomplete run ({result.tiles_done} of {result.tile_count} "
             "tiles done): the points of the tiles not done read as invalid")
        return True
    return False


def axis_label(name):
    """Axis label with the SPEC name and its definition or unit."""
    return AXIS_LABELS.get(name, name)


def cell_edges(samples):
    """Edges of the cells whose centres are `samples` (uniform, cell-centred as in SPEC section 4).

    Returned as (first edge, last edge) following the samples' order, so a
    decreasing axis keeps its orientation; a single sample gets a unit cell.
    """
    if len(samples) == 1:
        return samples[0] - 0.5, samples[0] + 0.5
    half = 0.5 * (samples[-1] - samples[0]) / (len(samples) - 1)
    return samples[0] - half, samples[-1] + half
