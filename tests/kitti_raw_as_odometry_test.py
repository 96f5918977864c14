#!/usr/bin/env python3
"""Test of scripts/peers/kitti_raw_as_odometry.py (ctest `bench.kitti_raw_layout`), which gives
the peer (ORB-SLAM2 reads the odometry layout only) and planeloc the same files of a KITTI raw
drive: image links renumbered in name order, times in seconds from the first timestamp, P0..P3
from P_rect_00..03, and exit 2 naming the file on a calibration without P_rect_01.

Usage: tests/kitti_raw_as_odometry_test.py  (python3 -m unittest also works)
"""
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "scripts", "peers", "kitti_raw_as_odometry.py")

P_RECT_00 = "721.5 0 609.5 0 0 721.5 172.8 0 0 0 1 0"
P_RECT_01 = "721.5 0 609.5 -387.57 0 721.5 172.8 0 0 0 1 0"


def raw_drive(root, calib_lines, frames=3):
    """A raw drive folder: `frames` stereo pairs (any bytes: nothing decodes them), timestamps
    0.1 s apart across a minute boundary (at most 3), and the calibration one folder up, as KITTI ships it."""
    drive = os.path.join(root, "2011_09_26", "2011_09_26_drive_0001_sync")
    for camera in ("image_00", "image_01"):
        os.makedirs(os.path.join(drive, camera, "data"))
        for i in reversed(range(frames)):  # listing order must not matter
            with open(os.path.join(drive, camera, "data", f"{i:010d}.png"), "w") as f:
                f.write(f"{camera} {i}")
    clock = ["13:02:59.950000000", "13:03:00.050000000", "13:03:00.150000000"]
    with open(os.path.join(drive, "image_00", "timestamps.txt"), "w") as f:
        f.writelines(f"2011-09-26 {t}\n" for t in clock[:frames])
    with open(os.path.join(root, "2011_09_26", "calib_cam_to_cam.txt"), "w") as f:
        f.write("calib_time: 09-Jan-2012 13:57:47\n" + "".join(line + "\n" for line in calib_lines))
    return drive


def convert(drive, out):
    return subprocess.run([sys.executable, SCRIPT, drive, out], capture_output=True, text=True)


class KittiRawAsOdometryTest(unittest.TestCase):
    def test_links_times_and_projections(self):
        with tempfile.TemporaryDirectory() as tmp:
            drive = raw_drive(tmp, [f"P_rect_00: {P_RECT_00}", f"P_rect_01: {P_RECT_01}"])
            out = os.path.join(tmp, "seq", "00")
            done = convert(drive, out)
            self.assertEqual(done.returncode, 0, done.stderr)
            for camera, raw in ((0, "image_00"), (1, "image_01")):
                for i in range(3):
                    link = os.path.join(out, f"image_{camera}", f"{i:06d}.png")
                    self.assertTrue(os.path.islink(link), link)
                    with open(link) as f:
                        self.assertEqual(f.read(), f"{raw} {i}")
            with open(os.path.join(out, "times.txt")) as f:
                times = [float(line) for line in f]
            # 13:02:59.95, 13:03:00.05, 13:03:00.15.
            self.assertEqual(len(times), 3)
            for got, want in zip(times, (0.0, 0.1, 0.2)):
                self.assertAlmostEqual(got, want, places=6)
            with open(os.path.join(out, "calib.txt")) as f:
                rows = {line.split(":")[0]: [float(v) for v in line.split(":")[1].split()]
                        for line in f}
            self.assertEqual(rows["P0"], [float(v) for v in P_RECT_00.split()])
            self.assertEqual(rows["P1"][3], -387.57)  # -fx * baseline, as the odometry files
            # No colour projections in this calibration: P2/P3 repeat the grey ones.
            self.assertEqual(rows["P2"], rows["P0"])
            self.assertEqual(rows["P3"], rows["P1"])
            # A second call over the same folder replaces the links.
            self.assertEqual(convert(drive, out).returncode, 0)

    def test_missing_right_projection_is_exit_2_naming_the_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            drive = raw_drive(tmp, [f"P_rect_00: {P_RECT_00}"])
            done = convert(drive, os.path.join(tmp, "out"))
            self.assertEqual(done.returncode, 2)
            self.assertIn("calib_cam_to_cam.txt has no P_rect_01", done.stderr)

    def test_timestamps_for_other_frames_are_exit_2(self):
        with tempfile.TemporaryDirectory() as tmp:
            drive = raw_drive(tmp, [f"P_rect_00: {P_RECT_00}", f"P_rect_01: {P_RECT_01}"])
            os.remove(os.path.join(drive, "image_00", "data", "0000000002.png"))
            os.remove(os.path.join(drive, "image_01", "data", "0000000002.png"))
            done = convert(drive, os.path.join(tmp, "out"))
            self.assertEqual(done.returncode, 2)
            self.assertIn("timestamps.txt has 3 timestamps for 2 images", done.stderr)


if __name__ == "__main__":
    unittest.main()
