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



def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def load(path):
    with open(path) as f:
        return json.load(f)["planes"]


def in_plane_basis(n):
    helper = [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0]
    u = unit(cross(n, helper))
    return u, cross(n, u)


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
        ab = sub(b, a)
        t = 0.0 if dot(ab, ab) == 0 else min(1.0, max(0.0, dot(sub(q, a), ab) / dot(ab, ab)))
        r = sub(q, [a[0] + t * ab[0], a[1] + t * ab[1]])
        best = min(best, math.sqrt(dot(r, r)))
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
        n = u["normal"]
        c = u["centroid"]
        bu, bv = in_plane_basis(n)
        ring = [[dot(p, bu), dot(p, bv)] for p in u["polygon"]]
        hits = []
        for t in tiled:
            angle = math.degrees(math.acos(min(1.0, abs(dot(t["normal"], n)))))
            offset = abs(dot(t["normal"], c) + t["d"])
            tc = t["centroid"]
            near = (len(ring) < 3 or
                    distance_to_polygon([dot(tc, bu), dot(tc, bv)], ring) <= args.near)
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
        "area_ratio_median": sorted(area_ratios)[len(area_ratios) // 2] if area_ratios else 0.0,
    }
    print(json.dumps(summary))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)
    return 0 if matched == checked and split == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
