#!/usr/bin/env python3
"""Perturbs a KITTI pose file (12 numbers per line, world_from_cam) with seeded Gaussian noise:
each pose moved by N(0, sigma_t^2) metres per axis and turned by a rotation vector drawn from
N(0, sigma_r^2) per axis (degrees), applied on the left (in the world frame, about the camera
centre). Issue 10's "noisy map" benchmark: a LiDAR map accumulated from such poses has planes
that are blurred and slightly off, as a map from an imperfect LiDAR odometry would be.

  noisy_poses.py IN.txt OUT.txt --seed 1 --sigma-t 0.05 --sigma-r-deg 0.2

python3 only (no numpy).
"""
import argparse
import math
import random
import sys


def rodrigues(v):
    angle = math.sqrt(sum(x * x for x in v))
    if angle < 1e-15:
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    k = [x / angle for x in v]
    c, s = math.cos(angle), math.sin(angle)
    kx, ky, kz = k
    return [[c + kx * kx * (1 - c), kx * ky * (1 - c) - kz * s, kx * kz * (1 - c) + ky * s],
            [ky * kx * (1 - c) + kz * s, c + ky * ky * (1 - c), ky * kz * (1 - c) - kx * s],
            [kz * kx * (1 - c) - ky * s, kz * ky * (1 - c) + kx * s, c + kz * kz * (1 - c)]]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sigma-t", type=float, default=0.05, help="metres per axis")
    ap.add_argument("--sigma-r-deg", type=float, default=0.2, help="degrees per axis")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    out = []
    with open(args.input) as f:
        for number, line in enumerate(f, 1):
            if not line.strip():
                continue
            v = [float(x) for x in line.split()]
            if len(v) != 12:
                sys.exit(f"{args.input}:{number}: expected 12 numbers, got {len(v)}")
            r = [v[0:3], v[4:7], v[8:11]]
            t = [v[3], v[7], v[11]]
            d = rodrigues([math.radians(rng.gauss(0, args.sigma_r_deg)) for _ in range(3)])
            r = [[sum(d[i][k] * r[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
            t = [t[i] + rng.gauss(0, args.sigma_t) for i in range(3)]
            out.append(" ".join(f"{x:.9e}" for x in (r[0] + [t[0]] + r[1] + [t[1]] + r[2] +
                                                    [t[2]])))
    with open(args.output, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
