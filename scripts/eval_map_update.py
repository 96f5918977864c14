#!/usr/bin/env python3
"""Scores `planeloc run --map-update` files against a simulated world's change labels (issue 32).

Each plane of planes.json (extracted from the mapping-time LiDAR map) is matched to the GT plane
of the simulator's planes_gt.json whose normal agrees within --angle degrees, whose outline's
bounding box (grown by 1 m) holds the plane's centroid, and whose plane passes nearest to that
centroid (within --max-distance metres). Its label is that GT plane's `change` (unchanged, moved
by offset_m, removed), or `none` (no GT plane: a car, a kerb). Its true offset is where the GT
plane is now, seen from the extracted plane at its centroid c along its normal n (points now sit
at +offset): -(n_gt . c + d_gt - offset_m) / (n_gt . n); for an unchanged plane that is the
extraction's own error.

Per updates file it prints, and writes with --json:
  - moved planes seen over at least --min-span frames (first to last frame seen): how many the
    run called corrected (recall) and, of all corrected planes, how many are moved (precision);
  - the median |offset - true offset| of the corrected moved planes;
  - false alarms, per km driven (--poses: the GT poses of the run's frames): planes within
    --right metres of the world (true offset) called corrected, and planes not removed called
    contradicted.

  scripts/eval_map_update.py --planes planes.json --gt planes_gt.json --updates u.json [...]
                             [--poses poses.txt] [--json out.json]
"""
import argparse
import json
import math
import statistics
import sys


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def match(plane, gt_planes, angle_deg, max_distance):
    """The GT plane `plane` is (mapping time), or None."""
    n = plane["normal"]
    c = plane["centroid"]
    best, best_distance = None, max_distance
    for gt in gt_planes:
        if abs(dot(n, gt["normal"])) < math.cos(math.radians(angle_deg)):
            continue
        polygon = gt.get("polygon") or []
        if polygon:
            lo = [min(p[i] for p in polygon) - 1.0 for i in range(3)]
            hi = [max(p[i] for p in polygon) + 1.0 for i in range(3)]
            if any(c[i] < lo[i] or c[i] > hi[i] for i in range(3)):
                continue
        distance = abs(dot(gt["normal"], c) + gt["d"])
        if distance < best_distance:
            best, best_distance = gt, distance
    return best


def path_length_km(poses_path):
    positions = []
    with open(poses_path) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            if len(v) == 12:
                positions.append((v[3], v[7], v[11]))
    return sum(math.dist(a, b) for a, b in zip(positions, positions[1:])) / 1000.0


def score(updates, labels, km, min_span, right):
    moved_seen, moved_detected, corrected, corrected_moved = 0, 0, 0, 0
    errors, false_alarms, contradicted_removed = [], [], 0
    for entry in updates["planes"]:
        label, true_offset = labels.get(entry["id"], ("none", 0.0))
        frames = entry["frames"]
        span = frames[-1] - frames[0] + 1 if frames else 0
        status = entry["status"]
        if label == "moved" and span >= min_span:
            moved_seen += 1
            moved_detected += status == "corrected"
        if status == "corrected":
            corrected += 1
            if label == "moved":
                corrected_moved += 1
                errors.append(abs(entry["offset"] - true_offset))
        if label in ("unchanged", "moved"):
            wrong_correction = status == "corrected" and abs(true_offset) < right
            if wrong_correction or (status == "contradicted" and label != "removed"):
                false_alarms.append(entry["id"])
        if label == "removed" and status == "contradicted":
            contradicted_removed += 1
    return {
        "moved_seen": moved_seen,
        "moved_detected": moved_detected,
        "recall": moved_detected / moved_seen if moved_seen else None,
        "corrected": corrected,
        "corrected_moved": corrected_moved,
        "precision": corrected_moved / corrected if corrected else None,
        "median_offset_error_m": statistics.median(errors) if errors else None,
        "false_alarms": false_alarms,
        "false_alarms_per_km": len(false_alarms) / km if km else None,
        "removed_contradicted": contradicted_removed,
        "statuses": {s: sum(e["status"] == s for e in updates["planes"])
                     for s in ("unseen", "confirmed", "corrected", "contradicted")},
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--planes", required=True)
    parser.add_argument("--gt", required=True)
    parser.add_argument("--updates", required=True, nargs="+")
    parser.add_argument("--poses")
    parser.add_argument("--angle", type=float, default=5.0)
    parser.add_argument("--max-distance", type=float, default=0.3)
    parser.add_argument("--min-span", type=int, default=20)
    parser.add_argument("--right", type=float, default=0.05)
    parser.add_argument("--json")
    args = parser.parse_args()
    planes = json.load(open(args.planes))["planes"]
    gt_planes = json.load(open(args.gt))["planes"]
    labels = {}
    for plane in planes:
        gt = match(plane, gt_planes, args.angle, args.max_distance)
        if gt is None:
            continue
        change = gt.get("change", "unchanged")
        d_now = gt["d"] - (gt.get("offset_m", 0.0) if change == "moved" else 0.0)
        offset = -(dot(gt["normal"], plane["centroid"]) + d_now) / dot(gt["normal"], plane["normal"])
        labels[plane["id"]] = (change, offset)
    km = path_length_km(args.poses) if args.poses else None
    results = {}
    for path in args.updates:
        result = score(json.load(open(path)), labels, km, args.min_span, args.right)
        results[path] = result
        print(f"{path}: moved seen {result['moved_seen']}, detected {result['moved_detected']}"
              f" (recall {result['recall']}), corrected {result['corrected']} of which moved "
              f"{result['corrected_moved']} (precision {result['precision']}), median offset "
              f"error {result['median_offset_error_m']} m, false alarms "
              f"{len(result['false_alarms'])} ({result['false_alarms_per_km']} per km), "
              f"statuses {result['statuses']}")
    label_counts = {}
    for change, _ in labels.values():
        label_counts[change] = label_counts.get(change, 0) + 1
    print(f"labels of the {len(planes)} planes: {label_counts}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"labels": label_counts, "km": km, "runs": results}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
