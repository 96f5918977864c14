#!/usr/bin/env python3
"""Present a KITTI raw drive (synced and rectified) in the KITTI odometry layout, for the peer.

    scripts/peers/kitti_raw_as_odometry.py RAW_DRIVE_DIR OUT_SEQUENCE_DIR

ORB-SLAM2's runner (build-peers/bin/orbslam2_stereo_kitti) reads the odometry layout only:
image_0/NNNNNN.png, image_1/NNNNNN.png, times.txt, calib.txt. From a raw drive folder
(image_00/data/*.png, image_01/data/*.png, image_00/timestamps.txt, and calib_cam_to_cam.txt
there or one folder up, as KITTI ships it) this writes OUT_SEQUENCE_DIR with:
  image_0/, image_1/  symbolic links to the raw images, renumbered 000000.png, ... in name order
                      (nothing is copied: the raw data stays where it is);
  times.txt           seconds since the first left timestamp;
  calib.txt           P0..P3 from P_rect_00..P_rect_03 (the rectified projections; P1's fourth
                      entry is -fx * baseline, as in the odometry calib files).
planeloc reads both layouts; the bench gives both programs this folder, so they read the same
files. Any missing or malformed input is exit 2 naming the file. Pure python3.
"""
import argparse
import datetime
import os
import sys


def fail(message):
    print(f"kitti_raw_as_odometry: {message}", file=sys.stderr)
    sys.exit(2)


def find_calib(raw):
    for folder in (raw, os.path.dirname(os.path.abspath(raw))):
        path = os.path.join(folder, "calib_cam_to_cam.txt")
        if os.path.isfile(path):
            return path
    fail(f"no calib_cam_to_cam.txt in {raw} or its parent folder (the raw drive's calibration)")


def read_projections(path):
    """P_rect_00..03 (12 numbers each) from calib_cam_to_cam.txt; P_rect_02/03 may be absent."""
    rows = {}
    with open(path) as f:
        for number, line in enumerate(f, 1):
            key, sep, values = line.partition(":")
            if not sep or not key.startswith("P_rect_"):
                continue
            try:
                numbers = [float(v) for v in values.split()]
            except ValueError:
                fail(f"{path}:{number}: {key} is not a list of numbers")
            if len(numbers) != 12:
                fail(f"{path}:{number}: {key} has {len(numbers)} numbers, not 12 (a 3x4 matrix)")
            rows[key] = numbers
    for key in ("P_rect_00", "P_rect_01"):
        if key not in rows:
            fail(f"{path} has no {key} line (the rectified projection of the grey cameras)")
    return [rows.get(f"P_rect_0{i}", rows[f"P_rect_0{i % 2}"]) for i in range(4)]


def read_times(path, frames):
    """Seconds since the first of the raw 'YYYY-MM-DD HH:MM:SS.fffffffff' timestamps."""
    if not os.path.isfile(path):
        fail(f"{path} is missing (the left camera's timestamps)")
    stamps = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            text = line.strip()
            if not text:
                continue
            day, _, fraction = text.partition(".")
            try:
                whole = datetime.datetime.strptime(day, "%Y-%m-%d %H:%M:%S")
                seconds = whole.timestamp() + (float("0." + fraction) if fraction else 0.0)
            except ValueError:
                fail(f"{path}:{number}: '{text}' is not a 'YYYY-MM-DD HH:MM:SS.fraction' timestamp")
            stamps.append(seconds)
    if len(stamps) != frames:
        fail(f"{path} has {len(stamps)} timestamps for {frames} images")
    return [s - stamps[0] for s in stamps]


def images(raw, camera):
    folder = os.path.join(raw, f"image_0{camera}", "data")
    if not os.path.isdir(folder):
        fail(f"{folder} is missing (the raw drive's grey camera {camera})")
    names = sorted(n for n in os.listdir(folder) if n.endswith(".png"))
    if not names:
        fail(f"{folder} holds no .png image")
    return [os.path.join(os.path.abspath(folder), n) for n in names]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("raw", help="raw drive folder (image_00/data, image_01/data, ...)")
    parser.add_argument("out", help="sequence folder to write (odometry layout)")
    args = parser.parse_args()
    if not os.path.isdir(args.raw):
        fail(f"{args.raw} is not a folder (a KITTI raw drive, synced and rectified)")
    left, right = images(args.raw, 0), images(args.raw, 1)
    if len(left) != len(right):
        fail(f"{args.raw}: {len(left)} left images but {len(right)} right ones")
    projections = read_projections(find_calib(args.raw))
    times = read_times(os.path.join(args.raw, "image_00", "timestamps.txt"), len(left))
    for camera, files in ((0, left), (1, right)):
        folder = os.path.join(args.out, f"image_{camera}")
        os.makedirs(folder, exist_ok=True)
        for index, source in enumerate(files):
            link = os.path.join(folder, f"{index:06d}.png")
            if os.path.lexists(link):
                os.remove(link)
            os.symlink(source, link)
    with open(os.path.join(args.out, "times.txt"), "w") as f:
        f.writelines(f"{t:.6e}\n" for t in times)
    with open(os.path.join(args.out, "calib.txt"), "w") as f:
        for i, p in enumerate(projections):
            f.write(f"P{i}: " + " ".join(f"{v:.12e}" for v in p) + "\n")
    print(f"{args.out}: {len(left)} stereo frames of {args.raw}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
