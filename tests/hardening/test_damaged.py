#!/usr/bin/python3
"""Damaged files, read by every reader: a table of damages applied one at a time (with
h5py or raw bytes) to a real result and a real partial file made by the binary. For each,
`superball info`, `superball analyse` and the analysis scripts (region_map.py,
summary.py) exit 2 with one line that names the file and the object (never a crash, a
traceback or a hang); and `explore --resume` onto a damaged partial file is refused with
the file left byte for byte. Then the writer's side: `explore --overwrite` replaces
superball's files only.

Run by ctest under the release build and, in the asan stage of tests/all, with the
binary built with AddressSanitizer (a report there exits 86, which no case expects).
Environment: SUPERBALL (the binary), SUPERBALL_SOURCE_DIR (for analysis/)."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import SOURCE, interrupted_run, mpi_env, superball_binary  # noqa: E402
# The damages, and the table of cases (shared with the C++ reader's test, tests/io/damaged).
from damages import (CASES, JOB, after, flip, make_empty, make_directory, make_text, not_superball_hdf5,  # noqa: E402
                     read_bytes, truncate, with_file, contradicting_journal, write_values)

ANALYSIS = os.path.join(SOURCE, "analysis")
PYTHON = os.environ.get("SUPERBALL_PYTHON") or "/usr/bin/python3"

def singleton_env():
    """The environment of one rank started without mpirun: Open MPI's UCX probing, useless
    for one rank, cost half of a refused run's 0.5 s here (the ob1 and self transports: 0.3 s)."""
    return {**mpi_env(), "OMPI_MCA_pml": "ob1", "OMPI_MCA_btl": "self"}

# Runs the analysis scripts' main() for many files in one Python process (matplotlib is
# imported once, not once per case): each case's exit status and standard error, or
# "traceback" with the traceback when an exception escapes the scripts' own handling.
DRIVER = r"""
import contextlib, io, json, sys, traceback
sys.path.insert(0, sys.argv[1])
import region_map, summary
scripts = {"region_map.py": region_map, "summary.py": summary}
results = []
for script, args in json.load(sys.stdin):
    module = scripts[script]
    err, out = io.StringIO(), io.StringIO()
    sys.argv = [script, *args]
    status = None
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        try:
            module.run_script(module.main)
        except SystemExit as e:
            status = e.code
        except BaseException:
            status = "traceback"
            err.write(traceback.format_exc())
    results.append({"status": status, "stdout": out.getvalue(), "stderr": err.getvalue()})
json.dump(results, sys.stdout)
"""


def make_result(cls, prefix, env):
    """The test class's binary, a fresh directory holding JOB and the result of it (every
    test class of this file starts from one)."""
    cls.binary = superball_binary()
    cls.dir = tempfile.mkdtemp(prefix=prefix)
    cls.job = os.path.join(cls.dir, "job.toml")
    with open(cls.job, "w") as f:
        f.write(JOB)
    cls.result = os.path.join(cls.dir, "result.h5")
    r = subprocess.run([cls.binary, "explore", cls.job, "-o", cls.result, "-q"], capture_output=True, text=True,
                       env=env, timeout=120)
    assert r.returncode == 0, r.stderr


class Damaged(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        make_result(cls, "superball-damaged-", mpi_env())
        cls.partial = interrupted_run(cls.binary, cls.job, os.path.join(cls.dir, "interrupted.h5"), cls.result,
                                      lambda t: t % 2 == 0)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def run_binary(self, *args):
        return subprocess.run([self.binary, *args], capture_output=True, text=True, env=singleton_env(), timeout=60)

    def damaged_copies(self, cases):
        """Each case applied to a fresh copy of its base: the partial file of case i is
        d<i>.h5.partial, so that `explore --resume -o d<i>.h5` finds it."""
        files = []
        for i, (what, base, damage, _) in enumerate(cases):
            out = os.path.join(self.dir, f"d{i}.h5")
            path = out + ".partial" if base == "P" else out
            shutil.copyfile(self.partial if base == "P" else self.result, path)
            damage(path)
            files.append((out, path))
        return files

    def assert_one_message(self, what, who, status, stderr, expected, path):
        self.assertNotEqual(status, "traceback", f"{what}: {who} raised:\n{stderr}")
        self.assertEqual(status, 2, f"{what}: {who} exit status {status}:\n{stderr}")
        lines = stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, f"{what}: {who} said more than one line:\n{stderr}")
        self.assertIn(path, lines[0], f"{what}: {who} does not name the file")
        alternatives = (expected,) if isinstance(expected, str) else expected
        self.assertTrue(any(e in lines[0] for e in alternatives), f"{what}: {who} said {lines[0]!r}, not {expected!r}")

    def test_every_reader_refuses_every_damage(self):
        files = self.damaged_copies(CASES)
        before = {path: read_bytes(path) if os.path.isfile(path) else None for _, path in files}
        # The scripts, all cases in one Python process.
        requests = []
        for _, path in files:
            requests += [["summary.py", [path]], ["region_map.py", [path, "-o", path + ".png"]]]
        driver = subprocess.run([PYTHON, "-c", DRIVER, ANALYSIS], input=json.dumps(requests), capture_output=True,
                                text=True, timeout=300)
        self.assertEqual(driver.returncode, 0, f"the analysis scripts crashed: {driver.stderr}")
        scripts = json.loads(driver.stdout)

        def binary_runs(i):
            out, path = files[i]
            runs = [("superball info", self.run_binary("info", path)), ("superball analyse", self.run_binary("analyse", path))]
            if CASES[i][1] == "P" and "forged" not in CASES[i][0]:
                # A tile forged with a matching checksum passes for computed: resume trusts
                # checksums, not values (the readers check those).
                runs.append(("explore --resume", self.run_binary("explore", self.job, "-o", out, "--resume", "-q")))
            return runs

        with ThreadPoolExecutor(max_workers=2) as pool:
            binary = list(pool.map(binary_runs, range(len(CASES))))
        for i, (what, base, _, expected) in enumerate(CASES):
            out, path = files[i]
            with self.subTest(what, base=base):
                for (name, run) in binary[i]:
                    self.assertNotIn("AddressSanitizer", run.stderr)
                    self.assertNotIn("runtime error", run.stderr)
                    self.assertEqual(run.stdout if name != "explore --resume" else "", "", f"{what}: {name} printed")
                    if name == "explore --resume":
                        self.assertEqual(run.returncode, 2, f"{what}: {name}: {run.stderr}")
                        self.assertEqual(run.stderr.count("superball explore:"), 1, run.stderr)
                        self.assertIn(path, run.stderr)
                        self.assertFalse(os.path.exists(out), f"{what}: {name} wrote a result")
                    else:
                        self.assert_one_message(what, name, run.returncode, run.stderr, expected, path)
                for k, script in enumerate(("summary.py", "region_map.py")):
                    r = scripts[2 * i + k]
                    self.assert_one_message(what, script, r["status"], r["stderr"], expected, path)
                if before[path] is not None:
                    self.assertEqual(read_bytes(path), before[path], f"{what}: a reader changed the file")
                elif base == "P" and what == "a directory as the partial file":
                    self.assertEqual(os.listdir(path), [])

    def test_scripts_as_a_user_runs_them(self):
        """The table runs the scripts' main() in one process; here each runs as a command."""
        ((out, path),) = self.damaged_copies([("", "R", write_values("outcome", (2, 3), 9), "")])
        for script in ("summary.py", "region_map.py"):
            r = subprocess.run([PYTHON, os.path.join(ANALYSIS, script), path], capture_output=True, text=True,
                               timeout=120)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertEqual(r.stderr.strip(), f"{script}: error: {path}: /outcome holds 9 at (2, 3): outcome codes "
                                                "are 0 to 3 (invalid left missed capped); the file is damaged")

    def test_one_byte_overwritten_anywhere(self):
        """A byte overwritten at offsets across each file: every reader either reads the
        file as it was (the byte was in space no object uses, or in a tile not done: what it
        prints is what it prints of the undamaged file) or refuses it with exit 2; never a
        crash, a traceback, a hang or wrong numbers."""
        cases = [(f"undamaged {base}", base, lambda path: None, "") for base in "RP"]
        for base, source in (("R", self.result), ("P", self.partial)):
            size = os.path.getsize(source)
            for offset in np.linspace(0, size - 1, 24).astype(int):
                def damage(path, offset=int(offset)):
                    with open(path, "r+b") as f:
                        f.seek(offset)
                        byte = f.read(1)[0]
                        f.seek(offset)
                        f.write(bytes([byte ^ 0xA5]))
                cases.append((f"byte {offset} of {base}", base, damage, ""))
        files = self.damaged_copies(cases)
        requests = [["summary.py", [path]] for _, path in files]
        driver = subprocess.run([PYTHON, "-c", DRIVER, ANALYSIS], input=json.dumps(requests), capture_output=True,
                                text=True, timeout=300)
        self.assertEqual(driver.returncode, 0, driver.stderr)
        refused = 0
        with ThreadPoolExecutor(max_workers=2) as pool:
            infos = list(pool.map(lambda f: self.run_binary("info", f[1]), files))
        summaries = json.loads(driver.stdout)
        # What each reader prints of the undamaged files (the first two cases), with the
        # file's name taken out.
        def printed(text, path):
            return text.replace(path, "FILE")
        expected = {cases[k][1]: (printed(infos[k].stdout, files[k][1]), printed(summaries[k]["stdout"], files[k][1]))
                    for k in (0, 1)}
        for k in (0, 1):
            self.assertEqual((infos[k].returncode, summaries[k]["status"]), (0, 0), cases[k][0])
        for (what, base, *_), (_, path), r, s in list(zip(cases, files, infos, summaries))[2:]:
            with self.subTest(what):
                self.assertIn(r.returncode, (0, 2), r.stderr)
                self.assertIn(s["status"], (0, 2), s["stderr"])
                if r.returncode == 0:
                    self.assertEqual(printed(r.stdout, path), expected[base][0], "info read the damaged file wrong")
                if s["status"] == 0:
                    self.assertEqual(printed(s["stdout"], path), expected[base][1], "summary.py read the damaged file wrong")
                if r.returncode == 2:
                    refused += 1
                    self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertGreater(refused, (len(cases) - 2) // 3)


class Overwrite(unittest.TestCase):
    """`explore --overwrite` replaces superball's files only; everything else is refused
    with a message that says what the file is, and left byte for byte."""

    @classmethod
    def setUpClass(cls):
        make_result(cls, "superball-overwrite-", singleton_env())

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def explore(self, out, *flags):
        return subprocess.run([self.binary, "explore", self.job, "-o", out, "-q", *flags], capture_output=True, text=True,
                              env=singleton_env(), timeout=120)

    def path(self, name):
        p = os.path.join(self.dir, name)
        for q in (p, p + ".partial", p + ".partial.undo"):
            if os.path.isdir(q):
                shutil.rmtree(q)
            elif os.path.exists(q):
                os.remove(q)
        return p

    def assert_refused(self, out, victim, flags, *needles):
        """Refused (exit 2, one message naming the file and saying what it is), the file left as it was."""
        before = read_bytes(victim) if os.path.isfile(victim) else None
        r = self.explore(out, *flags)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn(victim, r.stderr)
        for needle in needles:
            self.assertIn(needle, r.stderr)
        if before is not None:
            self.assertEqual(read_bytes(victim), before, "a refused run changed the file")
        self.assertFalse(os.path.exists(out + ".partial") and victim != out + ".partial", "a refused run left a partial file")
        return r

    def assert_valid_result(self, out):
        r = subprocess.run([self.binary, "info", out], capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("complete:    yes", r.stdout)

    def test_a_text_file_is_never_replaced(self):
        thesis = self.path("thesis.tex")
        make_text(thesis)
        size = os.path.getsize(thesis)
        r = self.assert_refused(thesis, thesis, ["--overwrite"], f"is a text file of {size} bytes, beginning",
                                "\\documentclass{article}", "not a superball file", "even with --overwrite")
        r = self.assert_refused(thesis, thesis, [], "is a text file", "not a superball file")
        self.assertNotIn("--overwrite", r.stderr)
        self.assert_refused(thesis, thesis, ["--resume"], "is a text file")

    def test_other_things_at_the_output_are_never_replaced(self):
        for what, make, needle in (("an empty file", make_empty, "is an empty file"),
                                   ("another program's HDF5 file", not_superball_hdf5, "an HDF5 file that is not superball's")):
            with self.subTest(what):
                out = self.path("other.h5")
                open(out, "w").close()
                make(out)
                self.assert_refused(out, out, ["--overwrite"], needle)
                r = self.assert_refused(out, out, [], needle)
                self.assertNotIn("--overwrite", r.stderr)
        directory = self.path("a-directory.h5")
        os.mkdir(directory)
        self.assert_refused(directory, directory, ["--overwrite"], "is a directory")
        self.assertTrue(os.path.isdir(directory))

    def test_the_partial_file_is_never_replaced_unless_it_is_superballs(self):
        out = self.path("p.h5")
        for what, make, needle in (("a text file", make_text, "is a text file"),
                                   ("another program's HDF5 file", not_superball_hdf5, "not superball's"),
                                   ("a directory", make_directory, "is a directory")):
            with self.subTest(what):
                partial = out + ".partial"
                if os.path.isdir(partial):
                    os.rmdir(partial)
                open(partial, "w").close()
                make(partial)
                for flags in (["--overwrite"], ["--resume"], []):
                    r = self.assert_refused(out, partial, flags, needle, "where this output's run keeps its tiles")
                    if "--overwrite" not in flags:
                        self.assertNotIn("--overwrite", r.stderr)
                self.assertFalse(os.path.exists(out))
        shutil.rmtree(out + ".partial")

    def test_damaged_superball_files_are_replaced_with_overwrite(self):
        """A result or partial file that cannot be read, but is superball's, is refused
        without --overwrite (which the message suggests) and replaced with it."""
        partial_source = interrupted_run(self.binary, self.job, self.path("source.h5"), self.result, lambda t: t == 0)
        cases = [
            ("truncated result", "R", truncate(0.5)),
            ("result with outcome 200", "R", write_values("outcome", (), 200)),
            ("result with a bit flipped in its root object header", "R", flip(after(b"OHDR", 12))),
            ("truncated partial file", "P", truncate(0.5)),
            ("partial file with a damaged done tile", "P", write_values("wall_bounces", (1, 1), 777)),
            ("partial file whose journal contradicts it", "P", with_file(contradicting_journal)),
        ]
        for what, base, damage in cases:
            with self.subTest(what):
                out = self.path("damaged.h5")
                victim = out + ".partial" if base == "P" else out
                shutil.copyfile(partial_source if base == "P" else self.result, victim)
                damage(victim)
                r = self.assert_refused(out, victim, [] if base == "R" else ["--resume"], "--overwrite")
                r = self.explore(out, "--overwrite")
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assert_valid_result(out)
                self.assertFalse(os.path.exists(out + ".partial"))

    def test_files_the_run_writes_beside_the_result(self):
        out = self.path("beside.h5")
        undo, sidecar = out + ".partial.undo", os.path.join(self.dir, "beside.xmf")
        make_text(undo)
        r = self.assert_refused(out, undo, ["--overwrite"], "is a text file", "undo log")
        os.remove(undo)
        with open(sidecar, "w") as f:
            f.write("my own notes\n")
        self.assert_refused(out, sidecar, [], "is a text file", "ParaView sidecar")
        os.remove(sidecar)
        # A sidecar superball wrote is its own: replaced.
        self.assertEqual(self.explore(out).returncode, 0)
        self.assertEqual(self.explore(out, "--overwrite").returncode, 0, r.stderr)
        self.assert_valid_result(out)
        # A result named like its own sidecar gets none: it is no foreign sidecar of itself.
        named_xmf = self.path("r.xmf")
        self.assertEqual(self.explore(named_xmf).returncode, 0)
        self.assertEqual(self.explore(named_xmf, "--overwrite").returncode, 0)
        self.assert_valid_result(named_xmf)


if __name__ == "__main__":
    superball_testing_main()
