"""The section "The default start (issue 30)" of docs/benchmarks.md, from the maplock.json of
scripts/bench_run.py (rows of scripts/bench_map_lock.py): per drive, the default prior given the
exact start pose against the exact start itself and VO; per drive with draws, the runs from start
poses drawn from the prior; every applied correction against its 3-sigma gate and the planes a
clean map had disabled.

scripts/bench_report.py includes it in the full page. Run alone with --splice, it replaces this
section of an existing docs/benchmarks.md from the maplock.json of `scripts/bench_run.py
--only-map-lock [PRESETS]` (which carries its own run), so that issue 30's benchmark can be
measured without the hours of the full bench.
"""
import sys

from bench_format import code, num, run_tag, splice_report_main, table

TITLE = "## The default start (issue 30)"

EXACT_BOUND = 1.1  # default prior from the exact start / exact start, all frames
AFTER_LOCK_BOUND = 1.1  # a draw after its lock / the exact start on the same frames


def bound_cell(value, bound):
    if value is None:
        return "—"
    text = f"{value:.2f}"
    return text if value <= bound else f"**{text}**"


def yes_no(condition):
    return "yes" if condition else "**no**"


def exact_start(rows, tag):
    """Rows of the exact-start table and a sentence counting the drives within the bounds."""
    out = []
    within = below_vo = 0
    for r in rows:
        ratio = r["ate_all_frames_m"] / r["ate_exact_start_m"]
        within += ratio <= EXACT_BOUND
        below_vo += r["ate_all_frames_m"] <= r["ate_vo_m"]
        out.append([f"{r['preset']} {r['seed']}", num(r["ate_vo_m"], 4),
                    num(r["ate_exact_start_m"], 4), num(r["ate_all_frames_m"], 4),
                    bound_cell(ratio, EXACT_BOUND), yes_no(r["ate_all_frames_m"] <= r["ate_vo_m"]),
                    r.get("final_lock") or "—",
                    f"{r['corrections'] - r['corrections_beyond_3sigma']} / {r['corrections']}",
                    str(r["max_planes_disabled"]), tag])
    summary = (f"Within {EXACT_BOUND}× of the exact start on {within} of {len(rows)} drives; "
               f"at or below VO on {below_vo} of {len(rows)}.")
    return out, summary


def draws(rows, tag):
    """Rows of the draws table, one per drive with draws."""
    out = []
    by_drive = {}
    for r in rows:
        by_drive.setdefault((r["preset"], r["seed"]), []).append(r)
    for (preset, seed), runs in sorted(by_drive.items()):
        ok = [r for r in runs if r["rc"] == 0]
        locked = [r for r in ok if r.get("lock_frame") is not None]
        ratios = [r["ate_after_lock_m"] / r["ate_exact_start_same_frames_m"] for r in locked]
        above_vo = sum(1 for r in ok if r["ate_all_frames_m"] > r["ate_vo_all_frames_m"])
        # Rows from before --out-final have no final ATE.
        final = [r for r in ok if r.get("ate_all_frames_final_m") is not None]
        above_vo_final = (str(sum(1 for r in final
                                  if r["ate_all_frames_final_m"] > r["ate_vo_all_frames_m"]))
                          if final else "—")
        mean = (lambda xs: sum(xs) / len(xs) if xs else None)
        out.append([
            f"{preset} {seed}", str(len(runs)), f"{len(locked)} / {len(runs)}",
            str(sum(1 for r in ok if r.get("wrong_lock"))),
            num(mean([r["ate_after_lock_m"] for r in locked]), 4),
            num(mean([r["ate_exact_start_same_frames_m"] for r in locked]), 4),
            bound_cell(max(ratios) if ratios else None, AFTER_LOCK_BOUND),
            str(sum(1 for x in ratios if x > AFTER_LOCK_BOUND)), str(above_vo),
            num(mean([r["ate_all_frames_final_m"] for r in final]), 4), above_vo_final,
            f"{sum(r['corrections'] - r['corrections_beyond_3sigma'] for r in ok)} / "
            f"{sum(r['corrections'] for r in ok)}",
            str(sum(1 for r in ok if r["max_planes_disabled"] > 0)), tag])
    return out


def section(data, tag):
    lock = data["map_lock"]
    exact_rows = [r for r in lock["rows"] if r["draw"] == "exact" and r["rc"] == 0]
    draw_rows = [r for r in lock["rows"] if r["draw"] != "exact"]
    failed = [r for r in lock["rows"] if r["rc"] != 0]
    exact_table, exact_summary = exact_start(exact_rows, tag)
    parts = [
        f"{TITLE}\n\n"
        "`planeloc run --planes` with its default prior `--init-sigma \"2 0.5 5\"`, by "
        f"{code('scripts/bench_map_lock.py --exact-start')} on each drive (`--deterministic`, "
        "ATE RMSE without alignment, metres). A registration is applied restricted to the DoF "
        "it observes, fused with the current pose and gated at 3σ "
        "([map-registration.md](map-registration.md)). Seeds 41, 43 and 47 are used by no test "
        "and no tuning.\n\n"
        "**Given the exact start pose.** *default prior*: the run with the default prior from the "
        "exact GT pose; *exact*: the same with `--init-sigma \"0 0 0\"` (plane constraints from "
        f"frame 0); bound: *default prior / exact* ≤ {EXACT_BOUND} (bold above). *corrections "
        "within 3σ*: applied corrections whose every registered DoF lies within 3 innovation "
        "sigmas, from the run's stats. *planes disabled*: the most disabled at once (the map is "
        "clean: each is a correct plane).\n\n"
        + table(["drive", "VO", "exact", "default prior", "default prior / exact", "at or below VO",
                 "lock at the end", "corrections within 3σ", "planes disabled", "measured"],
                exact_table) + "\n\n" + exact_summary]
    if draw_rows:
        parts.append(
            f"**Start poses drawn from the prior** ({lock.get('draws_per_seed', '?')} per drive, "
            "seeded). *after the lock*: ATE from the first full lock to the end, mean over the "
            "draws that locked; *exact, same frames*: the exact start on those frames; *worst "
            f"ratio*: the worst draw's ratio of the two (bound {AFTER_LOCK_BOUND}); *above VO*: "
            "draws whose ATE over all frames is above VO's, with `--out` (each frame as tracked: "
            "before the lock in the prior's frame) and with `--out-final` (the frames before the "
            "lock re-expressed by its correction; *all frames, final*: its mean ATE).\n\n"
            + table(["drive", "draws", "locked", "wrong locks", "after the lock",
                     "exact, same frames", "worst ratio", f"draws above {AFTER_LOCK_BOUND}×",
                     "above VO", "all frames, final", "above VO, final",
                     "corrections within 3σ", "runs with planes disabled",
                     "measured"], draws(draw_rows, tag)))
    if lock.get("presets_left_out"):
        parts.append("Not in this run: the drives of " + ", ".join(
            f"`{p}`" for p in lock["presets_left_out"]) + " (`scripts/bench_run.py "
            "--only-map-lock` with a list of presets).")
    if failed:
        parts.append("Failed runs: " + ", ".join(
            f"{r['preset']} {r['seed']} draw {r['draw']} (exit {r['rc']})" for r in failed) + ".")
    return "\n\n".join(parts)


def main():
    def alone(results):
        return section({"map_lock": results}, run_tag(results["meta"]))

    return splice_report_main(__doc__.split("\n\n")[0], "maplock.json",
                              "bench_run.py --only-map-lock", TITLE, alone, "default start")


if __name__ == "__main__":
    sys.exit(main())
