"""The same bad input to the command line (`superball count`, `superball trajectory`) and to
the module (superball.count, superball.trajectory) is refused in the same words: both take
their checks, their order and their messages from the library (core/input.hpp,
resolve_one_start). Each names a key as its user writes it (`--e-wall` on the command
line, `e_wall` in Python); with that spelling mapped, the texts are equal."""
import re

import pytest

from conftest import run_cli

M = dict(e=0.9, alpha=0.9)
CANONICAL = dict(xi=0.1, U=-1, W=1)
PHYSICAL = dict(x=0.1, u=-1, v=1, omega=1)

# (what is wrong, the arguments as Python keywords; the command line gets the same as flags)
CASES = [
    ("no coefficient", dict(CANONICAL)),
    ("e out of range", dict(CANONICAL, e=1.5, alpha=0.9)),
    ("alpha_floor out of range", dict(CANONICAL, **M, alpha_floor=-2)),
    ("e_wall not set", dict(CANONICAL, alpha=0.9, e_floor=0.8)),
    ("no start", dict(M)),
    ("W not set", dict(M, xi=0.1, U=-1)),
    ("canonical and physical", dict(M, **CANONICAL, x=0.1)),
    ("g with a canonical start", dict(M, **CANONICAL, g=9.81)),
    ("omega not set", dict(M, x=0.1, u=-1, v=1)),
    ("g out of range", dict(M, **PHYSICAL, g=-1)),
    ("radius out of range", dict(M, **PHYSICAL, radius=0)),
    ("max_bounces 0", dict(M, **CANONICAL, max_bounces=0)),
    ("max_bounces negative", dict(M, **CANONICAL, max_bounces=-3)),
    ("max_bounces past 2^32", dict(M, **CANONICAL, max_bounces=2**32)),
    ("model before start", dict(e=2)),
    ("start before max_bounces", dict(M, xi=0.1, max_bounces=0)),
    # SPEC.md 1b
    ("mu negative", dict(CANONICAL, **M, mu=-0.5)),
    ("mu_floor NaN", dict(CANONICAL, **M, mu_floor=float("nan"))),
    ("inertia 0", dict(CANONICAL, **M, inertia=0)),
    ("inertia past a thin shell", dict(CANONICAL, **M, inertia=0.7)),
]


def flags(arguments):
    return [f"--{key.replace('_', '-')}={value}" for key, value in arguments.items()]


def as_python(message):
    """The command line's message with its flags spelled as Python's arguments."""
    return re.sub(r"--([a-zA-Z]+(?:-[a-z]+)*)", lambda m: m.group(1).replace("-", "_"), message)


@pytest.mark.parametrize("command", ["count", "trajectory"])
@pytest.mark.parametrize("name,arguments", CASES, ids=[c[0] for c in CASES])
def test_the_command_line_and_python_refuse_in_the_same_words(superball, command, name, arguments):
    r = run_cli(command, *flags(arguments), check=False)
    assert r.returncode == 2, f"{name}: exit {r.returncode}\n{r.stderr}"
    prefix = f"superball {command}: "
    assert r.stderr.startswith(prefix), r.stderr
    cli = as_python(r.stderr[len(prefix):].strip())
    with pytest.raises(ValueError) as caught:
        getattr(superball, command)(**arguments)
    assert str(caught.value) == cli, f"{name}: Python {str(caught.value)!r}, command line {cli!r}"


def test_the_table_is_large():
    assert len(CASES) >= 12
