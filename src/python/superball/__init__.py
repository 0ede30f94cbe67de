"""superball: wall bounces of a spinning superball between a floor and a wall, from Python.

The model, the counts and the results of the `superball` program (Cross impact model:
normal and tangential coefficients of restitution e and alpha, angular momentum conserved
about the contact point), at the speed of its vectorised kernel:

    count(xi, U, W, e=..., alpha=...)     wall bounces and outcome of launches (NumPy arrays)
    trajectory(...)                       every impact of one launch (the CLI's CSV columns)
    fixed_points(...)                     cycles of the canonical map G (self-similar motions)
    continue_branch(...)                  branches of cycles followed in one coefficient
    explore(job)                          a job (TOML file or dict) run on threads: a result
                                          file and its xarray.Dataset
    open(path)                            a result file, validated, as an xarray.Dataset

Coordinates of a launch (the state just after a floor bounce), canonical:
    xi = g x / (2 |u| v)   launch distance from the wall as a fraction of the free-flight
                           range (0 < xi < 1: the wall is reached), dimensionless
    U  = u / v             launch direction (U < 0: toward the wall), dimensionless
    W  = a omega / v       spin relative to the vertical speed, dimensionless
or physical: x [m] (centre to wall), u, v [m/s], omega [rad/s], with g [m/s^2] (default
9.81) and the radius a [m] (default 0.025).

Outcomes (codes as in result files, attribute flag_values / flag_meanings of /outcome):
    0 invalid  not a launch toward the wall (U >= 0, xi <= 0, v <= 0...): 0 bounces
    1 left     after the last wall impact a floor bounce sent the ball away from the wall
    2 missed   heading to the wall, the ball landed on the floor first
    3 capped   max_bounces wall impacts and still bouncing

Bad input raises ValueError (or TypeError for the wrong kind of object) naming the argument
and its value. Counting runs with the GIL released. The repository's docs/python.md
has examples; analysis/region_trajectory.ipynb draws a figure with it.
"""

import enum
import numbers
import os
import tempfile
import typing

import numpy as np

from . import _core

__all__ = ["count", "trajectory", "fixed_points", "continue_branch", "explore", "open", "Counts", "Outcome",
           "Trajectory", "OUTCOMES", "__version__"]

__version__ = _core.version
#: "superball 0.1.0 (git 0123456789ab)": the version and the git commit of this build.
SOURCE = _core.source
#: The compiler, build type and counting kernels of this build.
BUILD = _core.build
#: The counting kernel in use, those compiled in and those this processor runs.
KERNELS = _core.kernel_report
#: Outcome names, indexed by code (the result files' flag_meanings).
OUTCOMES = tuple(_core.outcomes)

class Outcome(enum.IntEnum):
    """How the motion of a launch ended; the value is the code stored in result files."""

    invalid = 0
    left = 1
    missed = 2
    capped = 3

    def __repr__(self):
        return f"Outcome.{self.name}"

    __str__ = __repr__


class Counts(typing.NamedTuple):
    """What count() returns: wall bounces (uint32) and outcome codes (uint8, see Outcome),
    arrays of the launches' broadcast shape; an int and an Outcome for a single launch."""

    wall_bounces: typing.Any
    outcome: typing.Any

    def outcome_names(self):
        """The outcomes as names ("invalid", "left", "missed", "capped"), same shape."""
        return np.asarray(OUTCOMES)[np.asarray(self.outcome)]


class Trajectory(dict):
    """What trajectory() returns: a dict of NumPy arrays, one per column of `superball
    trajectory --format csv` (event, wall_bounces, t, x, y, u_in, v_in, omega_in, u, v,
    omega), one row per event and per flight-path sample. Its attributes say what the
    launch came to: `wall_bounces` (the total), `outcome` (an Outcome), `truncated`
    (events stop early where the motion left double precision; the count stays exact),
    `units`, `g`, `radius` and `start` (xi, U, W)."""


# ----------------------------------------------------------------------------- arguments


def _real(name, value, optional=True):
    """A scalar argument as a float (None stays None when optional)."""
    if value is None and optional:
        return None
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        what = f"an array of shape {np.shape(value)}" if np.ndim(value) > 0 else f"{type(value).__name__} {value!r}"
        raise TypeError(f"{name} must be one real number, not {what}")
    return float(value)


def _integral(name, value):
    """An integer argument as an int (the library checks its range)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, not {type(value).__name__} {value!r}")
    return int(value)


def _integer(name, value, low, high, accepted):
    value = _integral(name, value)
    if not low <= value <= high:
        raise ValueError(f"{name} = {value} is out of range: accepted {accepted}")
    return value


def _threads(threads):
    if threads is None:
        return 0  # the library's default: every core this process may use
    return _integer("threads", threads, 1, 4096, "1 to 4096, or None for every core this process may use")


def _kernel(kernel):
    if kernel is None:
        return ""
    if not isinstance(kernel, str):
        raise TypeError(f"kernel must be a name (simd, scalar, baseline, avx2, avx512, native) or None, not {kernel!r}")
    return kernel


def _model(e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu=None, mu_wall=None, mu_floor=None, inertia=None):
    """The coefficients as given (None: not given), for _core, which checks them as the
    command line does (SPEC.md 1b: mu defaults to infinite, inertia to 0.4)."""
    given = dict(e=e, alpha=alpha, e_wall=e_wall, alpha_wall=alpha_wall, e_floor=e_floor, alpha_floor=alpha_floor, mu=mu,
                 mu_wall=mu_wall, mu_floor=mu_floor, inertia=inertia)
    return {key: _real(key, value) for key, value in given.items()}


def _coordinate(name, value):
    """A start coordinate as a float64 or float32 array (no copy when it already is one)."""
    try:
        a = np.asarray(value)
    except Exception as error:  # ragged nested lists, objects NumPy cannot hold
        raise TypeError(f"{name} must be real numbers (a number or an array), not {type(value).__name__}: {error}")
    if a.dtype.kind == "f" and a.dtype.itemsize in (4, 8):
        # Another byte order (">f8" on this little-endian machine: data from a file, say) is
        # swapped here; read as it is it gave wrong counts without a word.
        return a if a.dtype.isnative else a.astype(a.dtype.newbyteorder("="))
    if a.dtype.kind in "fiub":  # float16, integers, booleans: converted (a copy)
        return a.astype(np.float64)
    raise TypeError(f"{name} must be real numbers (a number or an array), not an array of {a.dtype}")


def _one_start(coordinates, g, radius, model, max_bounces):
    """(physical, {name: value} of the start's coordinates, g, radius, max_bounces): the
    library's checks of count and trajectory, in the command line's order and words."""
    given = [name for name, value in coordinates.items() if value is not None]
    physical, g, radius, max_bounces = _core.resolve_one_start(given, _real("g", g), _real("radius", radius),
                                                              str(_integral("max_bounces", max_bounces)), model=model)
    names = ("x", "u", "v", "omega") if physical else ("xi", "U", "W")
    return physical, {name: coordinates[name] for name in names}, g, radius, max_bounces


def _call_text(function, positional, keywords):
    """The call as Python reads it back, for the result's history."""
    parts = [repr(a) for a in positional] + [f"{k}={v!r}" for k, v in keywords.items()]
    return f"superball.{function}({', '.join(parts)})"


# ---------------------------------------------------------------------------------- API


def count(xi=None, U=None, W=None, *, x=None, u=None, v=None, omega=None, g=None, radius=None, e=None, alpha=None,
          e_wall=None, alpha_wall=None, e_floor=None, alpha_floor=None, mu=None, mu_wall=None, mu_floor=None,
          inertia=None, max_bounces=1000, threads=None, kernel=None):
    """Wall bounces and outcome of launches, at the speed of the vectorised kernel.

    The start is canonical, count(xi, U, W, ...), or physical, count(x=..., u=..., v=...,
    omega=..., g=9.81, radius=0.025, ...). Each coordinate is a number or a NumPy array
    (any shape, strides and real dtype: float32 is read as it is, integers are converted);
    they broadcast together as NumPy does, so count(xi[:, None], -1, W[None, :], ...)
    counts a grid.

    Arguments:
        xi, U, W   canonical coordinates (dimensionless): xi = g x / (2 |u| v) the launch
                   distance as a fraction of the free-flight range, U = u / v the direction
                   (< 0: toward the wall), W = a omega / v the spin
        x, u, v, omega   physical start: centre's distance from the wall [m], horizontal and
                   vertical velocity [m/s], spin [rad/s] (counter-clockwise positive)
        g, radius  gravity [m/s^2] (default 9.81) and ball radius [m] (default 0.025):
                   physical starts only
        e, alpha   normal (0 < e <= 1) and tangential (-1 <= alpha <= 1; -1 smooth, 1
                   perfectly rough) coefficients of restitution of both surfaces;
        e_wall, alpha_wall, e_floor, alpha_floor   per surface (override e, alpha)
        mu, mu_wall, mu_floor   Coulomb friction coefficient (Walton's law, SPEC.md 1b;
                   0 <= mu, default inf: the Cross model), both surfaces or per surface
        inertia    the ball's moment of inertia over m a^2 (0 < inertia <= 2/3; default
                   0.4, a solid ball; 2/3 a thin shell)
        max_bounces   wall impacts after which a launch still bouncing is "capped"
                   (1 to 2^32 - 1, default 1000)
        threads    counting threads (default None: every core this process may use)
        kernel     counting kernel: None (SUPERBALL_KERNEL, else the widest this processor
                   runs), "simd", "scalar", or a variant ("baseline", "avx2", "avx512",
                   "native"); all give the same bits

    Returns Counts(wall_bounces, outcome): arrays (uint32 counts, uint8 outcome codes) of
    the broadcast shape, or an int and an Outcome when every coordinate is a number.
    Outcomes: 0 invalid (not a launch toward the wall: U >= 0, xi <= 0, x <= 0, u >= 0,
    v <= 0; 0 bounces), 1 left (a floor bounce sent the ball away from the wall), 2 missed
    (it landed on the floor before reaching the wall: xi >= 1), 3 capped (max_bounces
    reached). Counts.outcome_names() gives the names.

    Raises ValueError naming the argument and the value for a coefficient out of range,
    a coordinate that is NaN or infinite (with its index), coordinates whose shapes do not
    broadcast, a mixed or incomplete start, max_bounces or threads out of range; TypeError
    for an argument of the wrong kind (a string, an array where one number is needed).
    Runs with the GIL released.

    >>> superball.count(0.05, -1, -2, e=0.9, alpha=0.9)
    Counts(wall_bounces=8, outcome=Outcome.left)
    """
    model = _model(e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall, mu_floor, inertia)
    physical, start, g, radius, max_bounces = _one_start(dict(xi=xi, U=U, W=W, x=x, u=u, v=v, omega=omega), g, radius,
                                                         model, max_bounces)
    threads, kernel = _threads(threads), _kernel(kernel)
    arrays = {name: _coordinate(name, value) for name, value in start.items()}
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        given = ", ".join(f"{name} (shape {a.shape})" for name, a in arrays.items())
        raise ValueError(f"the coordinates' shapes do not broadcast together: {given}") from None
    coordinates = [(name, np.broadcast_to(a, shape)) for name, a in arrays.items()]
    wall_bounces, outcome = _core.count(coordinates, physical, g, radius, max_bounces=max_bounces, threads=threads,
                                        kernel=kernel, model=model)
    if shape == ():
        return Counts(int(wall_bounces), Outcome(int(outcome)))
    return Counts(wall_bounces, outcome)


def trajectory(xi=None, U=None, W=None, *, x=None, u=None, v=None, omega=None, g=None, radius=None, e=None,
               alpha=None, e_wall=None, alpha_wall=None, e_floor=None, alpha_floor=None, mu=None, mu_wall=None,
               mu_floor=None, inertia=None, max_bounces=1000, samples=0):
    """Every impact of one launch: a Trajectory, a dict of NumPy arrays with the columns of
    `superball trajectory --format csv`.

    The start and model as in count(), each coordinate one number. A canonical start is
    followed in dimensionless units (v0 = g = radius = 1, so omega = W), a physical one in
    SI units. samples=K (0, or 2 to 100000) adds K points on every flight parabola (event
    "path") for plotting.

    Columns (one row per event, then per path sample):
        event         "launch", "wall" (impact), "floor" (bounce), "land" (the floor contact
                      after the motion ended, recorded, not applied), "path" (a sample)
        wall_bounces  wall impacts up to and including the row (uint32)
        t             time since launch [s]
        x, y          centre of the ball [m]
        u_in, v_in, omega_in   velocity [m/s] and spin [rad/s] arriving
        u, v, omega   leaving (a path sample: at the sample, both sides alike)
    Attributes: wall_bounces (total), outcome (an Outcome, equal to count()'s), truncated,
    units, g, radius, start (the canonical xi, U, W).
    """
    model = _model(e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall, mu_floor, inertia)
    _, start, _, _, max_bounces = _one_start(dict(xi=xi, U=U, W=W, x=x, u=u, v=v, omega=omega), g, radius, model,
                                             max_bounces)
    values = {name: _real(name, value) for name, value in start.items()}
    samples = _integer("samples", samples, 0, 100000, "0 or 2 to 100000")
    coordinates = dict(xi=None, U=None, W=None, x=None, u=None, v=None, omega=None)
    coordinates.update(values)
    columns, result = _core.trajectory(**coordinates, g=_real("g", g), radius=_real("radius", radius),
                                       max_bounces=max_bounces, samples=samples, model=model)
    out = Trajectory(columns)
    out["event"] = np.asarray(columns["event"], dtype=str)
    out.wall_bounces = result["wall_bounces"]
    out.outcome = Outcome[result["outcome"]]
    out.truncated = result["truncated"]
    out.units = result["units"]
    out.g, out.radius = result["g"], result["radius"]
    out.start = result["start"]
    return out


_CYCLE_COLUMNS = ("period", "xi", "U", "W", "lambda", "eig1", "eig2", "eig3", "stability", "family", "corner",
                  "residual")


def fixed_points(*, e=None, alpha=None, e_wall=None, alpha_wall=None, e_floor=None, alpha_floor=None, mu=None,
                 mu_wall=None, mu_floor=None, inertia=None, period=1, starts=2000, seed=1, corner=False):
    """Fixed points and cycles of the canonical map G (self-similar motions), as
    `superball fixed-points` finds them: Newton's method on G^k, k = 1..period, from
    `starts` seeded starts (seed: std::mt19937_64), in 0 < xi < 1, U < 0, and with
    corner=True also on the corner plane xi = 0.

    Returns a dict of NumPy arrays, one entry per distinct cycle (interior cycles first,
    then by period, xi, U, W): period; xi, U, W (the cycle's point with the smallest xi);
    lambda (product of the multipliers v'/v over the cycle: the self-similar scale per
    period); eig1, eig2, eig3 (complex eigenvalues of the Jacobian of G^period, by
    decreasing modulus); stability ("stable", "unstable", "saddle", "marginal"); family
    (an eigenvalue 1: a member of a continuous family); corner (on the plane xi = 0);
    residual (relative |G^k(s) - s|, at most 1e-10); and "points": the cycle's k points,
    one (k, 3) array per cycle.
    """
    model = _model(e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall, mu_floor, inertia)
    period = _integer("period", period, -2**31, 2**31 - 1, "1 to 8")
    starts = _integer("starts", starts, -2**63, 2**63 - 1, "starts >= 1")
    seed = _integer("seed", seed, 0, 2**64 - 1, "0 to 2^64 - 1")
    cycles = _core.fixed_points(period=period, starts=starts, seed=seed, corner=bool(corner), model=model)
    out = {}
    for key in _CYCLE_COLUMNS:
        if key.startswith("eig"):
            values = [c["eigenvalues"][int(key[3]) - 1] for c in cycles]
            out[key] = np.asarray(values, dtype=complex)
        else:
            values = [c[key] for c in cycles]
            dtype = {"period": np.int64, "stability": str, "family": bool, "corner": bool}.get(key, np.float64)
            out[key] = np.asarray(values, dtype=dtype)
    out["points"] = [np.asarray(c["points"], dtype=np.float64) for c in cycles]
    return out


_POINT_COLUMNS = ("xi", "U", "W", "lambda", "ev1_re", "ev1_im", "ev2_re", "ev2_im", "ev3_re", "ev3_im", "stability",
                  "event", "note", "residual", "arclength", "bracket")


def _table(rows, columns):
    """A dict of NumPy arrays from rows of values."""
    out = {}
    for k, key in enumerate(columns):
        values = [r[k] for r in rows]
        if key in ("stability", "event", "note"):
            out[key] = np.asarray(values, dtype=str)
        elif key in ("branch", "curve", "period"):
            out[key] = np.asarray(values, dtype=np.int64)
        elif key == "corner":
            out[key] = np.asarray(values, dtype=bool)
        else:
            out[key] = np.asarray(values, dtype=np.float64)
    return out


def continue_branch(*, param, min, max, e=None, alpha=None, e_wall=None, alpha_wall=None, e_floor=None,
                    alpha_floor=None, mu=None, mu_wall=None, mu_floor=None, inertia=None, start=None, period=1, starts=2000, seed=1, corner=False, step=None,
                    max_step=0.05, min_step=1e-7, max_points=2000, curve=None, curve_min=None, curve_max=None,
                    curve_step=0.005, curve_max_step=0.02, curve_max_points=400):
    """Branches of cycles of G followed in one coefficient, as `superball continue` prints
    them (pseudo-arclength continuation around folds; events located to 1e-10).

    Arguments: param, the coefficient ("e", "alpha", "e_wall", "alpha_wall", "e_floor",
    "alpha_floor") followed between min and max; the model at the start (e, alpha, ...).
    Without start every cycle the fixed-point search finds (periods 1..period, starts,
    seed, corner as in fixed_points) starts a branch; with start=(xi, U, W) the cycle of
    period `period` Newton's method finds from there (xi = 0: on the corner plane). Steps
    in arclength: step (default min(0.01, max_step)), max_step, min_step; max_points per
    direction. curve="e" (with curve_min, curve_max, curve_step, curve_max_step,
    curve_max_points) also follows every fold, period doubling, Neimark-Sacker and branch
    point as a curve in the plane (param, curve).

    Returns a dict:
        "points"    NumPy arrays with the CSV's columns: branch, period, corner, <param>,
                    xi, U, W (the cycle's point with the smallest xi), lambda, ev1_re ...
                    ev3_im (eigenvalues of D(G^k) by decreasing modulus), stability, event
                    ("", "fold", "period_doubling", "neimark_sacker", "branch_point",
                    "boundary", "end"), note, residual, arclength, bracket
        "branches"  per branch: its start cycle (as fixed_points describes one), same_as
                    (the earlier branch it lies on, or None), continued, start_index
        "curves"    with curve: NumPy arrays with the curve CSV's columns (curve, branch,
                    event, period, corner, <param>, <curve>, xi, U, W, lambda, ev1_re ...,
                    stability, note), and "curve_ends": per curve, why each end stopped
    """
    model = _model(e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall, mu_floor, inertia)
    if not isinstance(param, str):
        raise TypeError(f"param must be a coefficient's name, not {param!r}")
    if curve is not None and not isinstance(curve, str):
        raise TypeError(f"curve must be a coefficient's name or None, not {curve!r}")
    if start is not None:
        if np.shape(start) != (3,):
            raise ValueError(f"start = {start!r} is not three numbers: accepted (xi, U, W)")
        start = tuple(_real("start", s, optional=False) for s in start)
    r = _core.continue_branch(
        param=param, min=_real("min", min), max=_real("max", max), start=start,
        period=_integer("period", period, -2**31, 2**31 - 1, "1 to 8"),
        starts=_integer("starts", starts, -2**63, 2**63 - 1, "starts >= 1"),
        seed=_integer("seed", seed, 0, 2**64 - 1, "0 to 2^64 - 1"), corner=bool(corner), step=_real("step", step),
        max_step=_real("max_step", max_step, optional=False), min_step=_real("min_step", min_step, optional=False),
        max_points=_integer("max_points", max_points, -2**31, 2**31 - 1, "max_points >= 1"), curve=curve or "",
        curve_min=_real("curve_min", curve_min), curve_max=_real("curve_max", curve_max),
        curve_step=_real("curve_step", curve_step, optional=False),
        curve_max_step=_real("curve_max_step", curve_max_step, optional=False),
        curve_max_points=_integer("curve_max_points", curve_max_points, -2**31, 2**31 - 1, "curve_max_points >= 1"),
        model=model)
    p = r["parameter"]
    rows = []
    for i, b in enumerate(r["branches"]):
        for q in b["points"]:
            rows.append((i, b["period"], b["corner"]) + tuple(q))
    out = {"points": _table(rows, ("branch", "period", "corner", p) + _POINT_COLUMNS),
           "branches": [{"start": b["start"], "same_as": b["same_as"], "continued": b["continued"],
                         "start_index": b.get("start_index")} for b in r["branches"]],
           "curves": None, "curve_ends": None}
    if "curves" in r:
        q = r["curve_parameter"]
        rows = []
        for i, c in enumerate(r["curves"]):
            for first, second, point in c["points"]:
                rows.append((i, c["branch"], c["event"], c["period"], c["corner"], first, second) + tuple(point[1:12])
                            + (point[13],))
        columns = ("curve", "branch", "event", "period", "corner", p, q, "xi", "U", "W", "lambda", "ev1_re", "ev1_im",
                   "ev2_re", "ev2_im", "ev3_re", "ev3_im", "stability", "note")
        out["curves"] = _table(rows, columns)
        out["curve_ends"] = [c.get("ends") for c in r["curves"]]
    return out


def _toml_value(value, where):
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))  # shortest text that reads back the same; nan, inf as TOML spells them
    if isinstance(value, str):
        import json

        return json.dumps(value)  # a TOML basic string
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_toml_key(k, where)} = {_toml_value(v, f'{where}.{k}')}" for k, v in value.items()) + " }"
    raise TypeError(f"job {where} = {value!r}: a job holds numbers, texts, booleans and tables of them")


def _toml_key(key, where):
    if not isinstance(key, str):
        raise TypeError(f"job {where}: key {key!r} is not a text")
    if key and all(c.isascii() and (c.isalnum() or c in "_-") for c in key):
        return key
    import json

    return json.dumps(key)


def _toml_text(job):
    """A job given as a dict ({"model": {...}, "grid": {...}, "run": {...}}) as TOML."""
    lines = []
    for section, body in job.items():
        if not isinstance(body, dict):
            raise TypeError(f"job [{section}] = {body!r}: a job's sections are tables (dicts), e.g. "
                            "{'model': {'e': 0.9, 'alpha': 0.9}, 'grid': {...}, 'run': {...}}")
        lines.append(f"[{_toml_key(section, section)}]")
        for key, value in body.items():
            lines.append(f"{_toml_key(key, section)} = {_toml_value(value, f'[{section}] {key}')}")
        lines.append("")
    return "\n".join(lines)


def explore(job, output=None, *, overwrite=False, resume=False, threads=None, kernel=None, progress=False,
            dataset=True):
    """Run an exploration job in this process, on threads (no MPI needed), and return its
    result as an xarray.Dataset: the same file `mpirun superball explore JOB` writes (names,
    coordinates, attributes, values), read back.

    Arguments:
        job        a job file's path (TOML, as for superball explore) or a dict of its
                   tables, e.g. {"model": {"e": 0.9, "alpha": 0.9}, "grid": {"coordinates":
                   "canonical", "xi": {"min": 0.0, "max": 1.0, "n": 512}, "U": -1.0,
                   "W": {"min": -3.0, "max": 3.0, "n": 512}}, "run": {"max_bounces": 1000}}
        output     the result file; default the job's [run] output, else a temporary file
                   removed once the dataset is read into memory
        overwrite  replace an existing result (superball's own files only)
        resume     finish an interrupted run of the same job (Ctrl-C, superball explore's
                   --stop-after or a signal leave a resumable OUTPUT.partial)
        threads    counting threads (default: every core this process may use)
        kernel     as for count()
        progress   print progress lines on standard error
        dataset    False: return the run's summary (a dict) instead of the dataset

    The result is written while the threads count (OUTPUT.partial, made OUTPUT when every
    tile is done), with its provenance: history names this call. Ctrl-C stops cleanly: the
    partial file is kept and KeyboardInterrupt raised; explore(..., resume=True) finishes
    it. Raises ValueError for a bad job (naming the key and value) or an output that must
    not be touched, RuntimeError when the files cannot be written.
    """
    keywords = {k: v for k, v in dict(output=output, overwrite=overwrite, resume=resume, threads=threads,
                                      kernel=kernel).items() if v not in (None, False)}
    command = _call_text("explore", [job], keywords)
    if isinstance(job, dict):
        parsed = _core.parse_job(_toml_text(job), "the job dict")
        source = "the job dict"
    elif isinstance(job, (str, os.PathLike)):
        source = os.fspath(job)
        parsed = _core.load_job(source)
    else:
        raise TypeError(f"job must be a job file's path or a dict of its tables, not {type(job).__name__}")
    if output is not None and not isinstance(output, (str, os.PathLike)):
        raise TypeError(f"output must be a file path or None, not {type(output).__name__}")
    run = dict(overwrite=bool(overwrite), resume=bool(resume), threads=_threads(threads), kernel=_kernel(kernel),
               command=command, progress=bool(progress))
    path = os.fspath(output) if output is not None else parsed["output"]
    if path:
        try:
            summary = _core.explore(parsed["text"], source, dict(run, output=path))
        except KeyboardInterrupt:
            import sys

            print(f"superball.explore: stopped; the run is kept in {path}.partial: explore(..., resume=True) finishes it",
                  file=sys.stderr)
            raise
        return open(summary["output"]) if dataset else summary
    with tempfile.TemporaryDirectory(prefix="superball-") as directory:
        summary = _core.explore(parsed["text"], source, dict(run, output=os.path.join(directory, "result.h5")))
        if not dataset:
            return summary
        with open(summary["output"]) as ds:
            return ds.load()


def open(path):  # noqa: A001 - superball.open, as xarray.open_dataset
    """A result file as an xarray.Dataset, after the validation `superball info` makes:
    the file's kind and format, every attribute, the datasets and coordinate variables,
    and every value (outcome codes 0 to 3, counts consistent with them). A damaged file,
    or the partial file of a run not finished, raises ValueError with the reason.

    The dataset has the file's names, coordinates (one per range axis, fixed coordinates as
    scalars) and attributes (the job, the model, the provenance: history, source,
    date_created, build). It reads the file lazily; close it (or use `with`) when done.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file path, not {type(path).__name__}")
    path = os.fspath(path)
    _core.validate(path)
    import xarray

    try:
        import h5netcdf  # noqa: F401 - the engine superball's tests read results with
        engine = "h5netcdf"
    except ImportError:
        engine = None
    return xarray.open_dataset(path, engine=engine)
