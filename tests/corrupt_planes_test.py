#!/usr/bin/env python3
"""Test of scripts/corrupt_planes.py (ctest `bench.corrupt_planes`), the wrong maps of
scripts/bench_wrong_map.sh: a plane rotated by --rotate-deg turns its normal by that angle, and
the map's uncertainty axis (planes.json `sigma.major_axis`, which `planeloc run` requires to lie
in the plane) turns with it; a moved plane keeps its axes and shifts d by the move.

Usage: tests/corrupt_planes_test.py  (python3 -m unittest also works)
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "scripts", "corrupt_planes.py")


def facade():
    """A 10 m x 5 m facade x = 6 (normal +x), its major axis along z."""
    return {"id": 3, "kind": "facade", "area": 50.0, "normal": [1.0, 0.0, 0.0], "d": -6.0,
            "centroid": [6.0, -1.0, 20.0],
            "polygon": [[6, -3.5, 15], [6, 1.5, 15], [6, 1.5, 25], [6, -3.5, 25]],
            "sigma": {"offset": 0.02, "normal": [0.001, 0.002], "major_axis": [0.0, 0.0, 1.0]}}


def corrupt(*args):
    with tempfile.TemporaryDirectory() as tmp:
        src, out = os.path.join(tmp, "in.json"), os.path.join(tmp, "out.json")
        with open(src, "w") as f:
            json.dump({"planes": [facade()]}, f)
        subprocess.run([sys.executable, SCRIPT, src, out, "--seed", "1", "--fraction", "1",
                        *args], check=True, capture_output=True)
        with open(out) as f:
            return json.load(f)["planes"][0]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


class CorruptPlanesTest(unittest.TestCase):
    def test_rotation_turns_the_uncertainty_axis_with_the_plane(self):
        plane = corrupt("--rotate-deg", "2")
        angle = math.degrees(math.acos(dot(plane["normal"], [1.0, 0.0, 0.0])))
        self.assertAlmostEqual(angle, 2.0, places=6)
        axis = plane["sigma"]["major_axis"]
        self.assertAlmostEqual(dot(axis, axis), 1.0, places=12)
        self.assertAlmostEqual(dot(axis, plane["normal"]), 0.0, places=12)
        # The rotation is about an in-plane axis through the centroid: it stays on the plane.
        self.assertAlmostEqual(dot(plane["normal"], plane["centroid"]) + plane["d"], 0.0,
                               places=9)

    def test_move_shifts_the_offset_and_keeps_the_axes(self):
        plane = corrupt("--move", "0.2")
        self.assertEqual(plane["normal"], [1.0, 0.0, 0.0])
        self.assertAlmostEqual(abs(plane["d"] - (-6.0)), 0.2, places=12)
        self.assertEqual(plane["sigma"]["major_axis"], [0.0, 0.0, 1.0])


if __name__ == "__main__":
    unittest.main()
