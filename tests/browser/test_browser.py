#!/usr/bin/env python3
"""The explorer's page in a real browser: Debian's chromium, headless, driven through the
DevTools protocol by puppeteer-core (page_test.mjs). It opens the page on a server started
for the test, pans and zooms (tiles of the new zoom load), reads the cursor readout (checked
against `superball count` at the same start), clicks a launch (its trajectory appears, with
the count `superball count` gives, and the ball moves), exports the view (a job `superball
explore --dry-run` accepts) and saves a screenshot: $SUPERBALL_SCREENSHOT, else
explorer.png in the working directory.

Needs node and tests/browser/install.sh (tests/all calls it). Label browser.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import Server, superball_binary  # noqa: E402

BINARY = superball_binary()


def legend_colour(legend, label):
    """The colour of the legend's entry `label` ("N = 8")."""
    for entry in legend["entries"]:
        if entry["label"] == label:
            return entry["colour"]
    raise AssertionError(f"no legend entry {label!r} in {legend}")


def count(start, *model):
    r = subprocess.run([BINARY, "count", "--xi", repr(start["xi"]), "--U", repr(start["U"]), "--W", repr(start["W"]),
                        *model, "--json"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


class BrowserTest(unittest.TestCase):
    def assert_explore_accepts(self, job_text):
        """`superball explore --dry-run` accepts the exported job."""
        with tempfile.TemporaryDirectory() as tmp:
            job = os.path.join(tmp, "view.toml")
            with open(job, "w") as f:
                f.write(job_text)
            r = subprocess.run([BINARY, "explore", job, "--dry-run"], capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)

    def test_page(self):
        node = shutil.which("node")
        self.assertIsNotNone(node, "node is needed: .ci/install-deps --browser")
        self.assertTrue(os.path.exists(os.path.join(HERE, "node_modules", "puppeteer-core")),
                        "puppeteer-core is missing: run tests/browser/install.sh")
        screenshot = os.path.abspath(os.environ.get("SUPERBALL_SCREENSHOT", "explorer.png"))
        with Server("--threads", "2") as server:
            r = subprocess.run([node, os.path.join(HERE, "page_test.mjs"), server.url, screenshot],
                               capture_output=True, text=True, timeout=300)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            report = json.loads(r.stdout)
            with urllib.request.urlopen(server.url.rstrip("/") + "/api/legend", timeout=60) as answer:
                legend = json.load(answer)
        self.assertEqual(report["errors"], [])
        self.assertEqual(report["message"], "")

        # Panned by the drag of (200, -150) px (Leaflet starts dragging after the first
        # move, of (20, -15) px), then zoomed in twice by the control, at least once by the wheel, and
        # out again to 2 levels above the start.
        pan = report["pan"]
        moved = [(pan["before"]["lng"] - pan["after"]["lng"]) * pan["scale"],
                 (pan["before"]["lat"] - pan["after"]["lat"]) * pan["scale"]]
        self.assertTrue(175 <= moved[0] <= 200 and 130 <= moved[1] <= 150, moved)
        self.assertAlmostEqual(moved[0] / moved[1], 4 / 3, places=2)
        self.assertGreaterEqual(report["zoom"]["wheeled"], report["zoom"]["before"] + 3)  # 2 clicks, the wheel
        self.assertEqual(report["zoom"]["after"], report["zoom"]["before"] + 2)
        self.assertGreater(report["zoom"]["tiles"]["loaded"], 0)

        # The readout: the start under the cursor, to the digits shown, and its count.
        model = ["--e", "0.9", "--alpha", "0.9", "--max-bounces", "1000"]
        readout, start = report["readout"]["text"], report["readout"]["start"]
        shown = dict(re.findall(r"^(\w+)\s*= (\S+)$", readout, re.M))
        for axis in ("xi", "W"):
            decimals = len(shown[axis].split(".")[1])
            self.assertAlmostEqual(float(shown[axis]), start[axis], places=decimals - 1)
        self.assertEqual(float(shown["U"]), -1)
        self.assertEqual(start["U"], -1)
        expected = count(start, *model)
        self.assertIn(f"N  = {expected['wall_bounces']} wall bounce", readout)
        self.assertTrue(readout.rstrip().endswith(expected["outcome"]), readout)
        # ... and the map's pixel there has the colour the legend gives that count (the
        # page's default colouring); the probe lies inside a region, not on a boundary.
        pixels = report["readout"]["pixels"]
        self.assertIsNotNone(pixels, "no map tile under the probe")
        self.assertEqual(len(set(pixels)), 1, f"the probe is on a boundary of regions, move it: {pixels}")
        self.assertEqual(pixels[4], legend_colour(legend, f"N = {expected['wall_bounces']}"),
                         f"the map shows {pixels[4]} where the readout says N = {expected['wall_bounces']}")

        # The first view held the whole window.
        self.assertTrue(report["initial"]["fits"], report["initial"])

        # The trajectory of the clicked launch.
        trajectory = report["trajectory"]
        expected = count(trajectory["start"], *model)
        self.assertIn(f"{expected['wall_bounces']} wall bounce", trajectory["info"])
        self.assertGreaterEqual(trajectory["wall_marks"], 1)
        self.assertEqual(trajectory["wall_marks"], expected["wall_bounces"])
        self.assertGreater(trajectory["path_points"], 24)
        self.assertNotEqual(trajectory["ball"][0], trajectory["ball"][1])

        # The exported job: the visible part of the map, accepted by explore.
        self.assertIn("[grid]", report["job"])
        self.assert_explore_accepts(report["job"])
        xi = re.search(r"^xi = \{ min = (\S+), max = (\S+), n = 4096 \}$", report["job"], re.M)
        self.assertIsNotNone(xi, report["job"])
        self.assertAlmostEqual(float(xi.group(1)), report["visible"]["sw"]["x"], places=12)
        self.assertAlmostEqual(float(xi.group(2)), report["visible"]["ne"]["x"], places=12)

        # SPEC.md 1b from the panel: mu = 0.3 and inertia = 0.5 reach the tiles, the readout
        # (its count that of `superball count` with them) and the exported job.
        friction = report["friction"]
        self.assertGreater(friction["tiles"], 0, "no tile requested with the new model")
        expected = count(friction["start"], *model, "--mu", "0.3", "--inertia", "0.5")
        self.assertIn(f"N  = {expected['wall_bounces']} wall bounce", friction["readout"])
        self.assertTrue(friction["readout"].rstrip().endswith(expected["outcome"]), friction["readout"])
        self.assertRegex(friction["job"], r"(?m)^mu = 0\.3$")
        self.assertRegex(friction["job"], r"(?m)^inertia = 0\.5$")
        self.assertIn("&mu=0.3&", friction["url"])  # the bookmarkable view holds the model
        self.assertEqual(friction["reset_message"], "")
        self.assert_explore_accepts(friction["job"])

        with open(screenshot, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")


if __name__ == "__main__":
    superball_testing_main()
