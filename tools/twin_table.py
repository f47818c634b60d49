#!/usr/bin/env python3
"""The OptiOdom twin table from scripts/twin_optiodom.sh's outputs (OUT/<day>_<training set>/twin.json).

Per training run: the effects named (value +- std, and which std; with more than one named, also their joint refit's
values +- marginal std), the twin's mean 10 s motion-capture drift on its own held-out part and on each held-out run,
nominal -> patched (ratio). Per day: every candidate's first-round fit on each training run (value +- std) and the
largest normalized spread |a - b| / sqrt(sa^2 + sb^2) over the pairs of runs, for the named effects as their rounds
fitted them ("named"), as the joint refit gives them ("joint": the joint values and marginal std where the run names
more than one effect, else the round's), and for all the candidates. A diagnosis fitted on a set of training runs
(`--train-with`, twin.json's training_runs) gives each further training run's own third after the first's, and no
spread (its runs share one fit).

    python3 tools/twin_table.py OUT_DIR
"""
import itertools
import json
import math
import pathlib
import sys


def drift(comparison):
    d = comparison.get("drift", {}).get("mocap")
    return d["mean_position_m"] if d else None


def ratio_text(before, after):
    if before is None or after is None:
        return "(no drift)"
    return f"{1000 * before:.1f} -> {1000 * after:.1f} mm ({after / before:.2f})"


def value_text(name, value, std):
    return f"{name} {value:.5g} +- {std:.2g}"


def effect_text(effect):
    return "; ".join(
        value_text(f"{effect['name']} {k}", v, effect["std"].get(k, math.nan))
        for k, v in effect["parameters"].items() if k in effect["std"])


def spreads(fits):
    """fits: run -> (value, std); the largest normalized spread over the pairs."""
    worst = None
    for (a, (va, sa)), (b, (vb, sb)) in itertools.combinations(sorted(fits.items()), 2):
        s = abs(va - vb) / math.hypot(sa, sb) if sa > 0 or sb > 0 else math.inf
        worst = s if worst is None else max(worst, s)
    return worst


def main(out):
    runs = sorted(p for p in pathlib.Path(out).glob("*_*/twin.json"))
    if not runs:
        print(f"twin_table.py: {out}: no */twin.json", file=sys.stderr)
        return 2
    days = {}
    ratios = {}
    print("| day, training run (run-01) | named (value +- std) | own third | held out |")
    print("|---|---|---|---|")
    for path in runs:
        day, training = path.parent.name.rsplit("_", 1)
        twin = json.loads(path.read_text())
        named = " / ".join(effect_text(e) for e in twin["effects"]) or "(none)"
        joint = (twin.get("joint") or {}).get("effects") or []
        if joint:
            named += "; joint: " + " / ".join(effect_text(e) for e in joint)
        own = ratio_text(drift(twin["heldout"]["before"]), drift(twin["heldout"]["after"]))
        for t in twin.get("training_runs", []):
            own += (f"; {pathlib.Path(t['recording']).name.split('_')[0]}: "
                    + ratio_text(drift(t["heldout"]["before"]), drift(t["heldout"]["after"])))
        held = "; ".join(
            f"{pathlib.Path(h['recording']).name.split('_')[0]}: "
            + ratio_text(drift(h["before"]), drift(h["after"])) for h in twin["heldout_runs"])
        print(f"| {day}, {training} | {named} ({twin['std_method']} std) | {own} | {held} |")
        for h in twin["heldout_runs"]:
            before, after = drift(h["before"]), drift(h["after"])
            if before and after is not None:
                ratios.setdefault(day, []).append(after / before)
        if "training_runs" in twin:
            continue
        day_fits = days.setdefault(day, {"named": {}, "joint": {}, "candidates": {}})
        for kind, effects in (("named", twin["effects"]), ("joint", joint or twin["effects"]),
                              ("candidates", twin["candidates"])):
            for e in effects:
                for k, v in e["parameters"].items():
                    if k in e.get("std", {}) and v is not None:
                        day_fits[kind].setdefault(f"{e['name']} {k}", {})[training] = (v, e["std"][k])
    for day, values in ratios.items():
        met = sum(r <= 0.5 for r in values)
        print(f"\n{day}: held-out drift ratio patched / nominal {min(values):.2f}-{max(values):.2f}; "
              f"{met} of {len(values)} at most 0.5")
    for day, fits in days.items():
        print(f"\n{day}: normalized spread between the runs |a - b| / sqrt(sa^2 + sb^2)")
        for kind in ("named", "joint", "candidates"):
            for parameter, values in sorted(fits[kind].items()):
                if len(values) < 2:
                    continue
                listed = ", ".join(f"{v:.5g} +- {s:.2g}" for _, (v, s) in sorted(values.items()))
                print(f"  {kind}: {parameter}: {listed}; spread {spreads(values):.2f}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0)
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
