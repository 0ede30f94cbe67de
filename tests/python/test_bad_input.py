"""Bad input to the module: every case raises ValueError or TypeError naming the argument
(and its value), never a crash or a silent wrong answer. Run under AddressSanitizer too
(the asan preset builds the module sanitized)."""
import math

import numpy as np
import pytest

M = dict(e=0.9, alpha=0.9)
nan = math.nan

# (call, exception, words the message must contain)
CASES = [
    ("count(nan, -1, -2)", lambda s: s.count(nan, -1, -2, **M), ValueError, ["xi = nan", "index ()", "not a finite"]),
    ("count(U with an inf)", lambda s: s.count(0.5, np.array([-1.0, -np.inf]), 0, **M), ValueError,
     ["U = -inf", "index (1,)"]),
    ("count(W NaN deep in a grid)", lambda s: s.count(np.full((3, 4), 0.5), -1, np.where(np.eye(3, 4) > 0, nan, 1.0), **M),
     ValueError, ["W = nan", "index (0, 0)"]),
    ("count(float32 NaN)", lambda s: s.count(np.float32(nan), -1, 0, **M), ValueError, ["xi = nan"]),
    ("count(omega NaN)", lambda s: s.count(x=0.1, u=-1, v=1, omega=[0, nan], **M), ValueError, ["omega = nan", "(1,)"]),
    ("count(e = 1.5)", lambda s: s.count(0.5, -1, 0, e=1.5, alpha=0.9), ValueError, ["e = 1.5", "0 < e <= 1"]),
    ("count(e = 0)", lambda s: s.count(0.5, -1, 0, e=0, alpha=0.9), ValueError, ["e = 0", "out of range"]),
    ("count(e = nan)", lambda s: s.count(0.5, -1, 0, e=nan, alpha=0.9), ValueError, ["e = nan"]),
    ("count(alpha = -2)", lambda s: s.count(0.5, -1, 0, e=0.9, alpha=-2), ValueError, ["alpha = -2", "-1 <= alpha <= 1"]),
    ("count(alpha_floor = 1.1)", lambda s: s.count(0.5, -1, 0, alpha_floor=1.1, **M), ValueError, ["alpha_floor = 1.1"]),
    ("count(no alpha)", lambda s: s.count(0.5, -1, 0, e=0.9), ValueError, ["alpha_wall is not set", "alpha"]),
    ("count(e an array)", lambda s: s.count(0.5, -1, 0, e=np.array([0.9, 0.8]), alpha=0.9), TypeError, ["e must be one"]),
    ("count(e a text)", lambda s: s.count(0.5, -1, 0, e="0.9", alpha=0.9), TypeError, ["e must be one", "'0.9'"]),
    ("count(shapes)", lambda s: s.count(np.zeros(3), np.zeros(4) - 1, 0, **M), ValueError,
     ["do not broadcast", "xi (shape (3,))", "U (shape (4,))"]),
    ("count(max_bounces = 0)", lambda s: s.count(0.5, -1, 0, max_bounces=0, **M), ValueError, ["max_bounces = 0"]),
    ("count(max_bounces = -5)", lambda s: s.count(0.5, -1, 0, max_bounces=-5, **M), ValueError, ["max_bounces = -5"]),
    ("count(max_bounces = 2^32)", lambda s: s.count(0.5, -1, 0, max_bounces=2**32, **M), ValueError,
     ["max_bounces = 4294967296"]),
    ("count(max_bounces = 1.5)", lambda s: s.count(0.5, -1, 0, max_bounces=1.5, **M), TypeError, ["max_bounces"]),
    ("count(threads = 0)", lambda s: s.count(0.5, -1, 0, threads=0, **M), ValueError, ["threads = 0"]),
    ("count(kernel unknown)", lambda s: s.count(0.5, -1, 0, kernel="avx9000", **M), ValueError,
     ["kernel = 'avx9000'", "accepted"]),
    ("count(strings)", lambda s: s.count(["a", "b"], -1, 0, **M), TypeError, ["xi must be real numbers"]),
    ("count(complex)", lambda s: s.count(0.5, -1 + 1j, 0, **M), TypeError, ["U must be real numbers"]),
    ("count(None inside)", lambda s: s.count([0.5, None], -1, 0, **M), TypeError, ["xi must be real numbers"]),
    ("count(mixed start)", lambda s: s.count(0.5, -1, 0, x=0.1, **M), ValueError, ["not both", "x"]),
    ("count(no W)", lambda s: s.count(0.5, -1, **M), ValueError, ["W is not set"]),
    ("count(no start)", lambda s: s.count(**M), ValueError, ["no start"]),
    ("count(g canonical)", lambda s: s.count(0.5, -1, 0, g=9.81, **M), ValueError, ["g and radius"]),
    ("count(g = -1)", lambda s: s.count(x=0.1, u=-1, v=1, omega=0, g=-1, **M), ValueError, ["g = -1"]),
    ("count(radius = 0)", lambda s: s.count(x=0.1, u=-1, v=1, omega=0, radius=0, **M), ValueError, ["radius = 0"]),
    ("trajectory(U = 0.5)", lambda s: s.trajectory(0.5, 0.5, 0, **M), ValueError, ["U = 0.5", "launch toward the wall"]),
    ("trajectory(samples = 1)", lambda s: s.trajectory(0.5, -1, 0, samples=1, **M), ValueError, ["samples = 1"]),
    ("trajectory(xi an array)", lambda s: s.trajectory(np.array([0.5, 0.6]), -1, 0, **M), TypeError, ["xi must be one"]),
    ("fixed_points(period = 9)", lambda s: s.fixed_points(period=9, **M), ValueError, ["period = 9", "1..8"]),
    ("fixed_points(starts = 0)", lambda s: s.fixed_points(starts=0, **M), ValueError, ["starts = 0"]),
    ("continue_branch(param)", lambda s: s.continue_branch(param="beta", min=0.9, max=1, **M), ValueError,
     ["param = beta", "accepted e, alpha"]),
    ("continue_branch(min >= max)", lambda s: s.continue_branch(param="alpha", min=0.95, max=0.9, e=0.9, alpha=0.92),
     ValueError, ["min = 0.95", "not below max"]),
    ("continue_branch(max_step)", lambda s: s.continue_branch(param="alpha", min=0.9, max=1, max_step=-1, **M),
     ValueError, ["max_step = -1"]),
    ("continue_branch(start U > 0)", lambda s: s.continue_branch(param="alpha", min=0.9, max=1, start=(0.2, 0.5, -1), **M),
     ValueError, ["start = 0.2,0.5,-1", "launch toward the wall"]),
    ("continue_branch(start no cycle)",
     lambda s: s.continue_branch(param="alpha", min=0.9, max=1, start=(0.9, -50, 30), **M), ValueError,
     ["start = 0.9,-50,30", "no cycle"]),
    ("continue_branch(curve_step)", lambda s: s.continue_branch(param="alpha", min=0.5, max=1, curve="e", curve_min=0.5,
                                                                curve_max=1, curve_step=0, e=0.9, alpha=0.99),
     ValueError, ["curve_step = 0"]),
    ("explore(job key)", lambda s: s.explore({"model": {"e": 0.9, "alpah": 0.9}}), ValueError,
     ["alpah", "did you mean alpha"]),
    ("explore(n = 0)", lambda s: s.explore({"model": M, "grid": {"xi": {"min": 0, "max": 1, "n": 0}, "U": -1, "W": 0}}),
     ValueError, ["n = 0"]),
    ("explore(min >= max)", lambda s: s.explore({"model": M, "grid": {"xi": {"min": 1, "max": 0, "n": 4}, "U": -1, "W": 0}}),
     ValueError, ["xi", "min"]),
    ("explore(value not TOML)", lambda s: s.explore({"model": {"e": [0.9]}}), TypeError, ["[model] e"]),
    ("explore(job a number)", lambda s: s.explore(3), TypeError, ["job must be"]),
    ("explore(missing file)", lambda s: s.explore("/nonexistent/job.toml"), ValueError, ["/nonexistent/job.toml"]),
    ("open(not a result)", lambda s: s.open(__file__), ValueError, ["test_bad_input.py", "not"]),
    ("open(a number)", lambda s: s.open(42), TypeError, ["path must be"]),
]


@pytest.mark.parametrize("name,call,exception,words", CASES, ids=[c[0] for c in CASES])
def test_bad_input_is_refused_with_the_argument_named(superball, name, call, exception, words):
    with pytest.raises(exception) as caught:
        call(superball)
    message = str(caught.value)
    for word in words:
        assert word in message, f"{name}: {message!r} lacks {word!r}"


def test_the_table_is_large():
    assert len(CASES) >= 20


def test_explore_refuses_to_overwrite(superball, tmp_path):
    job = {"model": M, "grid": {"xi": {"min": 0.0, "max": 1.0, "n": 8}, "U": -1.0, "W": 0.0}}
    out = tmp_path / "r.h5"
    superball.explore(job, out).close()
    with pytest.raises(ValueError, match="already holds a complete result"):
        superball.explore(job, out)
    text = tmp_path / "notes.txt"
    text.write_text("not mine\n")
    with pytest.raises(ValueError, match="not a superball file"):
        superball.explore(job, text, overwrite=True)
    assert text.read_text() == "not mine\n"
