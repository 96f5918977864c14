#!/usr/bin/env python3
"""Issue 15's acceptance comparison of a tiled plane map against the untiled one.

Planes correspond by their outlines: each polygon is rasterized (--cell metres) in the coordinate
plane its normal is closest to, and each tiled plane is assigned to the untiled plane, within
--angle degrees and whose centroid its plane passes within --offset metres of, that its outline
overlaps most (intersection over union). An untiled plane of at least --min-area m^2 is matched
when a tiled plane assigned to it has IoU >= --iou (the same plane, not one joined with a
neighbour: a joined plane's IoU drops); it is "split" when more than one tiled plane assigned to
it covers at least --split-cover of its outline (a plane cut at a tile border and not re-joined).
Outlines are outer boundaries (plane_outline.h), so a plane inside a road loop lies inside the
road's outline: assigning each tiled plane once keeps it from counting for the road too.
Prints one line per failure and a summary; exit 1 on any failure.

  scripts/compare_plane_maps.py untiled.json tiled.json [--min-area 20] [--angle 0.5]
                                [--offset 0.03] [--iou 0.5] [--allow-unmatched N]
                                [--allow-split N] [--json summary.json]
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


def project(plane):
    """Polygon in the coordinate plane closest to the plane's (drop the normal's largest axis)."""
    n = plane["normal"]
    drop = max(range(3), key=lambda k: abs(n[k]))
    keep = [k for k in range(3) if k != drop]
    return drop, [(p[keep[0]], p[keep[1]]) for p in plane["polygon"]]


def rasterize(ring, cell):
    """Cells (i, j) whose centre lies inside the closed ring (even-odd scanlines)."""
    cells = set()
    if len(ring) < 3:
        return cells
    ys = [p[1] for p in ring]
    edges = [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
    for j in range(math.floor(min(ys) / cell), math.ceil(max(ys) / cell) + 1):
        y = (j + 0.5) * cell
        xs = sorted(a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
                    for a, b in edges if (a[1] > y) != (b[1] > y))
        for x0, x1 in zip(xs[0::2], xs[1::2]):
            for i in range(math.ceil(x0 / cell - 0.5), math.floor(x1 / cell - 0.5) + 1):
                cells.add((i, j))
    return cells


def coplanar(u, t, args):
    angle = math.degrees(math.acos(min(1.0, abs(dot(t["normal"], u["normal"])))))
    offset = abs(dot(t["normal"], u["centroid"]) + t["d"])
    return angle < args.angle and offset < args.offset, angle, offset


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("untiled")
    parser.add_argument("tiled")
    parser.add_argument("--min-area", type=float, default=20.0)
    parser.add_argument("--angle", type=float, default=0.5, help="degrees")
    parser.add_argument("--offset", type=float, default=0.03, help="metres")
    parser.add_argument("--cell", type=float, default=0.5, help="raster cell, metres")
    parser.add_argument("--iou", type=float, default=0.5)
    parser.add_argument("--split-cover", type=float, default=0.1)
    parser.add_argument("--allow-unmatched", type=int, default=0,
                        help="exit 0 with up to this many checked planes unmatched")
    parser.add_argument("--allow-split", type=int, default=0,
                        help="exit 0 with up to this many checked planes split (a tile's own "
                             "extraction can cut a plane inside the tile, away from any border)")
    parser.add_argument("--json", help="write the summary here")
    args = parser.parse_args()
    untiled, tiled = load(args.untiled), load(args.tiled)
    raster = {}
    for key, planes in (("u", untiled), ("t", tiled)):
        for p in planes:
            drop, ring = project(p)
            raster[key, p["id"]] = (drop, rasterize(ring, args.cell))
    # Each tiled plane to the coplanar untiled plane its outline overlaps most (IoU).
    assigned = {}  # untiled id -> [(iou, cover of u, tiled plane, angle, offset)]
    for t in tiled:
        dt, ct = raster["t", t["id"]]
        best = None
        for u in untiled:
            ok, angle, offset = coplanar(u, t, args)
            du, cu = raster["u", u["id"]]
            if not ok or du != dt or not cu or not ct:
                continue
            common = len(cu & ct)
            if common == 0:
                continue
            iou = common / (len(cu) + len(ct) - common)
            if best is None or iou > best[0]:
                best = (iou, common / len(cu), u["id"], angle, offset)
        if best:
            assigned.setdefault(best[2], []).append((best[0], best[1], t, best[3], best[4]))
    checked = matched = split = 0
    worst_angle = worst_offset = 0.0
    area_ratios, ious = [], []
    for u in untiled:
        if u["area"] < args.min_area:
            continue
        checked += 1
        hits = sorted(assigned.get(u["id"], []), key=lambda h: -h[0])
        if not hits or hits[0][0] < args.iou:
            if hits:
                near = f"best IoU {hits[0][0]:.2f} (tiled plane {hits[0][2]['id']})"
            else:  # the tiled plane that covers it most was assigned elsewhere (a joined plane)
                du, cu = raster["u", u["id"]]
                cover = [(len(cu & raster["t", t["id"]][1]) / max(1, len(cu)), t) for t in tiled
                         if coplanar(u, t, args)[0] and raster["t", t["id"]][0] == du]
                c, t = max(cover, key=lambda x: x[0], default=(0.0, None))
                near = (f"{100 * c:.0f} % of it lies in tiled plane {t['id']} "
                        f"({t['area']:.0f} m^2), which matches another untiled plane better"
                        if t and c > 0 else "no coplanar tiled plane on it")
            print(f"untiled plane {u['id']} ({u['kind']}, {u['area']:.0f} m^2): no tiled match, "
                  f"{near}")
            continue
        matched += 1
        pieces = [h for h in hits if h[1] >= args.split_cover]
        if len(pieces) > 1:
            split += 1
            print(f"untiled plane {u['id']} ({u['kind']}, {u['area']:.0f} m^2): split into "
                  f"{len(pieces)} tiled planes {[h[2]['id'] for h in pieces]}")
        best = hits[0]
        worst_angle = max(worst_angle, best[3])
        worst_offset = max(worst_offset, best[4])
        area_ratios.append(best[2]["area"] / u["area"])
        ious.append(best[0])
    summary = {
        "untiled_planes": len(untiled), "tiled_planes": len(tiled), "checked": checked,
        "matched": matched, "split": split, "worst_angle_deg": worst_angle,
        "worst_offset_m": worst_offset,
        "area_ratio_min": min(area_ratios, default=0.0),
        "area_ratio_median": sorted(area_ratios)[len(area_ratios) // 2] if area_ratios else 0.0,
        "iou_min": min(ious, default=0.0),
    }
    print(json.dumps(summary))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)
    return 0 if checked - matched <= args.allow_unmatched and split <= args.allow_split else 1


if __name__ == "__main__":
    sys.exit(main())
