#!/usr/bin/env python3
"""The counting kernel against tests/reference/mp_counts.csv: launches whose wall-bounce
count N and outcome were computed by a second implementation of SPEC's model, in mpmath
at 40 and 80 digits and confirmed under relative 1e-12 perturbations of the launch
(tests/reference/mp_reference.py, issue 24). Every row must match exactly.

The kernel is reached through the Python module (src/python; the build tree's python/
directory next to the binary, or PYTHONPATH), one call per model and max_bounces, when it
imports; otherwise through `superball count --json`, one call per row. The command line is
checked on a sample of rows in any case (SUPERBALL_MP_REFERENCE_CLI=1: on every row).

Also checks that mp_reference.py reproduces canonical_counts.csv, the reference computed by
another independent implementation, and a few rows of mp_counts.csv itself.

Run by ctest as `$SUPERBALL_PYTHON tests/core/test_mp_reference.py -v` with
  SUPERBALL                the built binary
  SUPERBALL_BUILD_DIR      its build tree (for the Python module; optional)
  SUPERBALL_REFERENCE_DIR  tests/reference (defaults to ../reference next to this file)
"""

import csv
import importlib
import importlib.util
import json
import os
import re
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SUPERBALL = os.environ.get("SUPERBALL", "")
REFERENCE_DIR = os.environ.get("SUPERBALL_REFERENCE_DIR", os.path.join(HERE, os.pardir, "reference"))
MP_COUNTS = os.path.join(REFERENCE_DIR, "mp_counts.csv")
CANONICAL_COUNTS = os.path.join(REFERENCE_DIR, "canonical_counts.csv")
HEADER = ["e_wall", "alpha_wall", "e_floor", "alpha_floor", "max_bounces", "xi", "U", "W", "wall_bounces", "outcome"]
OUTCOMES = ("invalid", "left", "missed", "capped")
MIN_ROWS = 500
CLI_SAMPLE_EVERY = 7  # with the module: every 7th row, and every invalid row, also through the CLI


def setUpModule():
    if not SUPERBALL or not os.access(SUPERBALL, os.X_OK):
        raise RuntimeError("set SUPERBALL to the built superball binary (got %r)" % SUPERBALL)


def read_rows(path, expected=HEADER):
    """(line number, dict) of every data row; '#' lines are comments."""
    with open(path, newline="") as f:
        numbered = [(i + 1, line) for i, line in enumerate(f) if line.strip() and not line.startswith("#")]
    header = next(csv.reader([numbered[0][1]]))
    if header != expected:
        raise AssertionError("%s: header %r, expected %r" % (path, header, expected))
    return [(n, dict(zip(header, fields))) for (n, _), fields in
            zip(numbered[1:], csv.reader(line for _, line in numbered[1:]))]


def describe(number, row):
    return "mp_counts.csv line %d: %s" % (number, ",".join(row[k] for k in HEADER))


def load_module():
    """(the superball Python module of the build under test, or None; why not)."""
    if os.environ.get("SUPERBALL_MP_REFERENCE_CLI") == "1":
        return None, "SUPERBALL_MP_REFERENCE_CLI=1"
    candidates = []
    if os.environ.get("SUPERBALL_BUILD_DIR"):
        candidates.append(os.path.join(os.environ["SUPERBALL_BUILD_DIR"], "python"))
    candidates.append(os.path.join(os.path.dirname(os.path.abspath(SUPERBALL)), os.pardir, "python"))
    parents = [os.path.abspath(p) for p in candidates if os.path.isfile(os.path.join(p, "superball", "__init__.py"))]
    if not parents:
        return None, "no python/superball in the build tree"
    # Imported in a child first: a sanitized build's module aborts an interpreter that has
    # not preloaded the sanitizer's runtime, and numpy may be missing.
    env = dict(os.environ, PYTHONPATH=parents[0], PYTHONDONTWRITEBYTECODE="1")
    probe = subprocess.run([sys.executable, "-c", "import numpy, superball"], env=env, capture_output=True, text=True,
                           timeout=120)
    if probe.returncode != 0:
        return None, "it does not import here (status %d)" % probe.returncode
    sys.path.insert(0, parents[0])
    return importlib.import_module("superball"), None


def cli_count(row):
    """(N, outcome) from `superball count --json`; a launch the command line refuses as not a
    launch toward the wall (status 2, naming --xi or --U) is ("refused", message)."""
    r = subprocess.run(cli_args(row), capture_output=True, text=True, timeout=60)
    if r.returncode == 2:
        return "refused", r.stderr.strip()
    if r.returncode != 0:
        raise AssertionError("superball count exited %d: %s" % (r.returncode, r.stderr))
    out = json.loads(r.stdout)
    return out["wall_bounces"], out["outcome"]


def cli_args(row):
    flags = [("--xi", "xi"), ("--U", "U"), ("--W", "W"), ("--e-wall", "e_wall"), ("--alpha-wall", "alpha_wall"),
             ("--e-floor", "e_floor"), ("--alpha-floor", "alpha_floor"), ("--max-bounces", "max_bounces")]
    return [SUPERBALL, "count", "--json"] + ["%s=%s" % (flag, row[key]) for flag, key in flags]


class MpReference(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rows = read_rows(MP_COUNTS)

    def test_file_covers_the_issue(self):
        rows = [r for _, r in self.rows]
        self.assertGreaterEqual(len(rows), MIN_ROWS)
        outcomes = {r["outcome"] for r in rows}
        self.assertEqual(outcomes, set(OUTCOMES))
        self.assertTrue(any(r["outcome"] == "capped" and int(r["wall_bounces"]) >= 1000 for r in rows))
        self.assertTrue(any(r["outcome"] in ("left", "missed") and int(r["wall_bounces"]) >= 500 for r in rows))
        self.assertTrue(any(r["e_wall"] == r["alpha_wall"] == r["e_floor"] == r["alpha_floor"] == "1.0" for r in rows))
        self.assertTrue(any(0.999 < float(r["xi"]) < 1.0 for r in rows))
        for r in rows:
            self.assertIn(r["outcome"], OUTCOMES)
            self.assertLessEqual(int(r["wall_bounces"]), int(r["max_bounces"]))

    def setUp(self):
        self.mismatches = []

    def check(self, number, row, got, via):
        """Records a row the kernel disagrees with; report() fails with all of them."""
        want = (int(row["wall_bounces"]), row["outcome"])
        if got != want:
            self.mismatches.append("%s: %s gives %d %s" % (describe(number, row), via, got[0], got[1]))

    def report(self):
        if self.mismatches:
            self.fail("%d rows disagree with the kernel:\n%s" % (len(self.mismatches), "\n".join(self.mismatches)))

    def test_kernel_matches_every_row(self):
        module, why_not = load_module()
        if module is None:
            print("\nthe Python module is not used (%s): every row through the command line" % why_not,
                  file=sys.stderr)
            self.check_cli([nr for nr in self.rows])
            self.report()
            return
        import numpy as np

        groups = {}
        for number, row in self.rows:
            key = tuple(row[k] for k in ("e_wall", "alpha_wall", "e_floor", "alpha_floor", "max_bounces"))
            groups.setdefault(key, []).append((number, row))
        checked = 0
        for key, members in sorted(groups.items()):
            model = dict(zip(("e_wall", "alpha_wall", "e_floor", "alpha_floor"), map(float, key[:4])))
            xi, U, W = (np.array([float(r[k]) for _, r in members]) for k in ("xi", "U", "W"))
            c = module.count(xi, U, W, max_bounces=int(key[4]), threads=1, **model)
            for i, (number, row) in enumerate(members):
                self.check(number, row, (int(c.wall_bounces[i]), OUTCOMES[int(c.outcome[i])]), "the module")
                checked += 1
        self.assertEqual(checked, len(self.rows))
        print("\n%d rows of mp_counts.csv checked against the Python module (%s)" % (checked, module.__file__),
              file=sys.stderr)
        sample = [nr for i, nr in enumerate(self.rows) if i % CLI_SAMPLE_EVERY == 0 or nr[1]["outcome"] == "invalid"]
        self.check_cli(sample)
        self.report()

    def check_cli(self, rows):
        for number, row in rows:
            got = cli_count(row)
            if row["outcome"] == "invalid":
                # The command line refuses a start that is no launch toward the wall (SPEC
                # section 6: bad input, status 2), naming the coordinate.
                if got[0] != "refused" or not re.search("--(xi|U)", got[1]):
                    self.mismatches.append("%s: superball count does not refuse it with a message naming --xi "
                                           "or --U: %s" % (describe(number, row), got))
            elif got[0] == "refused":
                self.mismatches.append("%s: superball count refuses it: %s" % (describe(number, row), got[1]))
            else:
                self.check(number, row, got, "superball count")
        print("%d rows of mp_counts.csv checked through `superball count --json`" % len(rows), file=sys.stderr)


FRICTION_HEADER = ["e_wall", "alpha_wall", "mu_wall", "e_floor", "alpha_floor", "mu_floor", "inertia", "max_bounces", "xi",
                   "U", "W", "wall_bounces", "outcome", "slides"]
FRICTION_COUNTS = os.path.join(REFERENCE_DIR, "mp_friction_counts.csv")
FRICTION_MODEL = ("e_wall", "alpha_wall", "mu_wall", "e_floor", "alpha_floor", "mu_floor", "inertia")


class FrictionReference(unittest.TestCase):
    """SPEC section 1b (Walton's friction law, the moment of inertia) against
    tests/reference/mp_friction_counts.csv (mp_reference.py --friction): every row through
    the Python module, a sample and the invalid rows through `superball count` with --mu-wall,
    --mu-floor and --inertia. (Every kernel variant is checked on every row by test_core's
    FrictionReference.)"""

    @classmethod
    def setUpClass(cls):
        cls.rows = read_rows(FRICTION_COUNTS, FRICTION_HEADER)

    def test_file_covers_the_issue(self):
        rows = [r for _, r in self.rows]
        self.assertGreaterEqual(len(rows), 500)
        self.assertGreater(sum(int(r["slides"]) > 0 for r in rows), len(rows) // 3)
        self.assertGreater(sum(r["outcome"] == "capped" for r in rows), 100)
        self.assertGreater(sum(int(r["wall_bounces"]) >= 100 and int(r["slides"]) > 0 for r in rows), 50)
        self.assertGreaterEqual(len({r["inertia"] for r in rows}), 4)
        self.assertGreaterEqual(len({r["mu_wall"] for r in rows}), 5)

    def test_module_and_command_line_match_every_row(self):
        module, why_not = load_module()
        mismatches = []
        sample = self.rows if module is None else [
            nr for i, nr in enumerate(self.rows) if i % CLI_SAMPLE_EVERY == 0 or nr[1]["outcome"] == "invalid"]
        if module is not None:
            import numpy as np

            groups = {}
            for number, row in self.rows:
                groups.setdefault(tuple(row[k] for k in FRICTION_MODEL + ("max_bounces",)), []).append((number, row))
            for key, members in sorted(groups.items()):
                model = dict(zip(FRICTION_MODEL, map(float, key[:-1])))
                xi, U, W = (np.array([float(r[k]) for _, r in members]) for k in ("xi", "U", "W"))
                c = module.count(xi, U, W, max_bounces=int(key[-1]), threads=1, **model)
                for i, (number, row) in enumerate(members):
                    got = (int(c.wall_bounces[i]), OUTCOMES[int(c.outcome[i])])
                    if got != (int(row["wall_bounces"]), row["outcome"]):
                        mismatches.append("line %d: the module gives %s, the reference %s %s" %
                                          (number, got, row["wall_bounces"], row["outcome"]))
        else:
            print("\nthe Python module is not used (%s): every row through the command line" % why_not, file=sys.stderr)
        for number, row in sample:
            flags = ["--%s=%s" % (key.replace("_", "-"), row[key]) for key in FRICTION_MODEL + ("xi", "U", "W", "max_bounces")]
            r = subprocess.run([SUPERBALL, "count", "--json"] + flags, capture_output=True, text=True, timeout=60)
            if row["outcome"] == "invalid":
                if r.returncode != 2:
                    mismatches.append("line %d: superball count does not refuse it (status %d)" % (number, r.returncode))
                continue
            if r.returncode != 0:
                mismatches.append("line %d: superball count exited %d: %s" % (number, r.returncode, r.stderr.strip()))
                continue
            out = json.loads(r.stdout)
            if (out["wall_bounces"], out["outcome"]) != (int(row["wall_bounces"]), row["outcome"]):
                mismatches.append("line %d: superball count gives %s %s" % (number, out["wall_bounces"], out["outcome"]))
        self.assertEqual(mismatches, [], "%d rows of mp_friction_counts.csv disagree" % len(mismatches))
        print("%d rows through the module, %d through `superball count --json`" %
              (0 if module is None else len(self.rows), len(sample)), file=sys.stderr)


class IndependentImplementations(unittest.TestCase):
    """mp_reference.py against the other independent reference, and against its own file."""

    @classmethod
    def setUpClass(cls):
        if importlib.util.find_spec("mpmath") is None:
            raise unittest.SkipTest("mpmath (Debian python3-mpmath) is not installed")
        sys.path.insert(0, os.path.abspath(REFERENCE_DIR))
        sys.dont_write_bytecode = True  # no __pycache__ in the source tree
        cls.mp = importlib.import_module("mp_reference")

    def test_reproduces_canonical_counts(self):
        rows, bad = self.mp.check_canonical(CANONICAL_COUNTS)
        self.assertEqual(len(rows), 40)
        self.assertEqual(bad, [], "mp_reference.py disagrees with canonical_counts.csv")

    def test_reproduces_its_own_rows(self):
        # The first row of each outcome and the longest motions: the file is the script's.
        rows = read_rows(MP_COUNTS)
        chosen = {}
        for number, row in rows:
            chosen.setdefault(row["outcome"], (number, row))
        longest = sorted(rows, key=lambda nr: -int(nr[1]["wall_bounces"]))
        picks = list(chosen.values()) + [nr for nr in longest if nr[1]["outcome"] != "capped"][:2] + longest[:1]
        for number, row in picks:
            model = self.mp.Model(row["e_wall"], row["alpha_wall"], row["e_floor"], row["alpha_floor"])
            got = self.mp.count(float(row["xi"]), float(row["U"]), float(row["W"]), model, int(row["max_bounces"]))
            self.assertEqual(got, (int(row["wall_bounces"]), row["outcome"]), describe(number, row))

    def test_reproduces_its_own_friction_rows(self):
        # The first row of each outcome, the longest motion and the one that slid most.
        rows = [row for _, row in read_rows(FRICTION_COUNTS, FRICTION_HEADER)]
        picks = {}
        for row in rows:
            picks.setdefault(row["outcome"], row)
        picks["longest"] = max(rows, key=lambda r: int(r["wall_bounces"]))
        picks["slid most"] = max(rows, key=lambda r: int(r["slides"]))
        for what, row in picks.items():
            model = self.mp.Model(row["e_wall"], row["alpha_wall"], row["e_floor"], row["alpha_floor"], row["mu_wall"],
                                  row["mu_floor"], row["inertia"])
            got = self.mp.count(float(row["xi"]), float(row["U"]), float(row["W"]), model, int(row["max_bounces"]))
            self.assertEqual(got, (int(row["wall_bounces"]), row["outcome"]), "%s: %s" % (what, row))

    def test_documented_counts(self):
        # The `superball count` examples of README.md and docs/ with the answer printed
        # under them: that answer is the independent implementation's, not only the binary's.
        source = os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.dirname(
            os.path.abspath(__file__))))
        docs = [os.path.join(source, "README.md")] + sorted(
            os.path.join(source, "docs", name) for name in os.listdir(os.path.join(source, "docs")) if name.endswith(".md"))
        examples = 0
        for path in docs:
            with open(path, encoding="utf-8") as f:
                lines = f.read().splitlines()
            for i, line in enumerate(lines[:-1]):
                m = re.fullmatch(r"\$ superball count (.*)", line.strip())
                answer = re.fullmatch(r"(\d+) wall bounces?, outcome (\w+)", lines[i + 1].strip())
                if not m or not answer:
                    continue
                flags = dict(re.findall(r"--([\w-]+) (\S+)", m.group(1)))
                e, alpha = flags.get("e", "1"), flags.get("alpha", "1")
                model = self.mp.Model(flags.get("e-wall", e), flags.get("alpha-wall", alpha), flags.get("e-floor", e),
                                      flags.get("alpha-floor", alpha))
                got = self.mp.count(float(flags["xi"]), float(flags["U"]), float(flags["W"]), model,
                                    int(flags.get("max-bounces", 1000)))
                self.assertEqual(got, (int(answer.group(1)), answer.group(2)), f"{path}:{i + 1}: {line.strip()}")
                examples += 1
        self.assertGreater(examples, 0, "no `$ superball count` example with its answer in README.md or docs/")


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    from superball_testing import main

    main()
