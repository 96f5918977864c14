#!/usr/bin/env python3
"""Makes a wrong plane map from planes.json: a seeded random fraction of the planes is moved along
its normal or rotated about its centroid (issue 10's "a map that can be wrong" benchmark).

  corrupt_planes.py IN.json OUT.json --seed 1 --fraction 0.2 --move 0.2
  corrupt_planes.py IN.json OUT.json --seed 1 --fraction 0.2 --rotate-deg 2
  corrupt_planes.py IN.json OUT.json --seed 1 --jitter 0.0005
  corrupt_planes.py IN.json OUT.json --seed 1 --fraction 0.2 --remove

Only planes with area >= --min-area (the tracker's Planes.minPlaneArea, 8 m^2) are candidates,
so the fraction is of the planes the tracker uses. Each chosen plane moves by +-move metres
(random sign) along its normal, polygon and centroid with it; or turns by rotate-deg about a
random in-plane axis through its centroid. The chosen ids go to stderr. python3 + json only.
--jitter S moves every plane by a Gaussian offset of sigma S metres along its normal instead: with
S = 0.5 mm the map is the same to any measurement, but the tracker's run is not (it is chaotic in
its map), so runs over a few such draws give the scatter of a single run (bench_wrong_map.sh
--draws).
--remove drops the planes that --move or --rotate-deg would corrupt (the same seed and fraction
choose the same planes): the "oracle" map, what a tracker that knew exactly which planes are wrong
and disabled them from the start would use. Its ATE is the best that disabling wrong planes can
reach, the reference for the wrong-map bound.
"""
import argparse
import json
import math
import random
import sys


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def normalized(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def rotate(v, axis, angle):
    """Rodrigues: v turned by angle (rad) about the unit axis."""
    c, s = math.cos(angle), math.sin(angle)
    k_x_v = cross(axis, v)
    k_d_v = dot(axis, v)
    return [v[i] * c + k_x_v[i] * s + axis[i] * k_d_v * (1 - c) for i in range(3)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--fraction", type=float, default=0.2)
    parser.add_argument("--move", type=float, default=0.0, help="metres along the normal")
    parser.add_argument("--rotate-deg", type=float, default=0.0)
    parser.add_argument("--min-area", type=float, default=8.0)
    parser.add_argument("--jitter", type=float, default=0.0,
                        help="metres: every plane moved by N(0, jitter) along its normal")
    parser.add_argument("--remove", action="store_true",
                        help="drop the chosen planes instead of corrupting them (oracle map)")
    args = parser.parse_args()
    if sum(x != 0.0 for x in (args.move, args.rotate_deg, args.jitter)) + args.remove != 1:
        parser.error("give exactly one of --move, --rotate-deg, --jitter and --remove")
    with open(args.input) as f:
        document = json.load(f)
    planes = document["planes"]
    if args.jitter:
        rng = random.Random(args.seed)
        for p in planes:
            shift = rng.gauss(0.0, args.jitter)
            n = normalized(p["normal"])
            p["d"] = p["d"] - shift
            move = [shift * x for x in n]
            if "centroid" in p:
                p["centroid"] = [p["centroid"][k] + move[k] for k in range(3)]
            p["polygon"] = [[q[k] + move[k] for k in range(3)] for q in p.get("polygon", [])]
        document.setdefault("stats", {})["jittered"] = {"seed": args.seed, "sigma": args.jitter}
        with open(args.output, "w") as f:
            json.dump(document, f, indent=1)
        return 0
    candidates = [i for i, p in enumerate(planes) if p.get("area", 0.0) >= args.min_area]
    rng = random.Random(args.seed)
    count = max(1, round(args.fraction * len(candidates)))
    chosen = sorted(rng.sample(candidates, count))
    if args.remove:
        ids = [planes[i]["id"] for i in chosen]
        document["planes"] = [p for i, p in enumerate(planes) if i not in set(chosen)]
        document.setdefault("stats", {})["removed"] = {
            "seed": args.seed, "fraction": args.fraction, "ids": ids}
        print(f"planes {ids} removed", file=sys.stderr)
        with open(args.output, "w") as f:
            json.dump(document, f, indent=1)
        return 0
    for i in chosen:
        p = planes[i]
        n = normalized(p["normal"])
        c = p.get("centroid", [-p["d"] * x for x in n])
        if args.move:
            shift = args.move * rng.choice([-1.0, 1.0])
            p["d"] = p["d"] - shift
            move = [shift * x for x in n]
            p["centroid"] = [c[k] + move[k] for k in range(3)]
            p["polygon"] = [[q[k] + move[k] for k in range(3)] for q in p.get("polygon", [])]
            what = f"moved {shift:+.2f} m"
        else:
            helper = [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0]
            u = normalized(cross(n, helper))
            v = cross(n, u)
            phi = rng.uniform(0.0, 2.0 * math.pi)
            axis = [math.cos(phi) * u[k] + math.sin(phi) * v[k] for k in range(3)]
            angle = math.radians(args.rotate_deg)
            n2 = normalized(rotate(n, axis, angle))
            p["normal"] = n2
            p["d"] = -dot(n2, c)
            p["polygon"] = [
                [c[k] + r[k] for k in range(3)]
                for r in (rotate([q[k] - c[k] for k in range(3)], axis, angle)
                          for q in p.get("polygon", []))
            ]
            # The map's uncertainty axes turn with the plane (the reader requires the major axis
            # to lie in the plane).
            sigma = p.get("sigma")
            if sigma and "major_axis" in sigma:
                sigma["major_axis"] = normalized(rotate(sigma["major_axis"], axis, angle))
            what = f"rotated {args.rotate_deg:.1f} deg"
        print(f"plane {p['id']} ({p.get('kind', '')}, {p.get('area', 0):.0f} m^2) {what}",
              file=sys.stderr)
    document.setdefault("stats", {})["corrupted"] = {
        "seed": args.seed, "fraction": args.fraction, "move": args.move,
        "rotate_deg": args.rotate_deg, "ids": [planes[i]["id"] for i in chosen]}
    with open(args.output, "w") as f:
        json.dump(document, f, indent=1)


if __name__ == "__main__":
    main()
