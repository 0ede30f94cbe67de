"""The damages of tests/hardening/test_damaged.py, each applied one at a time to a real result
(R) or partial file (P) made by the binary, and the table of cases: what, base, damage, and
the texts of which a reader's refusal must contain one (the object it names). Shared with
the C++ test of the reader's refusals (tests/io/damaged/make_damaged_files.py writes every
case's file for it)."""
import os
import sys

import h5py
import numpy as np
import xxhash  # Debian's python3-xxhash

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import stored_chunk  # noqa: E402

JOB = """[model]
e = 0.9
alpha = 0.9

[grid]
xi = { min = 0.0, max = 1.0, n = 40 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 30 }

[run]
max_bounces = 1000
tile_points = 400
"""


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


# --- Damages: each a function of the damaged file's path ---------------------------------


def with_file(change):
    def damage(path):
        with h5py.File(path, "r+") as f:
            change(f)
    return damage


def set_attribute(name, value, obj="/"):
    def change(f):
        f[obj].attrs[name] = value
    return with_file(change)


def delete_attribute(name, obj="/"):
    def change(f):
        del f[obj].attrs[name]
    return with_file(change)


def replace_dataset(name, make):
    """/name replaced by make(old values) (dtype and shape as it says), its dimension scales
    attached again where the shape still allows, so that only what the row says differs."""
    def change(f):
        old = f[name][()]
        del f[name]
        data = np.asarray(make(old))
        f.create_dataset(name, data=data)
        if name in ("wall_bounces", "outcome"):
            for k, axis in enumerate(f.attrs["axis_names"][:data.ndim]):
                axis = axis.decode() if isinstance(axis, bytes) else axis
                if data.shape[k] == f[axis].shape[0]:
                    f[name].dims[k].attach_scale(f[axis])
    return with_file(change)


def write_values(name, index, value):
    def change(f):
        f[name][index] = value
    return with_file(change)


def truncate(fraction):
    def damage(path):
        os.truncate(path, int(os.path.getsize(path) * fraction))
    return damage


def flip(offset_of):
    """Flips one bit of the byte at offset_of(path)."""
    def damage(path):
        offset = offset_of(path)
        with open(path, "r+b") as f:
            f.seek(offset)
            byte = f.read(1)[0]
            f.seek(offset)
            f.write(bytes([byte ^ 0x10]))
    return damage


def after(marker, skip):
    """The offset `skip` bytes after the first occurrence of `marker` in the file."""
    return lambda path: read_bytes(path).index(marker) + skip


def in_chunk(dataset, chunk, at=0.5):
    """An offset inside the stored bytes of one chunk of a dataset."""
    def offset(path):
        with h5py.File(path, "r") as f:
            info = f[dataset].id.get_chunk_info(chunk)
        return info.byte_offset + int(info.size * at)
    return offset


def in_stored_tile(tile, at=0.5):
    """An offset inside the stored (compressed) bytes of a compressed partial file's tile,
    where /progress/tile_stored says they lie."""
    def offset(path):
        with h5py.File(path, "r") as f:
            start, counts, outcomes = (int(v) for v in f["progress/tile_stored"][tile])
        return start + int((counts + outcomes) * at)
    return offset


def journal_offset(path):
    """Where /progress/tile_done's flags lie in the file."""
    with h5py.File(path, "r") as f:
        return f["progress/tile_done"].id.get_offset()


def contradicting_journal(f):
    """The issue's case: a file that says it is a complete result while its journal records
    1 of 4 tiles done."""
    f.attrs["superball_file"] = "result"
    f.attrs["complete"] = np.int64(1)
    f["progress/tile_done"][...] = [1, 0, 0, 0]


def forged_done_tile(value):
    """Tile 0 (done) holding `value` as its outcomes, stored anew past the file's end with its
    checksum: only the values say it is wrong."""
    def damage(path):
        end = os.path.getsize(path)
        with h5py.File(path, "r+") as f:
            shape = [int(t) for t in f.attrs["tile_shape"]]
            start, counts_bytes, _ = (int(v) for v in f["progress/tile_stored"][0])
            with open(path, "rb") as raw:
                raw.seek(start)
                counts = raw.read(counts_bytes)
            outcomes = stored_chunk(np.full(shape, value, dtype=np.uint8))
            where = f["progress/tile_stored"][()]
            where[0] = (end, len(counts), len(outcomes))
            f["progress/tile_stored"][...] = where
            sums = f["progress/tile_checksum"][()]
            sums[0] = xxhash.xxh3_64_intdigest(outcomes, seed=xxhash.xxh3_64_intdigest(counts, seed=0))
            f["progress/tile_checksum"][...] = sums
        assert os.path.getsize(path) == end  # the partial file's HDF5 end covers its tiles
        with open(path, "ab") as raw:
            raw.write(counts + outcomes)
    return damage


def swap_scales(f):
    """The scales of /wall_bounces's two dimensions attached the wrong way round."""
    d = f["wall_bounces"]
    d.dims[0].detach_scale(f["xi"])
    d.dims[1].detach_scale(f["W"])
    d.dims[0].attach_scale(f["W"])
    d.dims[1].attach_scale(f["xi"])


def make_empty(path):
    open(path, "wb").close()


def make_directory(path):
    os.remove(path)
    os.mkdir(path)


def make_text(path):
    with open(path, "w") as f:
        f.write("\\documentclass{article}\n\\begin{document}\nBounces.\n\\end{document}\n")


def not_superball_hdf5(path):
    os.remove(path)
    with h5py.File(path, "w") as f:
        f.create_dataset("temperature", data=np.arange(10.0))


def dimension_list_as_text(f):
    del f["wall_bounces"].attrs["DIMENSION_LIST"]
    f["wall_bounces"].attrs["DIMENSION_LIST"] = "xi W"


# (what, base file, damage, texts of which the message must contain one): the object the
# message names. R: a complete result; P: the partial file of an interrupted run (tiles 0
# and 2 of 4 done).
REQUIRED = ["superball_file", "superball_format", "coordinate_system", "axis_names", "e_wall", "alpha_wall", "e_floor",
            "alpha_floor", "fixed_U", "max_bounces", "software_version", "job_toml", "job_fingerprint", "mpi_ranks",
            "wall_seconds", "complete"]
CASES = [
    # Wrong types of the data.
    ("float counts", "R", replace_dataset("wall_bounces", lambda v: v.astype(np.float32)), "/wall_bounces holds"),
    ("signed counts", "R", replace_dataset("wall_bounces", lambda v: v.astype(np.int16)), "/wall_bounces holds"),
    ("64-bit outcomes", "R", replace_dataset("outcome", lambda v: v.astype(np.uint64)), "/outcome holds"),
    ("signed outcomes", "R", replace_dataset("outcome", lambda v: v.astype(np.int8)), "/outcome holds"),
    ("float counts in a partial file", "P", replace_dataset("wall_bounces", lambda v: v.astype(np.float64)),
     "/wall_bounces holds"),
    ("big-endian counts in a partial file", "P", replace_dataset("wall_bounces", lambda v: v.astype(">u2")),
     "/wall_bounces holds"),
    ("integer samples", "R", replace_dataset("xi", lambda v: np.arange(len(v))), "/xi holds"),
    # Wrong shapes.
    ("outcome of another shape", "R", replace_dataset("outcome", lambda v: v[:, :-1]), "/outcome (40, 29)"),
    ("a coordinate of the wrong length", "R", replace_dataset("W", lambda v: v[:-1]), "/W holds"),
    ("0-sized dimension", "R", with_file(lambda f: [f.__delitem__(n) for n in ("wall_bounces", "outcome")] and [
        f.create_dataset(n, shape=(0, 30), dtype=t) for n, t in (("wall_bounces", np.uint16), ("outcome", np.uint8))]),
     "is empty"),
    ("3-D counts for 2 axes", "R", replace_dataset("wall_bounces", lambda v: v[:, :, None]), "/wall_bounces has 3"),
    ("scalar counts", "R", replace_dataset("wall_bounces", lambda v: np.uint16(1)), "/wall_bounces"),
    ("journal of the wrong length", "P", replace_dataset("progress/tile_done", lambda v: v[:-1]),
     "/progress/tile_done holds"),
    ("tile_shape contradicting the chunks", "P", set_attribute("tile_shape", np.array([10, 15], np.uint64)),
     "/wall_bounces is stored in chunks of (20, 15)"),
    ("tile_shape of 3 entries", "P", set_attribute("tile_shape", np.array([20, 15, 1], np.uint64)),
     "attribute tile_shape lists 3"),
    ("tile_shape larger than the grid", "P", set_attribute("tile_shape", np.array([20, 99], np.uint64)),
     "attribute tile_shape = (20, 99)"),
    ("tile_shape signed", "P", set_attribute("tile_shape", np.array([20, -15], np.int64)), "attribute tile_shape"),
    # Attributes missing, each required one in turn.
    *[(f"no {name}", "R", delete_attribute(name), f"attribute {name} is missing") for name in REQUIRED],
    ("no tile_shape", "P", delete_attribute("tile_shape"), "attribute tile_shape is missing"),
    # Attributes of the wrong type or shape.
    ("text for a number", "R", set_attribute("max_bounces", "1000"), "attribute max_bounces is a text, not an integer"),
    ("number for a text", "R", set_attribute("coordinate_system", np.int64(7)),
     "attribute coordinate_system is an integer, not a text"),
    ("float for an integer", "R", set_attribute("complete", 1.0), "attribute complete is a floating-point number"),
    ("list for a scalar", "R", set_attribute("complete", np.array([1, 1], np.int64)),
     "attribute complete is a list of 2 integers"),
    ("one-element list for a scalar", "R", set_attribute("max_bounces", np.array([1000], np.int64)),
     "attribute max_bounces is a list of 1 integers"),
    ("list of numbers for texts", "R", set_attribute("axis_names", np.array([1.0, 2.0])),
     "attribute axis_names is a list of 2 floating-point numbers"),
    ("text of absurd length", "R", set_attribute("job_toml", "x" * (2 << 20)), "attribute job_toml holds a text of"),
    ("fixed-length text of absurd length", "R", set_attribute("software_version", np.bytes_(b"v" * 100000)),
     "attribute software_version holds a text of 100000 bytes"),
    # Attributes that contradict each other or the layout.
    ("a result with complete = 0", "R", set_attribute("complete", np.int64(0)), "contradicts superball_file = result"),
    ("a partial file with complete = 1", "P", set_attribute("complete", np.int64(1)),
     "contradicts superball_file = partial"),
    ("complete result, journal 1 of 4 tiles", "P", with_file(contradicting_journal), "recording 1 of 4 tiles done"),
    ("unknown kind", "R", set_attribute("superball_file", "draft"), 'superball_file = "draft"'),
    ("another format", "R", set_attribute("superball_format", np.int64(4)), "superball_format = 4"),
    ("an older format of partial file", "P", set_attribute("superball_format", np.int64(2)), "superball_format = 2"),
    ("chunks written into a compressed partial file's index", "P", write_values("wall_bounces", (1, 1), 7),
     "/wall_bounces holds chunks"),
    ("unknown coordinate_system", "R", set_attribute("coordinate_system", "polar"), 'coordinate_system = "polar"'),
    ("control characters in a text", "R", set_attribute("superball_file", "\x1b[2Jresult"),
     'superball_file = "\\x1b[2Jresult"'),
    ("axis_names = 'nonsense,,,'", "R", set_attribute("axis_names", "nonsense,,,"),
     "attribute axis_names is a text, not a list of texts"),
    ("axis_names naming an unknown axis", "R", set_attribute("axis_names", ["xi", "bogus"]), 'names "bogus"'),
    ("axis_names naming an axis twice", "R", set_attribute("axis_names", ["xi", "xi"]), 'names "xi" twice'),
    ("axis_names naming too many axes", "R", set_attribute("axis_names", ["e", "alpha", "xi", "U", "W"]),
     "attribute axis_names lists 5 items"),
    ("axis_names out of order", "R", set_attribute("axis_names", ["W", "xi"]), "out of order"),
    ("axis_names naming a fixed coordinate", "R", set_attribute("axis_names", ["xi", "U"]),
     "attribute fixed_W is missing"),
    ("coefficient out of range", "R", set_attribute("e_wall", 1.5), "attribute e_wall = 1.5"),
    ("coefficient naming no axis", "R", set_attribute("alpha_floor", "axis:alpha"), "attribute alpha_floor"),
    ("NaN wall_seconds", "R", set_attribute("wall_seconds", float("nan")), "attribute wall_seconds"),
    ("max_bounces 0", "R", set_attribute("max_bounces", np.int64(0)), "attribute max_bounces = 0"),
    ("max_bounces beyond 16-bit counts", "R", set_attribute("max_bounces", np.int64(70000)), "16-bit counts"),
    ("fixed_U contradicting /U", "R", set_attribute("fixed_U", -2.0), "contradicts attribute fixed_U"),
    ("scales swapped", "R", with_file(swap_scales), "is not attached to dimension 0 of /wall_bounces"),
    ("not a dimension scale", "R", delete_attribute("CLASS", "xi"), "/xi is not a dimension scale"),
    ("DIMENSION_LIST a text", "R", with_file(dimension_list_as_text), "DIMENSION_LIST"),
    ("coordinate variable deleted", "R", with_file(lambda f: f.__delitem__("W")), "/W is missing"),
    ("outcome deleted", "R", with_file(lambda f: f.__delitem__("outcome")), "/outcome is missing"),
    ("checksums deleted", "P", with_file(lambda f: f.__delitem__("progress/tile_checksum")),
     "/progress/tile_checksum is missing"),
    # Values out of range.
    ("outcome 200 everywhere", "R", write_values("outcome", (), 200), "/outcome holds 200 at (0, 0)"),
    ("outcome 4 at one point", "R", write_values("outcome", (17, 3), 4), "/outcome holds 4 at (17, 3)"),
    ("counts of an invalid point", "R", with_file(lambda f: (f["outcome"].__setitem__((5, 6), 0),
                                                              f["wall_bounces"].__setitem__((5, 6), 3))),
     "/wall_bounces holds 3 at (5, 6) with outcome 0"),
    ("capped below max_bounces", "R", with_file(lambda f: (f["outcome"].__setitem__((8, 1), 3),
                                                            f["wall_bounces"].__setitem__((8, 1), 999))),
     "/wall_bounces holds 999 at (8, 1) with outcome 3"),
    ("count above max_bounces", "R", with_file(lambda f: (f["outcome"].__setitem__((9, 9), 1),
                                                           f["wall_bounces"].__setitem__((9, 9), 4000))),
     "/wall_bounces holds 4000 at (9, 9)"),
    ("journal flag 2", "P", write_values("progress/tile_done", 1, 2), "/progress/tile_done holds 2 for tile 1"),
    ("a done tile changed", "P", flip(in_stored_tile(0, 0.3)), "tile 0 (xi 0..19, W 0..14)"),
    ("a done tile forged, checksum recomputed", "P", forged_done_tile(200), "/outcome holds 200 at (0, 0)"),
    ("coordinates not increasing", "R", replace_dataset("xi", lambda v: v[[0, 2, 1, *range(3, len(v))]]),
     "/xi is not increasing at 2"),
    ("coordinate NaN", "R", replace_dataset("W", lambda v: np.where(np.arange(len(v)) == 4, np.nan, v)),
     "/W holds nan at 4"),
    ("fixed coordinate not a scalar", "R", replace_dataset("U", lambda v: np.array([v])), "/U holds a list of 1"),
    # Truncated files.
    *[(f"truncated to {fraction:g}", base, truncate(fraction), "truncated")
      for base in "RP" for fraction in (0.001, 0.1, 0.5, 0.9, 0.999)],
    # One bit flipped: HDF5's metadata checksums, the deflate stream's, the tiles'.
    ("bit flip in the signature", "R", flip(lambda p: 1), "not a superball result"),
    ("bit flip in the superblock", "R", flip(lambda p: 20), ("superblock", "damaged", "truncated")),
    ("bit flip in the root object header", "R", flip(after(b"OHDR", 12)), ("damaged", "object header")),
    ("bit flip in the root object header", "P", flip(after(b"OHDR", 12)), ("damaged", "object header")),
    ("bit flip in an attribute's name", "R", flip(after(b"superball_file", 3)), ("superball_file", "damaged")),
    ("bit flip in the attribute heap", "P", flip(after(b"FRHP", 40)), ("damaged", "attribute")),
    # HDF5 trusts the sizes of the objects of its global heap (texts, DIMENSION_LIST): these
    # crashed libhdf5 1.10.8 itself (h5py too) before the readers walked the heap first.
    ("bit flip in a global heap object's size", "R", flip(after(b"GCOL", 16 + 8 + 1)), "the global heap at byte"),
    ("bit flip in a global heap object's size", "P", flip(after(b"GCOL", 16 + 8 + 1)), "the global heap at byte"),
    ("bit flip in the global heap's size", "R", flip(after(b"GCOL", 9)), "the global heap at byte"),
    ("bit flip in compressed counts", "R", flip(in_chunk("wall_bounces", 0)), "/wall_bounces"),
    ("bit flip in compressed outcomes", "R", flip(in_chunk("outcome", 0, 0.3)), "/outcome"),
    ("bit flip in a done tile", "P", flip(in_stored_tile(2, 0.9)), "tile 2 (xi 20..39, W 0..14)"),
    ("bit flip in the journal", "P", flip(lambda p: journal_offset(p) + 1),
     "/progress/tile_done holds 16 for tile 1"),
    # Not a superball file at all.
    ("a 0-byte file", "R", make_empty, "is an empty file"),
    ("a directory", "R", make_directory, "is a directory"),
    ("a text file", "R", make_text, "is a text file of"),
    ("another program's HDF5 file", "R", not_superball_hdf5, "not a superball result"),
    ("a 0-byte partial file", "P", make_empty, "is an empty file"),
    ("a directory as the partial file", "P", make_directory, "is a directory"),
    ("a text file as the partial file", "P", make_text, "is a text file of"),
]
