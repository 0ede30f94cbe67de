#!/usr/bin/python3
"""Every command of the README, run as written and in its order, from a scratch folder laid
out like a clone after the README's set-up (jobs/, analysis/ and .ci/ of the repository;
build/native and build/release both the build under test, so nothing is built again);
where the README shows what a command prints (`$ ` lines), the output is compared with it
(`...` stands for the lines left out).

The set-up commands: `jobs/local.sh jobs/quickstart.toml` runs here like the others;
`tests/all` is what CI runs (.ci/run) and would run this test again, so it is the one
command not run here.

Run by ctest (SUPERBALL = the built binary, SUPERBALL_SOURCE_DIR = the repository), or by hand:
  SUPERBALL=build/release/src/superball /usr/bin/python3 tests/launchers/test_readme.py -v
"""
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import SOURCE, mpi_env, superball_binary  # noqa: E402

README = os.path.join(SOURCE, "README.md")
NOT_RUN = {"tests/all": "what CI runs (.ci/run); it would run this test again"}


def readme_commands(text):
    """[(command, expected output lines or None, line number)] of the README's sh blocks, in
    order. In a block that starts with `$ `, the `$ ` lines are commands and the others
    their output; in any other block every line is a command, its `# comment` dropped."""
    commands = []
    transcript = None  # None: outside a block
    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            transcript = False if transcript is None and line.strip() == "```sh" else None
            continue
        if transcript is None or not line.strip():
            continue
        if line.startswith("$ "):
            transcript = True
            commands.append((line[2:], [], number))
        elif transcript:
            commands[-1][1].append(line)
        else:
            commands.append((re.sub(r"\s+#.*$", "", line), None, number))
    return commands


class Readme(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.binary = superball_binary()
        cls.build = os.path.dirname(os.path.dirname(cls.binary))
        cls.dir = tempfile.mkdtemp(prefix="superball-readme-")
        for name in ("jobs", "analysis", ".ci"):
            os.symlink(os.path.join(SOURCE, name), os.path.join(cls.dir, name))
        os.makedirs(os.path.join(cls.dir, "build"))
        for name in ("native", "release"):
            os.symlink(cls.build, os.path.join(cls.dir, "build", name))
        # Debian's python3 first (the README's Python is the system's), then what there was.
        cls.env = mpi_env()
        cls.env["PATH"] = "/usr/bin:/bin:" + cls.env.get("PATH", "")
        for name in ("SUPERBALL", "SUPERBALL_BUILD", "SUPERBALL_RANKS", "SUPERBALL_RESULTS", "PYTHONPATH"):
            cls.env.pop(name, None)
        with open(README) as f:
            cls.commands = readme_commands(f.read())

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def shell(self, exports, command, timeout=600):
        """`command` in bash from the scratch folder, after the README's exports so far."""
        script = "".join(e + "\n" for e in exports) + command
        return subprocess.run(["bash", "-c", script], cwd=self.dir, env=self.env, capture_output=True, text=True,
                              timeout=timeout)

    def serve(self, exports, command):
        """A `superball serve` command: it must print its URL, and the URL answer with the page."""
        script = "".join(e + "\n" for e in exports) + "exec " + command
        p = subprocess.Popen(["bash", "-c", script], cwd=self.dir, env=self.env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        try:
            ready, _, _ = select.select([p.stdout], [], [], 60)
            line = p.stdout.readline() if ready else ""
            match = re.search(r"http://\S+", line)
            self.assertTrue(match, f"{command}: printed no URL: {line!r}")
            with urllib.request.urlopen(match.group(0), timeout=60) as r:
                self.assertEqual(r.status, 200)
                self.assertIn(b"<html", r.read().lower())
        finally:
            p.send_signal(signal.SIGTERM)
            p.wait(timeout=30)
            stderr = p.stderr.read()
            p.stdout.close()
            p.stderr.close()
        self.assertEqual(p.returncode, 0, f"{command}: {stderr}")

    def test_every_command_runs_as_the_readme_shows(self):
        self.assertGreaterEqual(len(self.commands), 10, "the README's commands were not found")
        exports = []
        for command, expected, line in self.commands:
            with self.subTest(line=line, command=command):
                if command in NOT_RUN:
                    continue
                if command.startswith("export "):
                    exports.append(command)
                    continue
                if re.match(r"superball serve\b", command):
                    self.serve(exports, command)
                    continue
                r = self.shell(exports, command)
                self.assertEqual(r.returncode, 0, f"README line {line}: {command}\n{r.stdout}\n{r.stderr}")
                if expected:
                    shown = [x for x in expected if x != "..."]
                    got = r.stdout.splitlines()
                    if "..." in expected:
                        got = got[:len(shown)]
                    self.assertEqual(got, shown, f"README line {line}: {command}")
        # What the commands say they make.
        for path in ("results/quickstart.h5", "results/quickstart.png", "results/quickstart_2.h5", "alpha.csv",
                     "alpha.png", "alpha.pdf", "results/bifurcation_e0.9_alpha.csv",
                     "results/bifurcation_e0.9_alpha.png", "results/bifurcation_e0.9_alpha.pdf"):
            self.assertTrue(os.path.isfile(os.path.join(self.dir, path)), path)

    def test_only_the_set_up_is_left_out(self):
        commands = [c for c, _, _ in self.commands]
        self.assertEqual(commands[:2], ["jobs/local.sh jobs/quickstart.toml", "tests/all"])
        self.assertEqual([c for c in commands if c in NOT_RUN], ["tests/all"])


if __name__ == "__main__":
    superball_testing_main()
