#!/usr/bin/env python3
"""Issue 15's acceptance comparison of a tiled plane map against the untiled one.

Every untiled plane of at least --min-area m^2 must have a tiled plane within --angle degrees
whose plane passes within --offset metres of the untiled centroid, lying on it (its centroid
within --near metres of the untiled outline); it is "split" when more than one tiled plane does
(a plane cut at a tile border). Prints one line per failure and a summary; exit 1 on any failure.

  scripts/compare_plane_maps.py untiled.json tiled.json [--min-area 20] [--angle 0.5]
                                [--offset 0.03] [--json summary.json]
"""
import argparse
import json
import math
import sys

import numpy as np


def load(path):
    with open(path) as f:
        return json.load(f)["planes"]


def in_plane_basis(n):
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def distance_to_polygon(q, ring):
    """2-D distance from q to a closed ring; 0 inside."""
    inside = False
    best = math.inf
    for i in range(len(ring)):
        a, b = ring[i], ring[(i + 1) % len(ring)]
        if (a[1] > q[1]) != (b[1] > q[1]):
            x = a[0] + (q[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            if q[0] < x:
                inside = not inside
        ab = b - a
        t = 0.0 if ab @ ab == 0 else min(1.0, max(0.0, (q - a) @ ab / (ab @ ab)))
        best = min(best, float(np.linalg.norm(q - (a + t * ab))))
    return 0.0 if inside else best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("untiled")
    parser.add_argument("tiled")
    parser.add_argument("--min-area", type=float, default=20.0)
    parser.add_argument("--angle", type=float, default=0.5, help="degrees")
    parser.add_argument("--offset", type=float, default=0.03, help="metres")
    parser.add_argument("--near", type=float, default=1.0, help="metres")
    parser.add_argument("--json", help="write the summary here")
    args = parser.parse_args()
    untiled, tiled = load(args.untiled), load(args.tiled)
    checked = matched = split = 0
    worst_angle = worst_offset = 0.0
    area_ratios = []
    for u in untiled:
        if u["area"] < args.min_area:
            continue
        checked += 1
        n = np.array(u["normal"])
        c = np.array(u["centroid"])
        bu, bv = in_plane_basis(n)
        ring = [np.array([p @ bu, p @ bv]) for p in map(np.array, u["polygon"])]
        hits = []
        for t in tiled:
            tn = np.array(t["normal"])
            angle = math.degrees(math.acos(min(1.0, abs(float(tn @ n)))))
            offset = abs(float(tn @ c) + t["d"])
            tc = np.array(t["centroid"])
            near = len(ring) < 3 or distance_to_polygon(np.array([tc @ bu, tc @ bv]), ring) <= args.near
            if angle < args.angle and offset < args.offset and near:
                hits.append((t, angle, offset))
        if not hits:
            print(f"untiled plane {u['id']} ({u['kind']}, {u['area']:.0f} m^2): no tiled match")
            continue
        matched += 1
        if len(hits) > 1:
            split += 1
            print(f"untiled plane {u['id']} ({u['kind']}, {u['area']:.0f} m^2): split into "
                  f"{len(hits)} tiled planes {[h[0]['id'] for h in hits]}")
        best = max(hits, key=lambda h: h[0]["area"])
        worst_angle = max(worst_angle, best[1])
        worst_offset = max(worst_offset, best[2])
        area_ratios.append(best[0]["area"] / u["area"])
    summary = {
        "untiled_planes": len(untiled), "tiled_planes": len(tiled), "checked": checked,
        "matched": matched, "split": split, "worst_angle_deg": worst_angle,
        "worst_offset_m": worst_offset,
        "area_ratio_min": min(area_ratios, default=0.0),
        "area_ratio_median": float(np.median(area_ratios)) if area_ratios else 0.0,
    }
    print(json.dumps(summary))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)
    return 0 if matched == checked and split == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
