"""The section "A map that can be wrong (issue 10)" of docs/benchmarks.md, from the
robustness.json of scripts/bench_run.py: per drive, ATE with the plane map, wrong copies of it,
the oracle map, maps from noisy poses (as they are and refined) and no map, against the issue's
bound; and the ablation of the association's settings against the defaults.
"""
import statistics

from bench_format import cell, code, ratio, table

# Issue 10 item 5: (kind in robustness.json, column title). The moved and rotated maps are the
# localizer's test (against the clean map, the oracle map and VO); the map from noisy poses is the
# map side's (its remedy is `map refine-poses`: *refined*) and is reported on its own.
WRONG_MAP_COLUMNS = [("vo", "VO"), ("clean", "clean"), ("move0.1", "moved 0.1 m"),
                     ("move0.2", "moved 0.2 m"), ("move0.3", "moved 0.3 m"),
                     ("rot2", "rotated 2°"), ("oracle", "oracle")]
WRONG_MAPS = ("move0.1", "move0.2", "move0.3", "rot2")
WRONG_MAP_BOUND = 1.5  # worst wrong map / clean map


def bound_cell(value):
    text = f"{value:.2f}"
    return text if value <= WRONG_MAP_BOUND else f"**{text}**"


# Maps from noisy poses: (kind, title in the summary), reported when the results have them.
NOISY_MAPS = [("noisy", "not refined"), ("refined", "refined by `map refine-poses`")]


def noisy_kinds(data):
    return [k for k, _ in NOISY_MAPS if k in data["robustness"]["kinds"]]


def wrong_maps(data, tag):
    """Rows of the wrong-map table and a sentence counting the drives within the bounds."""
    rows = []
    within = below_vo = 0
    noisy = noisy_kinds(data)
    noisy_within = dict.fromkeys(noisy, 0)
    noisy_below_vo = dict.fromkeys(noisy, 0)
    records = data["robustness"]["wrong_maps"]
    for r in records:
        ate = r["ate3d_m"]
        worst = max(ate[k] for k in WRONG_MAPS)
        to_clean = worst / ate["clean"]
        within += to_clean <= WRONG_MAP_BOUND
        all_below = all(ate[k] < ate["vo"] for k in WRONG_MAPS + ("clean",))
        below_vo += all_below
        noisy_cells = []
        for k in noisy:
            noisy_within[k] += ate[k] / ate["clean"] <= WRONG_MAP_BOUND
            noisy_below_vo[k] += ate[k] < ate["vo"]
            noisy_cells += [f"{ate[k]:.4f}", bound_cell(ate[k] / ate["clean"]),
                            "yes" if ate[k] < ate["vo"] else "**no**"]
        rows.append([f"`{r['preset']}` seed {r['seed']} ({r['frames']} frames, "
                     f"{r['path_m']:.0f} m)"]
                    + [f"{ate[k]:.4f}" for k, _ in WRONG_MAP_COLUMNS]
                    + [bound_cell(to_clean), ratio(worst, ate["oracle"]),
                       "yes" if all_below else "**no**"]
                    + noisy_cells + [code(r["command"]), tag])
    n = len(records)
    summary = (f"Moved or rotated planes, worst / clean ≤ {WRONG_MAP_BOUND}: {within} of {n} "
               f"drives; clean and wrong maps all below VO: {below_vo} of {n}.")
    for k, title in NOISY_MAPS:
        if k in noisy:
            summary += (f" Map from noisy poses, {title}: ≤ {WRONG_MAP_BOUND}× clean on "
                        f"{noisy_within[k]} of {n}, below VO on {noisy_below_vo[k]} of {n}.")
    return rows, summary


def noisy_header(data):
    titles = {"noisy": "noisy poses", "refined": "refined"}
    header = []
    for k in noisy_kinds(data):
        header += [titles[k], f"{titles[k]} / clean", f"{titles[k]} below VO"]
    return header


def ablation(data, tag):
    abl = data["robustness"]["ablation"]
    means = {v["name"]: {k: statistics.fmean(v["ate3d_m"][k]) for k in abl["kinds"]}
             for v in abl["variants"]}
    default = means.get("default")
    rows = []
    for v in abl["variants"]:
        row = [v["name"], cell("; ".join(v["settings"]) or "(defaults)")]
        for k in abl["kinds"]:
            row.append(" / ".join(f"{x:.4f}" for x in v["ate3d_m"][k]))
            row.append(f"{means[v['name']][k]:.4f}")
            row.append(ratio(means[v["name"]][k], default[k]) if default else "—")
        rows.append(row + [tag])
    return rows


def section(data, tag):
    """The section's Markdown (data["robustness"] must be set)."""
    rob = data["robustness"]
    rows, summary = wrong_maps(data, tag)
    abl = rob["ablation"]
    kind_titles = dict(WRONG_MAP_COLUMNS)
    abl_header = ["variant", "settings (beside the defaults)"]
    for k in abl["kinds"]:
        title = kind_titles.get(k, k)
        abl_header += [f"{title}: per seed (m)", f"{title}: mean (m)",
                       f"{title}: / default"]
    return (
        "## A map that can be wrong (issue 10)\n\n"
        "ATE RMSE 3-D (m), no alignment, `planeloc run --deterministic` from the exact first "
        "pose (`--init-sigma \"0 0 0\"`), one run per cell, by "
        "`scripts/bench_wrong_map.sh`. The wrong maps (`scripts/corrupt_planes.py`): 20 % of "
        "the planes the tracker uses moved by 0.1, 0.2 or 0.3 m along their normal, or "
        "rotated by 2°; *noisy poses*: the LiDAR map built from poses with 5 cm / 0.2° noise "
        "(`scripts/noisy_poses.py`). *oracle*: the clean map without the planes the wrong "
        "maps corrupt, what a tracker that disabled exactly the wrong planes from the first "
        "frame would reach. Worst: the largest of the four moved or rotated maps; the issue's "
        f"bound is worst / clean ≤ {WRONG_MAP_BOUND} and every plane map below VO, for the "
        "wrong maps and for the noisy one. The noisy map's planes are themselves wrong "
        "(single-scan layers, tilted ground pieces); its remedy is on the map side, "
        "`planeloc map refine-poses` before `map build` (*refined*; pose graph of scan-to-scan "
        "ICP with the noisy poses as priors). One run scatters "
        "by about ±10 % (±25 % on `small` seed 13): the draws over jittered copies of the "
        "maps are in [experiments.md](experiments.md). `small` seeds 3, 11 and 21 tuned the "
        "association; 7, 13 and 29 did not (7 and 13 were diagnosed), nor did any `tiny` "
        "seed here.\n\n" + summary + "\n\n"
        + table(["drive"] + [title for _, title in WRONG_MAP_COLUMNS]
                + ["worst / clean", "worst / oracle", "all below VO"] + noisy_header(data)
                + ["command", "measured"],
                rows)
        + "\n\n### Ablation\n\n"
        f"Each variant changes one setting from the defaults (`scripts/bench_ablation.sh`), "
        f"`{abl['preset']}` seeds {', '.join(map(str, abl['seeds']))}, same maps as above "
        "(moved 0.2 m: 20 % of the planes). Command: " + code(abl["command"]) + ".\n\n"
        + table(abl_header + ["measured"], ablation(data, tag)))
