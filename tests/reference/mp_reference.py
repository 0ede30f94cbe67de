#!/usr/bin/env python3
"""An independent, high-precision reference for counting wall bounces (issue 24).

A second implementation of the model of ../shared/SPEC.md, written from its equations
in Python with mpmath (Debian's python3-mpmath; no other dependency), and the generator of
tests/reference/mp_counts.csv:

    /usr/bin/python3 tests/reference/mp_reference.py --out tests/reference/mp_counts.csv

and (SPEC section 1b: Coulomb friction per surface, the ball's moment of inertia) of
tests/reference/mp_friction_counts.csv:

    nice -n 19 /usr/bin/python3 tests/reference/mp_reference.py --friction --out tests/reference/mp_friction_counts.csv

What is computed (SPEC sections 1 to 3). A canonical launch (xi, U, W) is represented by
the physical state with v = 1 and g = 1: x = 2 xi |U| (from xi = g x / (2 |u| v)),
u = U, v = 1, W = W. Each excursion is the physical map F of SPEC section 1 applied as
written there:

    y   = -(x/u) (v + g x/(2u))        height of the centre at the wall; y <= 0: missed
    v_w = v + g x/u                    vertical velocity at the wall
    u+  = -e_w u,  v+ = (2/7)(1+a_w) W + (1/7)(5-2a_w) v_w,  W+ = (5/7)(1+a_w) v_w + (1/7)(2-5a_w) W
    v_f = -sqrt(v+^2 + 2 g y),  T = (v+ - v_f)/g,  x' = u+ T
    u'  = (1/7)(5-2a_f) u+ - (2/7)(1+a_f) W+,  W' = -(5/7)(1+a_f) u+ + (1/7)(2-5a_f) W+,  v' = -e_f v_f
    u' >= 0: left

after which the state is divided by its scale k = v' (x -> x/k^2, (u, v, W) -> (u, v, W)/k:
the invariance of SPEC section 2), so the numbers stay O(1) over thousands of bounces. No
closed form of the canonical map G is used: the C++ kernel (src/core/map.hpp) writes G with
y = 2 xi (1 - xi) and a cancellation-free flight time; this module goes through x and u.

Conventions (SPEC section 3): N is the number of wall impacts. invalid (N = 0): xi <= 0,
U >= 0 or a non-finite coordinate. missed: heading to the wall, y <= 0 (xi >= 1). capped:
N = max_bounces and the ball is heading for one more wall impact. SPEC does not say which
of missed and capped a ball gets when, after max_bounces impacts, its next excursion would
miss the wall; the C++ kernel says missed (src/core/count.cpp) and so does this module, but
the generator keeps no such row (the reference does not take sides where SPEC is silent).

Precision. Model coefficients and launch coordinates are the binary64 numbers written in
the CSV (shortest round-trip decimal), converted exactly to mpf, so the only difference
from a correct double-precision kernel is the kernel's rounding. A row is kept only when
its (N, outcome) is the same
  - at mp.dps = 40 and 80,
  - for launches perturbed by a relative 1e-12 in each coordinate (both signs) and in two
    random directions,
  - with the impact coefficients (1/7)(5 - 2 alpha)... rounded to binary64, and
  - in two runs with every coefficient moved by a random relative 1e-15 and the state moved
    by a random relative 1e-14 after every excursion (what a kernel's rounding does),
so that a correct kernel in double precision must give the same answer. Launch perturbations
alone are not enough: with e = alpha = 1 (no dissipation) launches near the saddle part of
the line of self-retracing motions (xi about 0.41) stay bouncing for 2000 impacts in exact
arithmetic, for every launch nearby, yet leave or miss after a few hundred once the
coefficients are rounded to binary64 (3/7 is not a binary64 number) or each step rounds:
the answer depends on the map being exactly SPEC's (energy-conserving, time-reversible),
which no binary64 kernel's is. 12 such rows disagreed with the C++ kernel before the map
perturbations were added to the test.

Section 1b: friction and inertia (`--friction`). A Model also has a friction coefficient per
surface, mu_wall and mu_floor (math.inf allowed: no Coulomb limit), and the ball's moment of
inertia kappa (job key `inertia`, 0 < kappa <= 2/3). The Cross model of section 1 (mu = inf on
both surfaces and kappa = 0.4, the defaults) keeps the coefficients above, so mp_counts.csv is
reproduced as it was; any other model is iterated with SPEC 1b's impacts (class Surface), in
mpmath, the flights as above:

    wall:  s = v_w - W, v_n = -u;    floor: s = u+ + W+, v_n = -v_f;    psi = |s| / v_n
    beta = min(alpha, -1 + mu (1 + e)(1 + 1/kappa) / psi)      (beta = alpha when s = 0, or mu = inf)
    u+ = -e_w u,  v+ = ((1 - kappa beta) v_w + kappa (1 + beta) W) / (1 + kappa),
                  W+ = ((1 + beta) v_w + (kappa - beta) W) / (1 + kappa)
    u' = ((1 - kappa beta) u+ - kappa (1 + beta) W+) / (1 + kappa),
    W' = ((kappa - beta) W+ - (1 + beta) u+) / (1 + kappa),  v' = -e_f v_f

An impact slides when beta < alpha (its tangential impulse is then mu times the normal one;
mu = 0: beta = -1), and grips otherwise. tests/reference/mp_friction_counts.csv has the columns

    e_wall,alpha_wall,mu_wall,e_floor,alpha_floor,mu_floor,inertia,max_bounces,xi,U,W,wall_bounces,outcome,slides

(floats as shortest round-trip decimals, infinity as `inf`; `slides`, for information: how many
impacts of the orbit, wall and floor together, slid), for the models FRICTION_MODELS: mu from 0
to 3 and inf, the same on both surfaces or not, kappa 0.25, 0.4, 0.5 and 2/3, e/alpha from
0.8/0.6 to 1/1. Its rows pass the tests above with the map of section 1b: the coefficients
rounded to binary64 or moved by a relative 1e-15 are e, alpha, kappa, 1/(1 + kappa),
mu (1 + e)(1 + 1/kappa) and the four impact factors (a sliding impact's afresh at each impact);
and, in addition, no impact of the orbit (dps 40) has psi within a relative 1e-9 (SWITCHING) of
its grip/slide threshold psi* = mu (1 + e)(1 + 1/kappa)/(1 + alpha), where the map switches
between its two smooth pieces, so the rows stay away from the switching surfaces.

Other checks: `--self-test` (the invariants of SPEC 1b's impacts on random impacts: angular
momentum about the contact point, s -> -beta s, kinetic energy, the Coulomb impulse ratio of a
sliding impact, section 1's coefficients for mu = inf and kappa = 0.4), `--check-cross`
(mp_counts.csv recomputed with SPEC 1b's impacts, mu = inf, kappa = 0.4: every row agrees),
`--check-friction` (mp_friction_counts.csv recomputed), `--count-friction` (one launch).

The generator is deterministic (a fixed seed); `--check-canonical` recomputes the rows of
tests/reference/canonical_counts.csv (computed by another, independent, implementation).
"""

import argparse
import csv
import math
import os
import random
import sys
import time

from mpmath import mp, mpf

OUTCOMES = ("invalid", "left", "missed", "capped")
HEADER = ["e_wall", "alpha_wall", "e_floor", "alpha_floor", "max_bounces", "xi", "U", "W", "wall_bounces", "outcome"]

DPS_LOW = 40
DPS_HIGH = 80
PERTURBATION = 1e-12        # relative, of the launch
COEFFICIENT_JITTER = 1e-15  # relative, of each impact coefficient (binary64 rounding: 1.1e-16)
STEP_NOISE = 1e-14          # relative, of the state after each excursion (binary64: a few 1e-16)
SWITCHING = 1e-9            # relative, the least distance of psi to a grip/slide threshold (section 1b)

HERE = os.path.dirname(os.path.abspath(__file__))


# ----------------------------------------------------------------------------- the model


class Model:
    """Coefficients of restitution of both surfaces, and (SPEC section 1b) the friction
    coefficient of each surface and the ball's moment of inertia kappa (binary64, as the
    kernel sees them). The defaults, mu = inf on both surfaces and kappa = 0.4, are the
    Cross model of SPEC section 1 (`cross()`), which count_in iterates with section 1's
    coefficients; any other model goes through the impacts of section 1b."""

    def __init__(self, e_wall, alpha_wall, e_floor, alpha_floor, mu_wall=math.inf, mu_floor=math.inf,
                 inertia=0.4):
        self.e_wall, self.alpha_wall = float(e_wall), float(alpha_wall)
        self.e_floor, self.alpha_floor = float(e_floor), float(alpha_floor)
        self.mu_wall, self.mu_floor = float(mu_wall), float(mu_floor)
        self.inertia = float(inertia)
        for e in (self.e_wall, self.e_floor):
            if not 0.0 < e <= 1.0:
                raise ValueError("e out of range: %r" % e)
        for a in (self.alpha_wall, self.alpha_floor):
            if not -1.0 <= a <= 1.0:
                raise ValueError("alpha out of range: %r" % a)
        for mu in (self.mu_wall, self.mu_floor):
            if not mu >= 0.0:
                raise ValueError("mu out of range: %r" % mu)
        if not 0.0 < self.inertia <= 2.0 / 3.0:
            raise ValueError("inertia out of range: %r" % self.inertia)

    @classmethod
    def uniform(cls, e, alpha):
        return cls(e, alpha, e, alpha)

    @classmethod
    def friction(cls, e_wall, alpha_wall, mu_wall, e_floor, alpha_floor, mu_floor, inertia):
        """The argument order of the friction CSV's columns."""
        return cls(e_wall, alpha_wall, e_floor, alpha_floor, mu_wall, mu_floor, inertia)

    @classmethod
    def friction_uniform(cls, e, alpha, mu, inertia):
        return cls(e, alpha, e, alpha, mu, mu, inertia)

    def cross(self):
        """The Cross model of SPEC section 1: no Coulomb limit, a solid ball."""
        return math.isinf(self.mu_wall) and math.isinf(self.mu_floor) and self.inertia == 0.4

    def fields(self):
        return [self.e_wall, self.alpha_wall, self.e_floor, self.alpha_floor]

    def friction_fields(self):
        return [self.e_wall, self.alpha_wall, self.mu_wall, self.e_floor, self.alpha_floor, self.mu_floor,
                self.inertia]

    def key(self):
        return tuple(self.fields()) if self.cross() else tuple(self.friction_fields())

    def __repr__(self):
        if self.cross():
            return "Model(%r, %r, %r, %r)" % tuple(self.fields())
        return "Model.friction(%r, %r, %r, %r, %r, %r, %r)" % tuple(self.friction_fields())


class Arithmetic:
    """The number type a count runs in: mpmath at mp.dps digits, or Python floats
    (used only to screen candidates quickly; never for a reference value)."""

    def __init__(self, dps=None):
        self.dps = dps

    def num(self, x):
        return mpf(x) if self.dps else float(x)

    def sqrt(self, x):
        return mp.sqrt(x) if self.dps else math.sqrt(x)


def _surface(e, alpha, A):
    """(e, c_ss, c_sW, c_Ws, c_WW) of one surface, in the arithmetic A: the factors
    (1/7)(5-2 alpha), (2/7)(1+alpha), (5/7)(1+alpha), (1/7)(2-5 alpha) of SPEC section 1."""
    e, a = A.num(e), A.num(alpha)
    seven = A.num(7)
    return e, (5 - 2 * a) / seven, 2 * (1 + a) / seven, 5 * (1 + a) / seven, (2 - 5 * a) / seven


class Jitter:
    """Perturbations of the map itself, standing in for what a binary64 kernel cannot avoid:
    its coefficients are binary64 numbers (`round_coefficients`: the nearest binary64 of each
    exact coefficient), and every step rounds (`coefficients` > 0: each coefficient moved by a
    random relative amount up to that size, once; `steps` > 0: the state after each
    excursion moved by a random relative amount up to that size in each of x, u, W)."""

    def __init__(self, rng=None, coefficients=0.0, steps=0.0, round_coefficients=False):
        self.rng = rng
        self.coefficient_size = coefficients
        self.step_size = steps
        self.round_coefficients = round_coefficients

    def _factor(self, size):
        return 1 + mpf(size) * mpf(self.rng.uniform(-1.0, 1.0))

    def surface(self, coefficients):
        if self.round_coefficients:
            coefficients = tuple(mpf(float(c)) for c in coefficients)
        if self.coefficient_size:
            coefficients = tuple(c * self._factor(self.coefficient_size) for c in coefficients)
        return coefficients

    def state(self, x, u, W):
        if not self.step_size:
            return x, u, W
        return (x * self._factor(self.step_size), u * self._factor(self.step_size),
                W * self._factor(self.step_size))


class Trace:
    """What a count saw besides its answer: the smallest |1 - xi_k| over every wall
    approach (how near the ball came to grazing the wall, or to reaching it on the last,
    missed approach), and the smallest |U| after a floor bounce (how near it came to
    leaving, or to staying). Section 1b models also record how many impacts slid (beta <
    alpha) and the smallest relative distance |psi - psi*| / psi* of an impact to the
    grip/slide threshold psi* = mu (1 + e)(1 + 1/kappa)/(1 + alpha) (inf: none came near,
    or no surface has one)."""

    def __init__(self):
        self.grazing = math.inf
        self.turning = math.inf
        self.slides = 0
        self.switching = math.inf


class CrossSurface:
    """One surface of SPEC section 1 (the Cross model of a solid ball) in the arithmetic A,
    with section 1's coefficients (1/7)(5 - 2 alpha) ... exactly as written there; with a
    Jitter they are rounded to binary64 or moved (once). The same methods as Surface."""

    def __init__(self, e, alpha, A, jitter=None):
        coefficients = _surface(e, alpha, A)
        if jitter is not None:
            coefficients = jitter.surface(coefficients)
        self.e, self.c_ss, self.c_sW, self.c_Ws, self.c_WW = coefficients

    def wall(self, u, v_w, W, trace):
        """Wall impact (eqs. 2, 6, 7): (u+, v+, W+)."""
        return -self.e * u, self.c_sW * W + self.c_ss * v_w, self.c_Ws * v_w + self.c_WW * W

    def floor(self, u, v_f, W, trace):
        """Floor impact: (u', v', W')."""
        return self.c_ss * u - self.c_sW * W, -self.e * v_f, self.c_WW * W - self.c_Ws * u


class Surface:
    """One surface of SPEC section 1b in the arithmetic A: restitution e, tangential
    restitution alpha of an impact that grips, friction coefficient mu (inf: always grips),
    and the ball's kappa. Holds kappa, d = 1/(1 + kappa), the Coulomb constant
    c = mu (1 + e)(1 + 1/kappa) of the law beta = min(alpha, -1 + c/psi) (None for mu = inf)
    and the impact factors of a gripping impact; with a Jitter these are rounded to binary64
    or moved (once), and so are the factors of every sliding impact (each time)."""

    def __init__(self, e, alpha, mu, kappa, A, jitter=None):
        e, alpha, kappa = A.num(e), A.num(alpha), A.num(kappa)
        one = A.num(1)
        d = one / (1 + kappa)
        c = None if math.isinf(mu) else A.num(mu) * (1 + e) * (1 + one / kappa)
        self.jitter = jitter
        if jitter is not None:
            e, alpha, kappa, d = jitter.surface((e, alpha, kappa, d))
            if c is not None:
                c = jitter.surface((c,))[0]
        self.e, self.alpha, self.kappa, self.d, self.c = e, alpha, kappa, d, c
        self.grip = self.factors(alpha)
        if jitter is not None:
            self.grip = jitter.surface(self.grip)

    def factors(self, beta):
        """((1 - kappa beta), kappa (1 + beta), (1 + beta), (kappa - beta)), each / (1 + kappa):
        SPEC 1b's impact, for the tangential factor beta."""
        k, d = self.kappa, self.d
        return (1 - k * beta) * d, k * (1 + beta) * d, (1 + beta) * d, (k - beta) * d

    def law(self, s, v_n, trace):
        """The factors of an impact with incoming contact velocity s and normal approach
        speed v_n > 0: Walton's beta = min(alpha, -1 + mu (1 + e)(1 + 1/kappa)/psi),
        psi = |s|/v_n (beta = alpha when s = 0 or mu = inf)."""
        if self.c is None or s == 0:
            return self.grip
        psi = abs(s) / v_n
        beta = -1 + self.c / psi
        if trace is not None and self.c > 0 and self.alpha > -1:
            # |psi - psi*| / psi*, psi* = c / (1 + alpha)
            trace.switching = min(trace.switching, abs(float(psi * (1 + self.alpha) / self.c - 1)))
        if not beta < self.alpha:
            return self.grip
        if trace is not None:
            trace.slides += 1
        f = self.factors(beta)
        return f if self.jitter is None else self.jitter.surface(f)

    def wall(self, u, v_w, W, trace):
        """Wall impact (contact velocity s = v - W; kappa W + v conserved): (u+, v+, W+)."""
        f_vv, f_vW, f_Wv, f_WW = self.law(v_w - W, -u, trace)
        v_p = f_vv * v_w + f_vW * W  # ((1 - kappa beta) v_w + kappa (1 + beta) W) / (1 + kappa)
        W_p = f_Wv * v_w + f_WW * W  # ((1 + beta) v_w + (kappa - beta) W) / (1 + kappa)
        return -self.e * u, v_p, W_p

    def floor(self, u, v_f, W, trace):
        """Floor impact (contact velocity s = u + W; kappa W - u conserved): (u', v', W')."""
        f_uu, f_uW, f_Wu, f_WW = self.law(u + W, -v_f, trace)
        u_n = f_uu * u - f_uW * W  # ((1 - kappa beta) u - kappa (1 + beta) W) / (1 + kappa)
        W_n = f_WW * W - f_Wu * u  # ((kappa - beta) W - (1 + beta) u) / (1 + kappa)
        return u_n, -self.e * v_f, W_n


def count_in(xi, U, W, model, max_bounces, A, trace=None, jitter=None, general=False):
    """(N, outcome name) of the canonical launch (xi, U, W), iterating SPEC's physical map
    in the arithmetic A. xi, U, W: numbers that convert exactly (floats or mpf). jitter
    (mpmath only): perturbations of the map (class Jitter), for the robustness test.
    The Cross model (model.cross()) with section 1's coefficients (CrossSurface) unless
    `general`; any other model, or `general`, with the impacts of section 1b (Surface)."""
    for c in (xi, U, W):
        if not math.isfinite(float(c)):
            return 0, "invalid"
    if not (xi > 0 and U < 0):
        return 0, "invalid"
    if general or not model.cross():
        wall = Surface(model.e_wall, model.alpha_wall, model.mu_wall, model.inertia, A, jitter)
        floor = Surface(model.e_floor, model.alpha_floor, model.mu_floor, model.inertia, A, jitter)
    else:
        wall = CrossSurface(model.e_wall, model.alpha_wall, A, jitter)
        floor = CrossSurface(model.e_floor, model.alpha_floor, A, jitter)
    g = A.num(1)
    # The representative with v = 1, g = 1.
    xi, u, W = A.num(xi), A.num(U), A.num(W)
    v = A.num(1)
    x = 2 * xi * (-u) * v / g
    n = 0
    while True:
        # Flight to the wall (seed eqs. 1, 4).
        r = x / u
        y = -r * (v + g * x / (2 * u))
        if trace is not None:
            # xi of the current state, g x / (2 |u| v).
            trace.grazing = min(trace.grazing, abs(1 - float(g * x / (2 * (-u) * v))))
        if y <= 0:
            return n, "missed"
        if n >= max_bounces:
            return n, "capped"
        v_w = v + g * r
        u_p, v_p, W_p = wall.wall(u, v_w, W, trace)
        n += 1
        # Flight back to the floor.
        v_f = -A.sqrt(v_p * v_p + 2 * g * y)
        T = (v_p - v_f) / g
        x = u_p * T
        u, v, W = floor.floor(u_p, v_f, W_p, trace)
        if trace is not None:
            trace.turning = min(trace.turning, abs(float(u / v)))
        if u >= 0:
            return n, "left"
        # Divide out the scale k = v (SPEC section 2): x -> x/k^2, (u, v, W) -> (u, v, W)/k.
        x = x / (v * v)
        u = u / v
        W = W / v
        v = A.num(1)
        if jitter is not None:
            x, u, W = jitter.state(x, u, W)


def count(xi, U, W, model, max_bounces, dps=DPS_LOW, trace=None, jitter=None, general=False):
    """(N, outcome) with mpmath at `dps` decimal digits."""
    with mp.workdps(dps):
        return count_in(xi, U, W, model, max_bounces, Arithmetic(dps), trace, jitter, general)


def count_double(xi, U, W, model, max_bounces, trace=None):
    """(N, outcome) in binary64: only for screening candidates."""
    return count_in(xi, U, W, model, max_bounces, Arithmetic(None), trace)


# ----------------------------------------------------------------------------- the robustness test


def perturbed_launches(xi, U, W, rng):
    """The launch moved by a relative PERTURBATION in each coordinate, both signs, and in two
    random directions (W near 0: absolute PERTURBATION). Exact mpf values, not rounded to
    binary64 (a 1e-12 step is far above binary64 resolution anyway)."""
    base = [mpf(xi), mpf(U), mpf(W)]
    scale = [abs(base[0]), abs(base[1]), max(abs(base[2]), mpf(1))]
    d = mpf(PERTURBATION)
    out = []
    for i in range(3):
        for sign in (1, -1):
            p = list(base)
            p[i] = base[i] + sign * d * scale[i]
            out.append(p)
    for _ in range(2):
        out.append([base[i] + rng.choice((-1, 1)) * d * scale[i] for i in range(3)])
    return out


class Verdict:
    """The outcome of the acceptance test of one candidate row."""

    def __init__(self, result=None, reason=None, grazing=math.inf, turning=math.inf, slides=0, switching=math.inf):
        self.result = result  # (N, outcome) when accepted
        self.reason = reason  # why not, otherwise
        self.grazing = grazing
        self.turning = turning
        self.slides = slides  # impacts that slid (section 1b), in the dps 40 run
        self.switching = switching  # least |psi - psi*|/psi* (section 1b), in the dps 40 run


def verify(xi, U, W, model, max_bounces, rng):
    """Accept (xi, U, W) when its (N, outcome) at dps 40 equals the one at dps 80, that of
    every perturbed launch, that with the impact coefficients rounded to binary64, and that
    of two runs with every coefficient jittered by a relative COEFFICIENT_JITTER and the
    state by a relative STEP_NOISE after every excursion (the others at dps 40). An invalid
    launch: dps 40 and 80 only (invalid is decided by signs, exactly). A model with a finite
    mu (section 1b) is also rejected when an impact of the orbit has psi within a relative
    SWITCHING of its grip/slide threshold psi* (the map's switching surfaces); its jitter
    covers e, alpha, kappa, 1/(1 + kappa), mu (1 + e)(1 + 1/kappa) and the impact factors."""
    trace = Trace()
    with mp.workdps(DPS_LOW):
        low = count(xi, U, W, model, max_bounces, DPS_LOW, trace)
    if low[1] == "invalid":
        high = count(xi, U, W, model, max_bounces, DPS_HIGH)
        return Verdict(low) if high == low else Verdict(reason="precision")
    if low[1] == "missed" and low[0] == max_bounces:
        return Verdict(reason="missed at the cap")
    if trace.switching <= SWITCHING:
        return Verdict(reason="grip/slide threshold", grazing=trace.grazing, turning=trace.turning)
    with mp.workdps(DPS_LOW):
        for p in perturbed_launches(xi, U, W, rng):
            if count(p[0], p[1], p[2], model, max_bounces, DPS_LOW) != low:
                return Verdict(reason="launch perturbation", grazing=trace.grazing, turning=trace.turning)
        if count(xi, U, W, model, max_bounces, DPS_LOW, jitter=Jitter(round_coefficients=True)) != low:
            return Verdict(reason="binary64 coefficients", grazing=trace.grazing, turning=trace.turning)
        for _ in range(2):
            jitter = Jitter(rng, COEFFICIENT_JITTER, STEP_NOISE)
            if count(xi, U, W, model, max_bounces, DPS_LOW, jitter=jitter) != low:
                return Verdict(reason="map perturbation", grazing=trace.grazing, turning=trace.turning)
    high = count(xi, U, W, model, max_bounces, DPS_HIGH)
    if high != low:
        return Verdict(reason="precision", grazing=trace.grazing, turning=trace.turning)
    return Verdict(low, grazing=trace.grazing, turning=trace.turning, slides=trace.slides,
                   switching=trace.switching)


# ----------------------------------------------------------------------------- candidates

GARWIN = Model.uniform(1.0, 1.0)
MODELS = [
    GARWIN,                                   # e = alpha = 1: no dissipation
    Model.uniform(0.9, 0.9),
    Model.uniform(0.95, 0.95),
    Model.uniform(0.7, 0.3),
    Model(0.8, 0.6, 0.85, 0.7),               # two materials
    Model(1.0, -0.5, 0.6, 0.95),              # extremes of the accepted ranges
    Model.uniform(0.99, 0.99),                # weak dissipation: hundreds of bounces near the corner
    Model.uniform(0.998, 0.998),              # weaker: a thousand and more
    Model(0.35, 1.0, 1.0, -1.0),              # a rough wall, a smooth elastic floor
]


def r17(x):
    """x as the binary64 the CSV will hold (what the kernel reads)."""
    return float(x)


class Candidate:
    def __init__(self, family, model, max_bounces, xi, U, W, quota=None):
        self.family = family
        self.quota = quota  # screened families: told of the accepted answer
        self.model = model
        self.max_bounces = int(max_bounces)
        self.xi, self.U, self.W = r17(xi), r17(U), r17(W)


def random_launch(rng, xi_lo=0.0, xi_hi=1.0):
    xi = 0.0
    while not xi > 0.0:
        xi = rng.uniform(xi_lo, xi_hi)
    return xi, -math.exp(rng.uniform(math.log(0.02), math.log(20.0))), rng.uniform(-5.0, 5.0)


def family_random(rng):
    """Uniform launches over the region of interest, every model: mostly short motions."""
    for model in MODELS:
        for _ in range(30):
            yield Candidate("random", model, 1000, *random_launch(rng))


def family_near_wall(rng):
    """Launches close to the wall (xi log-uniform in 1e-5 .. 0.2): long approaches to the
    corner, many bounces."""
    for model in MODELS:
        for _ in range(30):
            xi = math.exp(rng.uniform(math.log(1e-5), math.log(0.2)))
            _, U, W = random_launch(rng)
            yield Candidate("near_wall", model, 1000, xi, U, W)


def family_self_retracing(rng):
    """e = alpha = 1 around the marginally stable self-retracing motion (0.25, -0.5, -1.25):
    capped at several caps, and launches a little further out."""
    caps = [1000, 1000, 1000, 2000, 500, 300, 100, 37]
    for i in range(64):
        radius = 0.02 if i < 40 else 0.08
        xi = 0.25 + rng.uniform(-radius, radius)
        U = -0.5 + rng.uniform(-radius, radius)
        W = -1.25 + rng.uniform(-radius, radius)
        yield Candidate("self_retracing", GARWIN, caps[i % len(caps)], xi, U, W)
    # The orbit itself (exactly periodic in exact arithmetic: capped at any cap).
    yield Candidate("self_retracing", GARWIN, 1000, 0.25, -0.5, -1.25)
    yield Candidate("self_retracing", GARWIN, 2000, 0.25, -0.5, -1.25)


def self_retracing_point(xi):
    """The self-retracing motion of e = alpha = 1 launched at xi: the ball comes back along
    its path when the wall reverses the velocity it arrives with, (U, v_w, W) -> -(U, v_w, W)
    with v_w = 1 - 2 xi; with alpha = 1 that needs W = -(5/2) v_w, and the floor returning
    the reversed ball into the launch needs W = (5/2) U: U = -(1 - 2 xi), W = -(5/2)(1 - 2 xi).
    A line of fixed points of G, marginally stable for xi below about 0.41, saddles above."""
    return -(1.0 - 2.0 * xi), -2.5 * (1.0 - 2.0 * xi)


# Points of period-3 cycles of G for e = alpha = 1 (marginally stable; located with
# `superball fixed-points --period 3`), used only as launch seeds.
GARWIN_PERIOD_3 = [(0.0299741, -0.116786, -0.291966), (0.0512983, -0.157767, -0.394418),
                   (0.119585, -0.297531, -0.743826), (0.168398, -0.406779, -1.01695),
                   (0.198917, -0.479748, -1.19937), (0.216322, -0.523147, -1.30787)]

CAPS = [1000, 1000, 2000, 1500, 999, 750, 500, 250, 100, 42, 10, 1]


def family_garwin_cycles(rng):
    """e = alpha = 1 near the line of self-retracing fixed points (xi from 0.02 to 0.40) and
    near period-3 cycles: capped (quasi-periodic motions), at caps from 1 to 2000."""
    for i in range(36):
        xi0 = rng.uniform(0.02, 0.40)
        U0, W0 = self_retracing_point(xi0)
        r = min(math.exp(rng.uniform(math.log(1e-5), math.log(3e-2))), 0.5 * xi0)
        yield Candidate("garwin_cycles", GARWIN, CAPS[i % len(CAPS)], xi0 + rng.uniform(-r, r),
                        U0 + rng.uniform(-r, r), W0 + rng.uniform(-r, r))
    for i, (xi0, U0, W0) in enumerate(GARWIN_PERIOD_3 * 2):
        r = 10.0 ** rng.uniform(-6, -3)
        yield Candidate("garwin_cycles", GARWIN, CAPS[(i + 3) % len(CAPS)], xi0 * (1 + rng.uniform(-r, r)),
                        U0 * (1 + rng.uniform(-r, r)), W0 * (1 + rng.uniform(-r, r)))


class Quota:
    """Screened candidates are offered while fewer than `per_bin` rows of their (model,
    outcome, N range) have been accepted (the generator verifies each candidate before the
    next is screened)."""

    def __init__(self, per_bin):
        self.per_bin = per_bin
        self.bins = {}

    def open(self, model, n, outcome):
        return self.bins.get((model.key(), outcome, n_range(n)), 0) < self.per_bin

    def accept(self, model, n, outcome):
        key = (model.key(), outcome, n_range(n))
        self.bins[key] = self.bins.get(key, 0) + 1


def family_garwin_saddles(rng, tries, quota):
    """e = alpha = 1 near the saddle part of the self-retracing line (xi 0.41 .. 0.49): the
    ball leaves along the unstable direction after tens to thousands of bounces. Screened in
    binary64 with max_bounces 2000, at most quota.per_bin per outcome and N range."""
    for _ in range(tries):
        xi0 = rng.uniform(0.409, 0.49)
        U0, W0 = self_retracing_point(xi0)
        r = 10.0 ** rng.uniform(-9, -4)
        xi, U, W = xi0 + rng.uniform(-r, r), U0 + rng.uniform(-r, r), W0 + rng.uniform(-r, r)
        n, outcome = count_double(xi, U, W, GARWIN, 2000)
        if n >= 30 and quota.open(GARWIN, n, outcome):
            yield Candidate("garwin_saddles", GARWIN, 2000, xi, U, W, quota)


def corner_fixed_point(model):
    """(U, W) of the fixed point of G on the corner plane xi = 0, or None: there the ball is
    launched at the wall (x = 0), hits it at once (v_w = 1), and comes off it going down
    (v+ < 0), so it lands where it started (x' = 0, v_f = v+). Newton's method (mpmath)."""
    with mp.workdps(30):
        A = Arithmetic(30)
        ew, w_ss, w_sW, w_Ws, w_WW = _surface(model.e_wall, model.alpha_wall, A)
        ef, f_ss, f_sW, f_Ws, f_WW = _surface(model.e_floor, model.alpha_floor, A)

        def residual(U, W):
            u_p, v_p, W_p = -ew * U, w_sW * W + w_ss, w_Ws + w_WW * W
            u, Wn, v = f_ss * u_p - f_sW * W_p, f_WW * W_p - f_Ws * u_p, -ef * v_p
            return [u / v - U, Wn / v - W]

        try:
            U, W = mp.findroot(residual, (mpf(-1), mpf(-2.5)))
        except (ValueError, ZeroDivisionError):
            return None
        if not (U < 0 and w_sW * W + w_ss < 0):
            return None
        return float(U), float(W)


def family_corner(rng, tries, quota):
    """Dissipative models, launches close to the wall near the (unstable) self-similar motion
    into the corner, the fixed point of G on the plane xi = 0: the ball lingers for many
    bounces (hundreds for e = alpha = 0.99) before it leaves or misses. Screened in binary64
    with max_bounces 2000."""
    for model in MODELS:
        if model is GARWIN:
            continue
        fixed = corner_fixed_point(model)
        if fixed is None:
            continue
        U0, W0 = fixed
        for _ in range(tries):
            xi = 10.0 ** rng.uniform(-9, -2)
            U = U0 * (1 + rng.choice((-1, 1)) * 10.0 ** rng.uniform(-9, -2))
            W = W0 * (1 + rng.choice((-1, 1)) * 10.0 ** rng.uniform(-9, -2))
            n, outcome = count_double(xi, U, W, model, 2000)
            if n >= 10 and quota.open(model, n, outcome):
                yield Candidate("corner", model, 2000, xi, U, W, quota)


def long_launch(rng):
    """A launch for the long-motion screens: half the time uniform in xi, half the time
    log-uniform in xi from 1e-4 to 0.5 (near the wall, where motions last)."""
    if rng.random() < 0.5:
        return random_launch(rng)
    xi = math.exp(rng.uniform(math.log(1e-4), math.log(0.5)))
    _, U, W = random_launch(rng)
    return xi, U, W


def family_long(rng, screen_budget, quota):
    """Random launches screened in binary64 for long motions (N >= 50, any outcome) in every
    model, with max_bounces 2000 so that escapes after hundreds of bounces show."""
    for model in MODELS:
        for _ in range(screen_budget):
            xi, U, W = long_launch(rng)
            n, outcome = count_double(xi, U, W, model, 2000)
            if n >= 50 and quota.open(model, n, outcome):
                yield Candidate("long", model, 2000, xi, U, W, quota)


def cap_edges(rng, long_rows):
    """The cap at the edges of long motions already accepted (left or missed after N wall
    impacts): max_bounces = N (the answer stands; for missed, SPEC is silent and the row is
    dropped), N - 1 (capped at N - 1) and a random cap below N (capped)."""
    for row in long_rows:
        n = row["n"]
        model = Model(*row["model"])
        for cap in (n, n - 1, rng.randint(1, n - 1)):
            if cap >= 1:
                yield Candidate("cap_edges", model, cap, row["xi"], row["U"], row["W"])


def family_grazing_launch(rng):
    """Launches that barely reach the wall (xi = 1 - d) or barely miss it (xi = 1 + d),
    d from 1e-2 to 1e-9: resolvable by a 1e-12 perturbation."""
    for model in MODELS:
        for k in range(8):
            d = 10.0 ** -(2 + k)
            _, U, W = random_launch(rng)
            yield Candidate("grazing_launch", model, 1000, 1.0 - d * rng.uniform(1.0, 3.0), U, W)
        for k in range(2):
            _, U, W = random_launch(rng)
            yield Candidate("grazing_launch", model, 1000, 1.0 + 10.0 ** -(3 + 3 * k), U, W)
    # xi = 1 exactly: y = 0, missed with no wall impact.
    yield Candidate("grazing_launch", MODELS[1], 1000, 1.0, -1.0, 0.5)


def family_boundaries(rng, per_model):
    """Launches next to a boundary between two answers (a later approach that only just
    reaches the wall or only just misses it, a bounce that only just leaves): a segment in
    xi whose ends give different answers (binary64), bisected to 1e-13 relative, then stepped
    off by a relative 1e-9 .. 1e-7 to each side. The mp test decides which survive."""
    for model in MODELS:
        made = 0
        tries = 0
        while made < per_model and tries < 40 * per_model:
            tries += 1
            xi, U, W = random_launch(rng, 0.02, 0.98)
            step = 10.0 ** rng.uniform(-3, -1.3)
            a, b = xi, min(xi + step, 0.999)
            ra = count_double(a, U, W, model, 1000)
            rb = count_double(b, U, W, model, 1000)
            if ra == rb or "capped" in (ra[1], rb[1]):
                continue
            for _ in range(80):
                m = 0.5 * (a + b)
                if count_double(m, U, W, model, 1000) == ra:
                    a = m
                else:
                    b = m
                if b - a <= 1e-13 * b:
                    break
            off = 10.0 ** rng.uniform(-9, -7)
            yield Candidate("boundary", model, 1000, a * (1.0 - off), U, W)
            yield Candidate("boundary", model, 1000, b * (1.0 + off), U, W)
            made += 1


def family_invalid(rng):
    """Not launches toward the wall: xi <= 0 or U >= 0 (finite: the CLI and the Python module
    refuse NaN and infinities as bad input before counting)."""
    starts = [(0.0, -1.0, 0.0), (-0.25, -0.5, -1.25), (-1e-300, -1.0, 2.0), (0.5, 0.0, 0.0), (0.5, 1.0, -1.0),
              (0.25, 0.5, -1.25), (2.0, 3.0, 1.0), (0.0, 0.0, 0.0), (-3.0, 2.0, 5.0), (0.1, 1e-300, 0.0)]
    for i, s in enumerate(starts):
        yield Candidate("invalid", MODELS[i % len(MODELS)], 1000, *s)


def candidates(rng, screen_budget):
    """Every candidate but the cap edges (which follow from accepted rows)."""
    yield from family_invalid(rng)
    yield from family_random(rng)
    yield from family_near_wall(rng)
    yield from family_self_retracing(rng)
    yield from family_garwin_cycles(rng)
    yield from family_grazing_launch(rng)
    yield from family_boundaries(rng, 6)
    yield from family_garwin_saddles(rng, 5 * screen_budget, Quota(8))
    yield from family_corner(rng, screen_budget, Quota(8))
    yield from family_long(rng, screen_budget, Quota(4))


# ----------------------------------------------------------------------------- candidates: section 1b

TWO_THIRDS = 2.0 / 3.0  # the binary64 0.6666666666666666: a thin spherical shell
F = Model.friction
FU = Model.friction_uniform
FRICTION_MODELS = [
    FU(0.9, 0.9, 0.5, 0.4),
    FU(0.9, 0.9, 0.2, 0.4),
    FU(0.9, 0.9, 1.0, 0.5),
    FU(0.95, 0.99, 0.5, 0.4),
    FU(0.95, 0.99, 1.5, TWO_THIRDS),         # long motions (hundreds of bounces), some sliding
    FU(0.95, 0.99, 3.0, 0.25),               # ... and capped ones (an attracting corner)
    FU(0.8, 0.6, 0.2, 0.25),
    FU(0.8, 0.6, 1.0, 0.4),
    FU(0.99, 0.99, 1.5, 0.4),                # weak dissipation: long motions near the corner
    FU(0.998, 0.998, 1.5, 0.4),
    FU(1.0, 1.0, 0.5, 0.4),                  # dissipation by sliding only
    FU(1.0, 1.0, 1.5, TWO_THIRDS),           # grips on the self-retracing line (psi = 1 + 1/kappa)
    FU(1.0, 1.0, 3.0, 0.25),
    F(0.9, 0.9, 0.2, 0.95, 0.99, 1.5, 0.5),  # two materials, or two frictions
    F(0.95, 0.99, 1.0, 0.8, 0.6, 0.5, 0.4),
    F(0.9, 0.9, 3.0, 0.9, 0.9, 0.2, TWO_THIRDS),
    F(0.95, 0.99, 1.5, 0.95, 0.99, 3.0, 0.5),
    F(0.9, 0.9, math.inf, 0.9, 0.9, 0.5, 0.4),   # one surface without a Coulomb limit
    F(0.95, 0.99, 0.5, 0.95, 0.99, math.inf, TWO_THIRDS),
    F(1.0, 1.0, math.inf, 1.0, 1.0, 1.5, 0.4),
    FU(0.9, 0.9, 0.0, 0.4),                  # smooth surfaces: beta = -1
    F(1.0, 1.0, 0.0, 1.0, 1.0, 1.5, 0.25),
    FU(0.9, 0.9, math.inf, TWO_THIRDS),      # the Cross model for other balls
    FU(1.0, 1.0, math.inf, 0.25),
    FU(0.95, 0.99, math.inf, 0.5),
]


def general_self_retracing_point(xi, kappa):
    """The self-retracing motion for e = alpha = 1 and a gripping impact (as
    self_retracing_point, for any kappa): U = -(1 - 2 xi), W = -(1 - 2 xi)/kappa. Its wall
    impact has psi = 1 + 1/kappa: it grips when mu >= 1."""
    return -(1.0 - 2.0 * xi), -(1.0 - 2.0 * xi) / kappa


def general_corner_fixed_points(model):
    """[(U, W)] of the fixed points of G on the corner plane xi = 0 (corner_fixed_point, with
    the impacts of section 1b), found by Newton's method from a few starts (the map is
    piecewise smooth: a start converges when the fixed point is off a switching surface)."""
    found = []
    with mp.workdps(30):
        A = Arithmetic(30)
        wall = Surface(model.e_wall, model.alpha_wall, model.mu_wall, model.inertia, A)
        floor = Surface(model.e_floor, model.alpha_floor, model.mu_floor, model.inertia, A)

        def residual(U, W):
            u_p, v_p, W_p = wall.wall(U, mpf(1), W, None)
            u, v, Wn = floor.floor(u_p, v_p, W_p, None)
            return [u / v - U, Wn / v - W]

        for start in ((-1, -2.5), (-0.5, -1), (-2, -5), (-1, 1), (-0.3, -3), (-3, -1)):
            try:
                U, W = mp.findroot(residual, (mpf(start[0]), mpf(start[1])))
            except (ValueError, ZeroDivisionError, TypeError):  # no convergence, a singular Jacobian
                continue
            if not (U < 0 and wall.wall(U, mpf(1), W, None)[1] < 0):
                continue
            if max(abs(r) for r in residual(U, W)) > mpf(10) ** -20:
                continue
            p = (float(U), float(W))
            if all(abs(p[0] - q[0]) + abs(p[1] - q[1]) > 1e-9 for q in found):
                found.append(p)
    return found


FRICTION_CAPS = [1000, 200, 1000, 500, 200, 100, 1000, 50]


def friction_family_invalid(rng):
    starts = [(0.0, -1.0, 0.0), (0.5, 0.0, 1.0), (-0.25, -0.5, -1.25), (0.3, 2.0, -4.0)]
    for i, s in enumerate(starts):
        yield Candidate("invalid", FRICTION_MODELS[3 * i], 1000, *s)


def friction_family_random(rng, per_model):
    """Uniform launches over the region of interest (max_bounces 1000 or 200)."""
    for model in FRICTION_MODELS:
        for i in range(per_model):
            yield Candidate("random", model, (1000, 200)[i % 2], *random_launch(rng))


def friction_family_near_wall(rng, per_model):
    """Launches close to the wall (xi log-uniform in 1e-5 .. 0.2)."""
    for model in FRICTION_MODELS:
        for i in range(per_model):
            xi = math.exp(rng.uniform(math.log(1e-5), math.log(0.2)))
            _, U, W = random_launch(rng)
            yield Candidate("near_wall", model, (1000, 200)[i % 2], xi, U, W)


def friction_family_grazing_launch(rng, per_model):
    """Launches that barely reach the wall, xi = 1 - d, d from 1e-3 to 1e-8, and (every fifth
    model) one that barely misses it, xi = 1 + d (missed, N = 0)."""
    for i, model in enumerate(FRICTION_MODELS):
        for _ in range(per_model):
            _, U, W = random_launch(rng)
            yield Candidate("grazing_launch", model, 1000, 1.0 - 10.0 ** rng.uniform(-8, -3), U, W)
        if i % 5 == 0:
            _, U, W = random_launch(rng)
            yield Candidate("grazing_launch", model, 1000, 1.0 + 10.0 ** rng.uniform(-8, -3), U, W)


def friction_family_garwin(rng, per_model):
    """e = alpha = 1 on both surfaces: launches near the self-retracing line, at caps from
    50 to 1000 (quasi-periodic motions while every impact grips; sliding dissipates)."""
    for model in FRICTION_MODELS:
        if model.fields() != [1.0, 1.0, 1.0, 1.0]:
            continue
        for i in range(per_model):
            xi0 = rng.uniform(0.02, 0.45)
            U0, W0 = general_self_retracing_point(xi0, model.inertia)
            r = min(10.0 ** rng.uniform(-5, -1.5), 0.5 * xi0)
            yield Candidate("garwin", model, FRICTION_CAPS[i % len(FRICTION_CAPS)], xi0 + rng.uniform(-r, r),
                            U0 + rng.uniform(-r, r), W0 + rng.uniform(-r, r))


class SlideQuota(Quota):
    """Quota per (model, outcome, N range, whether an impact slid): the binary64 screen's
    slides (`screened`) until the row is verified, then the mp count's."""

    def open(self, model, n, outcome, slid=False):
        return self.bins.get((model.key(), outcome, n_range(n), slid), 0) < self.per_bin

    def accept(self, model, n, outcome, slid=False):
        key = (model.key(), outcome, n_range(n), slid)
        self.bins[key] = self.bins.get(key, 0) + 1


def screen(xi, U, W, model, max_bounces):
    """(N, outcome, slid) in binary64, for screening."""
    trace = Trace()
    n, outcome = count_double(xi, U, W, model, max_bounces, trace)
    return n, outcome, trace.slides > 0


def friction_family_corner(rng, tries, quota):
    """Launches close to the wall near the fixed points of G on the corner plane xi = 0:
    long motions into the corner. Screened in binary64 with max_bounces 1000."""
    for model in FRICTION_MODELS:
        for U0, W0 in general_corner_fixed_points(model):
            for _ in range(tries):
                xi = 10.0 ** rng.uniform(-9, -2)
                U = U0 * (1 + rng.choice((-1, 1)) * 10.0 ** rng.uniform(-9, -2))
                W = W0 * (1 + rng.choice((-1, 1)) * 10.0 ** rng.uniform(-9, -2))
                n, outcome, slid = screen(xi, U, W, model, 1000)
                if n >= 10 and quota.open(model, n, outcome, slid):
                    yield Candidate("corner", model, 1000, xi, U, W, quota)


def friction_family_long(rng, screen_budget, quota):
    """Random launches screened in binary64 for long motions (N >= 30, any outcome), with
    max_bounces 1000."""
    for model in FRICTION_MODELS:
        for _ in range(screen_budget):
            xi, U, W = long_launch(rng)
            n, outcome, slid = screen(xi, U, W, model, 1000)
            if n >= 30 and quota.open(model, n, outcome, slid):
                yield Candidate("long", model, 1000, xi, U, W, quota)


def friction_cap_edges(rng, long_rows):
    """The cap below long motions already accepted: N - 1, a random cap below N, and 200
    when N > 200 (all capped)."""
    for row in long_rows:
        n, model = row["n"], row["model_obj"]
        caps = [n - 1, rng.randint(1, n - 1)] + ([200] if n > 200 else [])
        for cap in caps:
            if cap >= 1:
                yield Candidate("cap_edges", model, cap, row["xi"], row["U"], row["W"])


def friction_candidates(rng, screen_budget):
    yield from friction_family_invalid(rng)
    yield from friction_family_random(rng, 8)
    yield from friction_family_near_wall(rng, 5)
    yield from friction_family_grazing_launch(rng, 1)
    yield from friction_family_garwin(rng, 8)
    yield from friction_family_corner(rng, screen_budget, SlideQuota(2))
    yield from friction_family_long(rng, screen_budget, SlideQuota(2))


# ----------------------------------------------------------------------------- output


def fmt(x):
    """Shortest round-trip decimal of a binary64 (what strtod and float() read back)."""
    return repr(float(x))


def n_range(n):
    for hi, name in ((0, "0"), (9, "1-9"), (99, "10-99"), (499, "100-499"), (999, "500-999")):
        if n <= hi:
            return name
    return ">=1000"


def coverage_table(rows, label="model (e_w,a_w,e_f,a_f)"):
    """Text table: rows per model x outcome x N range."""
    ranges = ["0", "1-9", "10-99", "100-499", "500-999", ">=1000"]
    width = max([30, len(label)] + [len(",".join("%g" % c for c in r["model"])) for r in rows])
    lines = []
    for outcome in OUTCOMES:
        sel = [r for r in rows if r["outcome"] == outcome]
        if not sel:
            continue
        lines.append("%s (%d rows)" % (outcome, len(sel)))
        lines.append("  %-*s" % (width, label) + "".join("%9s" % h for h in ranges))
        for model in sorted({r["model"] for r in sel}):
            counts = [sum(1 for r in sel if r["model"] == model and n_range(r["n"]) == h) for h in ranges]
            lines.append("  %-*s" % (width, ",".join("%g" % c for c in model)) + "".join("%9d" % c for c in counts))
    return "\n".join(lines)


class Collector:
    """The candidates verified (verify) and the rows kept, counted per family, for both
    generators; `friction`: section 1b's rows also record the impacts that slid."""

    def __init__(self, check_rng, verbose, friction=False):
        self.check_rng, self.verbose, self.friction = check_rng, verbose, friction
        self.kept, self.dropped, self.families = [], {}, {}

    def consider(self, cand):
        v = verify(cand.xi, cand.U, cand.W, cand.model, cand.max_bounces, self.check_rng)
        fam = self.families.setdefault(cand.family, [0, 0])
        fam[0] += 1
        if v.result is None:
            self.dropped[(cand.family, v.reason)] = self.dropped.get((cand.family, v.reason), 0) + 1
            return
        n, outcome = v.result
        fam[1] += 1
        if cand.quota is not None:
            cand.quota.accept(cand.model, n, outcome, *((v.slides > 0,) if self.friction else ()))
        row = {"model": cand.model.key(), "max_bounces": cand.max_bounces, "xi": cand.xi, "U": cand.U, "W": cand.W,
               "n": n, "outcome": outcome, "family": cand.family, "grazing": v.grazing, "turning": v.turning}
        if self.friction:
            row.update(model_obj=cand.model, slides=v.slides, switching=v.switching)
        self.kept.append(row)
        if self.verbose and self.friction:
            print("%-15s %-40s %-45s max %4d -> %4d %-7s slides %d" % (
                cand.family, cand.model.key(), (cand.xi, cand.U, cand.W), cand.max_bounces, n, outcome, v.slides),
                file=sys.stderr)
        elif self.verbose:
            print("%-15s %-40s max %4d -> %4d %s" % (cand.family, (cand.xi, cand.U, cand.W), cand.max_bounces, n,
                                                    outcome), file=sys.stderr)

    def report(self, out_path, seconds, label):
        """What both generators print once the file is written."""
        kept = self.kept
        print("wrote %d rows to %s in %.1f s" % (len(kept), out_path, seconds))
        print("candidates per family (kept/tried): " +
              ", ".join("%s %d/%d" % (k, v[1], v[0]) for k, v in self.families.items()))
        print("dropped: " + (", ".join("%s: %d (%s)" % (k[0], c, k[1]) for k, c in sorted(self.dropped.items()))
                             or "none"))
        print(coverage_table(kept, label))


def generate(out_path, seed, screen_budget, verbose):
    start = time.time()
    rng = random.Random(seed)
    collector = Collector(random.Random(seed + 1), verbose)
    kept = collector.kept
    for cand in candidates(rng, screen_budget):
        collector.consider(cand)
    # The cap at the edges of some of the long motions found (a sample of 30).
    long_rows = [r for r in kept if r["outcome"] in ("left", "missed") and r["n"] >= 10]
    for cand in cap_edges(rng, rng.sample(long_rows, min(30, len(long_rows)))):
        collector.consider(cand)
    seconds = time.time() - start
    with open(out_path, "w", newline="") as f:
        f.write("# Generated by tests/reference/mp_reference.py --seed %d (mpmath %s): %d rows, each the same at "
                "dps %d and %d, for launches perturbed by %g, coefficients rounded to binary64 or moved by %g, "
                "states moved by %g per excursion (relative)\n" % (seed, mp_version(), len(kept), DPS_LOW, DPS_HIGH,
                                                                   PERTURBATION, COEFFICIENT_JITTER, STEP_NOISE))
        w = csv.writer(f, lineterminator="\n")
        w.writerow(HEADER)
        for r in kept:
            w.writerow([fmt(c) for c in r["model"]] + [r["max_bounces"], fmt(r["xi"]), fmt(r["U"]), fmt(r["W"]),
                                                       r["n"], r["outcome"]])
    collector.report(out_path, seconds, "model (e_w,a_w,e_f,a_f)")
    near = [r for r in kept if r["grazing"] < 1e-3]
    print("near-grazing rows (some approach with |1 - xi_k| < 1e-3): %d, of which < 1e-6: %d" %
          (len(near), sum(1 for r in near if r["grazing"] < 1e-6)))
    print("near-turning rows (some |U_k| < 1e-3 after a floor bounce): %d" %
          sum(1 for r in kept if r["turning"] < 1e-3))
    return kept


FRICTION_HEADER = ["e_wall", "alpha_wall", "mu_wall", "e_floor", "alpha_floor", "mu_floor", "inertia", "max_bounces",
                   "xi", "U", "W", "wall_bounces", "outcome", "slides"]


def generate_friction(out_path, seed, screen_budget, verbose):
    """The section 1b reference (mp_friction_counts.csv): as generate, for FRICTION_MODELS,
    with the number of impacts that slid in the last column."""
    start = time.time()
    rng = random.Random(seed)
    collector = Collector(random.Random(seed + 1), verbose, friction=True)
    kept = collector.kept
    for cand in friction_candidates(rng, screen_budget):
        collector.consider(cand)
    # The cap below some of the long motions found: 30 that slid, 10 that did not.
    long_rows = [r for r in kept if r["outcome"] in ("left", "missed") and r["n"] >= 10]
    slid = [r for r in long_rows if r["slides"] > 0]
    gripped = [r for r in long_rows if r["slides"] == 0]
    sample = rng.sample(slid, min(30, len(slid))) + rng.sample(gripped, min(10, len(gripped)))
    for cand in friction_cap_edges(rng, sample):
        collector.consider(cand)
    seconds = time.time() - start
    with open(out_path, "w", newline="") as f:
        f.write("# Generated by tests/reference/mp_reference.py --friction --seed %d (mpmath %s): %d rows (SPEC 1b: "
                "Walton friction mu per surface, inertia kappa), each the same at dps %d and %d, for launches "
                "perturbed by %g, coefficients (e, alpha, mu, kappa and derived factors) rounded to binary64 or moved "
                "by %g, states moved by %g per excursion (relative), no impact within a relative %g of its grip/slide "
                "threshold; slides = impacts with beta < alpha\n" % (
                    seed, mp_version(), len(kept), DPS_LOW, DPS_HIGH, PERTURBATION, COEFFICIENT_JITTER, STEP_NOISE,
                    SWITCHING))
        w = csv.writer(f, lineterminator="\n")
        w.writerow(FRICTION_HEADER)
        for r in kept:
            w.writerow([fmt(c) for c in r["model_obj"].friction_fields()] +
                       [r["max_bounces"], fmt(r["xi"]), fmt(r["U"]), fmt(r["W"]), r["n"], r["outcome"], r["slides"]])
    collector.report(out_path, seconds, "model (e,a,mu wall; floor; kappa)")
    print("rows per outcome: " + ", ".join("%s %d" % (o, sum(1 for r in kept if r["outcome"] == o))
                                           for o in OUTCOMES))
    print("rows with slides > 0: %d (left %d, missed %d, capped %d; N >= 100: %d)" % (
        sum(1 for r in kept if r["slides"] > 0),
        *[sum(1 for r in kept if r["slides"] > 0 and r["outcome"] == o) for o in ("left", "missed", "capped")],
        sum(1 for r in kept if r["slides"] > 0 and r["n"] >= 100)))
    print("least relative distance |psi - psi*|/psi* of an impact to its grip/slide threshold: %.3g; rows "
          "with one below 1e-6: %d" % (min(r["switching"] for r in kept),
                                       sum(1 for r in kept if r["switching"] < 1e-6)))
    disagree = [r for r in kept if count_double(r["xi"], r["U"], r["W"], r["model_obj"], r["max_bounces"]) !=
                (r["n"], r["outcome"])]
    print("rows where this module's binary64 count disagrees: %d" % len(disagree))
    return kept


def mp_version():
    import mpmath

    return mpmath.__version__


# ----------------------------------------------------------------------------- cross-check


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if line.strip() and not line.startswith("#")))


def check_canonical(path, max_bounces=1000):
    """Recompute every row of canonical_counts.csv (no max_bounces column: 1000, the
    command line's default). Returns the rows that disagree."""
    bad = []
    rows = read_rows(path)
    for row in rows:
        model = Model(row["e_wall"], row["alpha_wall"], row["e_floor"], row["alpha_floor"])
        got = count(float(row["xi"]), float(row["U"]), float(row["W"]), model, max_bounces)
        want = (int(row["wall_bounces"]), row["outcome"])
        if got != want:
            bad.append((row, got))
    return rows, bad


def check_cross(path):
    """Recompute every row of mp_counts.csv (the Cross model) with the impacts of section 1b
    (mu = inf, kappa = 0.4): they must be section 1's. Returns the rows that disagree."""
    bad = []
    rows = read_rows(path)
    for row in rows:
        model = Model(row["e_wall"], row["alpha_wall"], row["e_floor"], row["alpha_floor"])
        got = count(float(row["xi"]), float(row["U"]), float(row["W"]), model, int(row["max_bounces"]),
                    general=True)
        if got != (int(row["wall_bounces"]), row["outcome"]):
            bad.append((row, got))
    return rows, bad


def check_friction(path):
    """Recompute every row of mp_friction_counts.csv at dps 40 (N, outcome and slides)."""
    bad = []
    rows = read_rows(path)
    for row in rows:
        model = Model.friction(*(float(row[k]) for k in FRICTION_HEADER[:7]))
        trace = Trace()
        got = count(float(row["xi"]), float(row["U"]), float(row["W"]), model, int(row["max_bounces"]),
                    trace=trace)
        if got + (trace.slides,) != (int(row["wall_bounces"]), row["outcome"], int(row["slides"])):
            bad.append((row, got + (trace.slides,)))
    return rows, bad


def self_test(trials=2000, seed=1):
    """The invariants of SPEC 1b on random impacts, at dps 50 (returns a list of failures):
    kappa W + v (wall) and kappa W - u (floor) conserved; the contact velocity s -> -beta s;
    kinetic energy u^2 + v^2 + kappa W^2 never grows (e, |alpha| <= 1); a sliding impact's
    tangential impulse is mu times the normal one; beta = alpha with mu = inf, and then,
    with kappa = 2/5, section 1's coefficients (5 - 2 alpha)/7, 2 (1 + alpha)/7, ..."""
    rng = random.Random(seed)
    fails = []
    with mp.workdps(50):
        A = Arithmetic(50)
        tol = mpf(10) ** -40

        def check(ok, what):
            if not ok:
                fails.append(what)

        for _ in range(trials):
            e = rng.choice((1.0, rng.uniform(0.05, 1.0)))
            alpha = rng.choice((1.0, -1.0, rng.uniform(-1.0, 1.0)))
            mu = rng.choice((0.0, math.inf, math.exp(rng.uniform(math.log(0.05), math.log(5.0)))))
            kappa = rng.choice((0.4, TWO_THIRDS, rng.uniform(0.01, TWO_THIRDS)))
            S = Surface(e, alpha, mu, kappa, A)
            k = mpf(kappa)
            u, v, W = -mpf(rng.uniform(0.01, 5.0)), mpf(rng.uniform(-5.0, 5.0)), mpf(rng.uniform(-10.0, 10.0))
            what = (e, alpha, mu, kappa, float(u), float(v), float(W))
            trace = Trace()
            u_p, v_p, W_p = S.wall(u, v, W, trace)  # wall: normal u, tangential v
            check(abs((k * W_p + v_p) - (k * W + v)) < tol, ("wall angular momentum", what))
            check(abs(u_p + mpf(e) * u) < tol, ("wall normal", what))
            energy = u * u + v * v + k * W * W
            check(u_p * u_p + v_p * v_p + k * W_p * W_p <= energy * (1 + tol), ("wall energy", what))
            s, s_p = v - W, v_p - W_p
            if trace.slides:
                check(abs(abs(v_p - v) - mpf(mu) * (1 + mpf(e)) * (-u)) < tol, ("wall Coulomb", what))
                beta = -s_p / s  # s -> -beta s, -1 <= beta < alpha
                check(-1 - tol <= beta < alpha, ("wall slide beta", what))
            else:
                check(abs(s_p + mpf(alpha) * s) < tol * (1 + abs(s)), ("wall grip", what))
            if math.isinf(mu):
                check(not trace.slides, ("mu = inf slid", what))
            # floor: normal v_f < 0, tangential u
            v_f = -abs(v) - mpf(0.01)
            trace = Trace()
            u_n, v_n, W_n = S.floor(u, v_f, W, trace)
            check(abs((k * W_n - u_n) - (k * W - u)) < tol, ("floor angular momentum", what))
            check(abs(v_n + mpf(e) * v_f) < tol, ("floor normal", what))
            energy = u * u + v_f * v_f + k * W * W
            check(u_n * u_n + v_n * v_n + k * W_n * W_n <= energy * (1 + tol), ("floor energy", what))
            s, s_p = u + W, u_n + W_n
            if trace.slides:
                check(abs(abs(u_n - u) - mpf(mu) * (1 + mpf(e)) * (-v_f)) < tol, ("floor Coulomb", what))
                beta = -s_p / s
                check(-1 - tol <= beta < alpha, ("floor slide beta", what))
            else:
                check(abs(s_p + mpf(alpha) * s) < tol * (1 + abs(s)), ("floor grip", what))
            if math.isinf(mu) and kappa == 0.4:
                # section 1's coefficients, with kappa the binary64 0.4 (not exactly 2/5)
                _, c_ss, c_sW, c_Ws, c_WW = _surface(e, alpha, A)
                tol1 = mpf(1e-15)
                check(abs(v_p - (c_sW * W + c_ss * v)) < tol1 * 20 and
                      abs(W_p - (c_Ws * v + c_WW * W)) < tol1 * 20, ("section 1 wall", what))
                check(abs(u_n - (c_ss * u - c_sW * W)) < tol1 * 20 and
                      abs(W_n - (c_WW * W - c_Ws * u)) < tol1 * 20, ("section 1 floor", what))
    return fails


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", help="write the reference CSV here")
    p.add_argument("--friction", action="store_true",
                   help="with --out: the section 1b reference (mp_friction_counts.csv) instead of mp_counts.csv")
    p.add_argument("--seed", type=int, default=24)
    p.add_argument("--screen-budget", type=int, default=None,
                   help="binary64 launches screened per model for long motions (default 1500; --friction: 600)")
    p.add_argument("--check-canonical", nargs="?", const=os.path.join(HERE, "canonical_counts.csv"),
                   metavar="CSV", help="recompute canonical_counts.csv (default: the one next to this file)")
    p.add_argument("--check-cross", nargs="?", const=os.path.join(HERE, "mp_counts.csv"), metavar="CSV",
                   help="recompute mp_counts.csv with the impacts of SPEC 1b (mu = inf, kappa = 0.4)")
    p.add_argument("--check-friction", nargs="?", const=os.path.join(HERE, "mp_friction_counts.csv"),
                   metavar="CSV", help="recompute mp_friction_counts.csv at dps 40 (N, outcome, slides)")
    p.add_argument("--self-test", action="store_true", help="check the invariants of SPEC 1b's impacts")
    p.add_argument("--count", nargs=8, metavar=("E_W", "A_W", "E_F", "A_F", "MAX", "XI", "U", "W"),
                   help="count one launch at dps 40 and 80")
    p.add_argument("--count-friction", nargs=11,
                   metavar=("E_W", "A_W", "MU_W", "E_F", "A_F", "MU_F", "INERTIA", "MAX", "XI", "U", "W"),
                   help="count one launch of a section 1b model at dps 40 and 80 (N, outcome, slides)")
    p.add_argument("-v", "--verbose", action="store_true")
    a = p.parse_args(argv)
    status = 0
    if a.self_test:
        fails = self_test()
        for what in fails[:20]:
            print("FAIL %s" % (what,))
        print("self-test of SPEC 1b's impacts: %d failures" % len(fails))
        if fails:
            status = 1
    if a.check_canonical:
        rows, bad = check_canonical(a.check_canonical)
        for row, got in bad:
            print("MISMATCH %s: mp gives %s" % (dict(row), got))
        print("canonical_counts.csv: %d rows, %d disagree" % (len(rows), len(bad)))
        if bad:
            return 1
    for path, check, what, label in ((a.check_cross, check_cross, "section 1b", " with SPEC 1b's impacts"),
                                     (a.check_friction, check_friction, "mp", "")):
        if path:
            rows, bad = check(path)
            for row, got in bad:
                print("MISMATCH %s: %s gives %s" % (dict(row), what, got))
            print("%s%s: %d rows, %d disagree" % (path, label, len(rows), len(bad)))
            if bad:
                status = 1
    if a.count:
        model = Model(*a.count[:4])
        args = (float(a.count[5]), float(a.count[6]), float(a.count[7]), model, int(a.count[4]))
        print("dps %d: %s; dps %d: %s" % (DPS_LOW, count(*args, DPS_LOW), DPS_HIGH, count(*args, DPS_HIGH)))
    if a.count_friction:
        c = a.count_friction
        model = Model.friction(*(float(x) for x in c[:7]))
        args = (float(c[8]), float(c[9]), float(c[10]), model, int(c[7]))
        for dps in (DPS_LOW, DPS_HIGH):
            trace = Trace()
            print("dps %d: %s, slides %d" % (dps, count(*args, dps, trace), trace.slides))
    if a.out:
        if a.friction:
            generate_friction(a.out, a.seed, 600 if a.screen_budget is None else a.screen_budget, a.verbose)
        else:
            generate(a.out, a.seed, 1500 if a.screen_budget is None else a.screen_budget, a.verbose)
    if not (a.out or a.count or a.count_friction or a.check_canonical or a.check_cross or a.check_friction or
            a.self_test):
        p.print_usage()
        return 2
    return status


if __name__ == "__main__":
    sys.exit(main())
