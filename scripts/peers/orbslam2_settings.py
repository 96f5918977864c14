#!/usr/bin/env python3
"""Write an ORB-SLAM2 stereo settings file (OpenCV FileStorage YAML, %YAML:1.0) for a sequence.

    scripts/peers/orbslam2_settings.py SEQUENCE_DIR [-o OUT.yaml]

SEQUENCE_DIR is in KITTI odometry layout (calib.txt, image_0/000000.png). From calib.txt:
P0 gives fx fy cx cy, bf = -P1[3] (P1[3] = -fx * baseline). The image size is read from the PNG
header of image_0/000000.png (or of the first image_0/*.png). Everything else is ORB-SLAM2's
KITTI00-02.yaml: fps 10, RGB 1, no distortion, ThDepth 35, ORB 2000 features, scale 1.2,
8 levels, FAST 20/7, and its viewer block (the runner keeps the viewer off). Pure python3.
Without -o the YAML goes to stdout.
"""
import argparse
import os
import struct
import sys


def read_calib(path):
    rows = {}
    with open(path) as f:
        for line in f:
            if ":" not in line:
                continue
            key, values = line.split(":", 1)
            try:
                rows[key.strip()] = [float(v) for v in values.split()]
            except ValueError:
                raise SystemExit(f"orbslam2_settings: bad numbers on line '{line.strip()}' of {path}")
    for key in ("P0", "P1"):
        if len(rows.get(key, [])) != 12:
            raise SystemExit(f"orbslam2_settings: {path} has no 12-number {key} line")
    return rows["P0"], rows["P1"]


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise SystemExit(f"orbslam2_settings: {path} is not a PNG file")
    width, height = struct.unpack(">II", head[16:24])
    return width, height


def first_image(seq):
    folder = os.path.join(seq, "image_0")
    first = os.path.join(folder, "000000.png")
    if os.path.isfile(first):
        return first
    try:
        pngs = sorted(n for n in os.listdir(folder) if n.endswith(".png"))
    except OSError:
        pngs = []
    if not pngs:
        raise SystemExit(f"orbslam2_settings: no PNG image in {folder}")
    return os.path.join(folder, pngs[0])


def settings_yaml(p0, p1, width, height, source):
    fx, fy, cx, cy = p0[0], p0[5], p0[2], p0[6]
    bf = -p1[3]
    if fx <= 0 or fy <= 0 or bf <= 0:
        raise SystemExit(f"orbslam2_settings: implausible calibration fx={fx} fy={fy} bf={bf}")
    if abs(p1[0] - fx) > 1e-6 * fx or abs(p1[2] - cx) > 1e-6 * max(1.0, abs(cx)):
        print("orbslam2_settings: warning: P1's fx/cx differ from P0's (not a rectified pair?)",
              file=sys.stderr)

    def num(v):
        return repr(float(v))

    return f"""%YAML:1.0
# ORB-SLAM2 stereo settings written by scripts/peers/orbslam2_settings.py for
# {source}
# Camera from calib.txt (P0; bf = -P1[3]); everything else as ORB-SLAM2's KITTI00-02.yaml.

# Camera Parameters (rectified: no distortion)
Camera.fx: {num(fx)}
Camera.fy: {num(fy)}
Camera.cx: {num(cx)}
Camera.cy: {num(cy)}

Camera.k1: 0.0
Camera.k2: 0.0
Camera.p1: 0.0
Camera.p2: 0.0

Camera.width: {width}
Camera.height: {height}

# Camera frames per second
Camera.fps: 10.0

# stereo baseline times fx
Camera.bf: {num(bf)}

# Color order of the images (0: BGR, 1: RGB. It is ignored if images are grayscale)
Camera.RGB: 1

# Close/Far threshold. Baseline times.
ThDepth: 35

# ORB Parameters
ORBextractor.nFeatures: 2000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7

# Viewer Parameters (unused: the runner has no viewer)
Viewer.KeyFrameSize: 0.6
Viewer.KeyFrameLineWidth: 2
Viewer.GraphLineWidth: 1
Viewer.PointSize: 2
Viewer.CameraSize: 0.7
Viewer.CameraLineWidth: 3
Viewer.ViewpointX: 0
Viewer.ViewpointY: -100
Viewer.ViewpointZ: -0.1
Viewer.ViewpointF: 2000
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence", help="KITTI-layout sequence folder (calib.txt, image_0/)")
    parser.add_argument("-o", "--out", help="output YAML (default: stdout)")
    args = parser.parse_args()
    calib = os.path.join(args.sequence, "calib.txt")
    if not os.path.isfile(calib):
        raise SystemExit(f"orbslam2_settings: no calib.txt in {args.sequence}")
    p0, p1 = read_calib(calib)
    width, height = png_size(first_image(args.sequence))
    text = settings_yaml(p0, p1, width, height, os.path.abspath(args.sequence))
    if args.out:
        tmp = args.out + ".tmp"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, args.out)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
