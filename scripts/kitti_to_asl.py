#!/usr/bin/env python3
"""Writes a rectified KITTI-odometry-layout sequence (image_0/1, calib.txt P0/P1, times.txt) in
the ASL / EuRoC MAV layout (mav0/cam0|cam1/{data.csv,data/,sensor.yaml}), as an ideal rig: no
distortion, cam1 `baseline` metres along cam0's x axis, T_BS of cam0 the identity. Images are
copied. `planeloc run --sequence OUT` then reads it through the ASL reader and rectifies it on
load (the identity here), which is how tests/asl_run_test.sh checks that reader end to end.

Usage: scripts/kitti_to_asl.py SEQUENCE_DIR OUT_DIR [--start-ns N]
"""
import argparse
import os
import shutil
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sequence")
    ap.add_argument("out")
    ap.add_argument("--start-ns", type=int, default=1403715273000000000,
                    help="timestamp of frame 0 in nanoseconds (EuRoC's clock is Unix time)")
    args = ap.parse_args()
    calib = os.path.join(args.sequence, "calib.txt")
    projections = {}
    try:
        with open(calib) as f:
            for number, line in enumerate(f, 1):
                if ":" in line:
                    key, values = line.split(":", 1)
                    projections[key.strip()] = [float(v) for v in values.split()]
    except (OSError, ValueError) as error:
        sys.exit(f"{calib}: {error} (a KITTI odometry calib.txt with P0 and P1)")
    if len(projections.get("P0", [])) != 12 or len(projections.get("P1", [])) != 12:
        sys.exit(f"{calib}: needs P0 and P1 with 12 numbers each")
    p0, p1 = projections["P0"], projections["P1"]
    fx, cx, fy, cy = p0[0], p0[2], p0[5], p0[6]
    baseline = -(p1[3] - p0[3]) / fx
    with open(os.path.join(args.sequence, "times.txt")) as f:
        times = [float(line) for line in f if line.strip()]
    left = sorted(os.listdir(os.path.join(args.sequence, "image_0")))
    right = sorted(os.listdir(os.path.join(args.sequence, "image_1")))
    if len(left) != len(times) or len(right) != len(times):
        sys.exit(f"{args.sequence}: {len(times)} times but {len(left)} / {len(right)} images")
    width, height = png_size(os.path.join(args.sequence, "image_0", left[0]))
    mav0 = os.path.join(args.out, "mav0")
    for camera, folder, images, shift in (("cam0", "image_0", left, 0.0),
                                          ("cam1", "image_1", right, baseline)):
        data = os.path.join(mav0, camera, "data")
        os.makedirs(data, exist_ok=True)
        with open(os.path.join(mav0, camera, "sensor.yaml"), "w") as f:
            f.write("%YAML:1.0\nsensor_type: camera\ncomment: written by kitti_to_asl.py\n"
                    "T_BS:\n  cols: 4\n  rows: 4\n"
                    f"  data: [1.0, 0.0, 0.0, {shift!r}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0,"
                    " 0.0, 0.0, 0.0, 1.0]\n"
                    f"rate_hz: 10\nresolution: [{width}, {height}]\ncamera_model: pinhole\n"
                    f"intrinsics: [{fx!r}, {fy!r}, {cx!r}, {cy!r}]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n")
        with open(os.path.join(mav0, camera, "data.csv"), "w") as f:
            f.write("#timestamp [ns],filename\n")
            for t, image in zip(times, images):
                stamp = args.start_ns + int(round(t * 1e9))
                shutil.copyfile(os.path.join(args.sequence, folder, image),
                                os.path.join(data, f"{stamp}.png"))
                f.write(f"{stamp},{stamp}.png\n")
    print(f"{mav0}: {len(times)} frames, fx {fx}, baseline {baseline:.4f} m")


def png_size(path):
    with open(path, "rb") as f:
        header = f.read(24)
    if header[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG image")
    return int.from_bytes(header[16:20], "big"), int.from_bytes(header[20:24], "big")


if __name__ == "__main__":
    main()
