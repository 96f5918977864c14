#!/usr/bin/env python3
"""Writes a rectified KITTI-odometry-layout sequence (image_0/1, calib.txt P0/P1, times.txt) in
the ASL / EuRoC MAV layout (mav0/cam0|cam1/{data.csv,data/,sensor.yaml}), as an ideal rig: no
distortion, cam1 `baseline` metres along cam0's x axis, T_BS of cam0 the identity. Images are
copied. `planeloc run --sequence OUT` then reads it through the ASL reader and rectifies it on
load (the identity here), which is how tests/asl_run_test.sh checks that reader end to end.
With --poses (KITTI world_from_cam, one line a frame) it also writes the ground truth as
mav0/state_groundtruth_estimate0/data.csv (the body is cam0 here: T_BS is the identity).

Usage: scripts/kitti_to_asl.py SEQUENCE_DIR OUT_DIR [--poses POSES] [--start-ns N]
"""
import argparse
import os
import shutil
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sequence")
    ap.add_argument("out")
    ap.add_argument("--poses", default="", help="KITTI pose file of the sequence (ground truth)")
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
    if args.poses:
        write_ground_truth(args.poses, times, args.start_ns, mav0)
    print(f"{mav0}: {len(times)} frames, fx {fx}, baseline {baseline:.4f} m")


def write_ground_truth(poses_path, times, start_ns, mav0):
    with open(poses_path) as f:
        poses = [[float(v) for v in line.split()] for line in f if line.strip()]
    if len(poses) != len(times) or any(len(p) != 12 for p in poses):
        sys.exit(f"{poses_path}: needs one line of 12 numbers per frame ({len(times)})")
    folder = os.path.join(mav0, "state_groundtruth_estimate0")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "data.csv"), "w") as f:
        f.write("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
                "q_RS_y [], q_RS_z []\n")
        for t, p in zip(times, poses):
            w, x, y, z = quaternion(p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10])
            stamp = start_ns + int(round(t * 1e9))
            f.write(f"{stamp},{p[3]!r},{p[7]!r},{p[11]!r},{w!r},{x!r},{y!r},{z!r}\n")


def quaternion(r00, r01, r02, r10, r11, r12, r20, r21, r22):
    """(w, x, y, z) of a rotation matrix (Shepperd's method: the largest diagonal term first)."""
    trace = r00 + r11 + r22
    if trace > 0:
        s = 2.0 * (trace + 1.0) ** 0.5
        return 0.25 * s, (r21 - r12) / s, (r02 - r20) / s, (r10 - r01) / s
    if r00 > r11 and r00 > r22:
        s = 2.0 * (1.0 + r00 - r11 - r22) ** 0.5
        return (r21 - r12) / s, 0.25 * s, (r01 + r10) / s, (r02 + r20) / s
    if r11 > r22:
        s = 2.0 * (1.0 + r11 - r00 - r22) ** 0.5
        return (r02 - r20) / s, (r01 + r10) / s, 0.25 * s, (r12 + r21) / s
    s = 2.0 * (1.0 + r22 - r00 - r11) ** 0.5
    return (r10 - r01) / s, (r02 + r20) / s, (r12 + r21) / s, 0.25 * s


def png_size(path):
    with open(path, "rb") as f:
        header = f.read(24)
    if header[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG image")
    return int.from_bytes(header[16:20], "big"), int.from_bytes(header[20:24], "big")


if __name__ == "__main__":
    main()
