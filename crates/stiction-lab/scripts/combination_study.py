#!/usr/bin/env python3
"""Could a learned combination of the families' statistics replace the verdict's rules?

An opt-in study (not part of the tests; needs numpy and scikit-learn). It reads the JSON lines
of the plant benchmark and of the diagnose benchmark, trains a logistic regression and gradient
boosted trees on the statistics every family reports (the model family's test ratio, gain and
fits, the stick-slip episodes, the shape indices, the loop family's lag, gain, distance and
residual, the oscillation, the compression share), on further calibration draws of the
catalogue, and judges them where the rules are judged: the catalogue's calibration and benchmark
sets (other seeds), the ISDB's 14 loops and the 108-loop oscillating set. Results in
crates/stiction-lab/journal/accuracy-history.md ("A learned combination of the families' statistics").

    D=/tmp/combination; mkdir -p $D
    cargo build --release -p stiction-lab --examples
    B=target/release/examples
    for s in routine fast; do
      for n in 1 2 3 4 5 6; do $B/plant_benchmark --set $s --extra $n --out $D/x.md --jsonl $D/$s-extra$n.jsonl; done
      $B/plant_benchmark --set $s --calibration --out $D/x.md --jsonl $D/$s-calibration.jsonl
      $B/plant_benchmark --set $s --out $D/x.md --jsonl $D/$s-benchmark.jsonl
    done
    $B/diagnose_benchmark --out $D/x.md --jsonl $D/diagnose.jsonl     # needs ../shared/data/isdb
    python3 -m venv $D/venv && $D/venv/bin/pip install numpy scikit-learn
    $D/venv/bin/python crates/stiction-lab/scripts/combination_study.py $D
"""

import collections
import json
import math
import sys

import numpy as np
from sklearn.ensemble import GradientBoostingClassifier
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

VOTE = {"stiction": 1, "no_stiction": -1, "undetermined": 0}
# statistics that mark how the catalogue was built rather than how valves behave: only its
# healthy look-alikes have a compressed PV or OP steps the controller did not make
CATALOGUE_MARKS = ("compressed_share", "unprovoked_op_steps")


def num(x, default=0.0):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default


def log1(x):
    return math.log1p(max(num(x), 0.0))


def family(d, name):
    return next((f for f in d["families"] if f["family"] == name), {})


def statistics(d):
    """The families' statistics of one diagnosis, by name (no verdict among them)."""
    s = {}
    m = family(d, "model")
    me = m.get("model") or {}
    r2 = num(me.get("r2_without_stiction"))
    s |= {
        "model_vote": VOTE[m.get("vote", "undetermined")] * num(m.get("strength")),
        "model_log_ratio": log1(me.get("significance")),
        "model_improvement": num(me.get("improvement")),
        "model_explained": num(me.get("explained")),
        "model_r2": r2,
        "model_stenman_gain": num(me.get("r2_stenman")) - r2,
        "model_slip_gain": num(me.get("r2_slip_jump")) - r2,
        "model_noise_share": num(me.get("noise_share")),
        "model_log_band": log1(me.get("stenman_d_percent_of_span")),
        "unprovoked_op_steps": num((me.get("unprovoked_op_steps") or {}).get("share")),
        "model_log_span": log1(me.get("correlation_span")),
        "model_fitted": 1.0 if me else 0.0,
    }
    t = family(d, "stick_slip")
    te = t.get("stick_slip") or {}
    s |= {
        "stick_vote": VOTE[t.get("vote", "undetermined")] * num(t.get("strength")),
        "stick_log_episodes": log1(te.get("episodes")),
        "stick_stuck_share": num(te.get("stuck_share")),
        "stick_log_travel": log1(num(te.get("median_travel")) / max(num(te.get("op_noise"), 1.0), 1e-9)),
        "stick_log_slow": log1(te.get("skipped_slow")),
        "stick_log_direction": log1(te.get("skipped_direction")),
        "stick_log_quiet": log1(te.get("quiet_stretches")),
    }
    h = family(d, "shape")
    s |= {
        "shape_vote": VOTE[h.get("vote", "undetermined")] * num(h.get("strength")),
        "shape_value": num(h.get("value")),
    }
    indices = {i["name"]: i for i in d.get("indices") or []}
    for name in ("cross_correlation", "curve_fitting", "harmonics", "shape"):
        s[f"index_{name}"] = num((indices.get(name) or {}).get("value"))
    lp = family(d, "loop")
    le = lp.get("limit_cycle") or {}
    s |= {
        "loop_vote": VOTE[lp.get("vote", "undetermined")] * num(lp.get("strength")),
        "loop_lag": num(le.get("needed_lag_degrees")) / 90.0,
        "loop_gain": min(num(le.get("needed_gain"), 1.0), 5.0),
        "loop_distance": min(num((le.get("describing") or {}).get("distance"), 5.0), 5.0),
        "loop_residual": num(le.get("residual_share"), 1.0),
        "loop_harmonics": num(le.get("harmonics")),
        "loop_gain_margin": min(num((le.get("margins") or {}).get("gain_margin"), 5.0), 5.0),
        "loop_measured": 1.0 if le else 0.0,
    }
    o = d.get("oscillation") or {}
    s |= {
        "oscillating": 1.0 if o.get("oscillating") else 0.0,
        "log_regularity": log1((o.get("regularity") or {}).get("regularity")),
        "cycle_share": num(o.get("cycle_share")),
    }
    gates = {g["gate"]: g for g in d.get("quality") or []}
    s["compressed_share"] = num((gates.get("pv_compressed") or {}).get("value"))
    return s


def read(path, truth_of):
    rows = [json.loads(line) for line in open(path)]
    rows = [r for r in rows if truth_of(r) is not None]
    return rows, np.array([truth_of(r) for r in rows])


def catalogue_truth(r):
    return {"sticky": 1, "not_sticky": 0}.get(r["truth"])


def matrix(rows, names):
    return np.array([[statistics(r["diagnosis"])[n] for n in names] for r in rows])


def tie_break(r, p, hi=0.7, lo=0.3):
    """The rules' verdict, an `undetermined` one decided where the combination is sure."""
    v = r["diagnosis"]["verdict"]
    if v != "undetermined":
        return v
    if p >= hi:
        return "stiction"
    if p <= lo and not any(f["vote"] == "stiction" for f in r["diagnosis"]["families"]):
        return "no_stiction"
    return v


def catalogue_cells(rows, y, verdicts):
    sticky = np.mean([v == "stiction" for v, t in zip(verdicts, y) if t == 1])
    healthy = np.mean([v == "no_stiction" for v, t in zip(verdicts, y) if t == 0])
    by_class = collections.defaultdict(list)
    for r, v, t in zip(rows, verdicts, y):
        if t == 0:
            by_class[r["class"]].append(v != "stiction")
    worst = min((np.mean(ok), c) for c, ok in by_class.items())
    return f"{0.5 * (sticky + healthy):.3f} ({100 * sticky:.0f} %, {worst[1]} {100 * worst[0]:.0f} %)"


def main(folder):
    sets = {}
    for suite in ("routine", "fast"):
        for name in ("calibration", "benchmark"):
            sets[(suite, name)] = read(f"{folder}/{suite}-{name}.jsonl", catalogue_truth)
    diagnose = [json.loads(line) for line in open(f"{folder}/diagnose.jsonl")]
    train = [r for s in ("routine", "fast") for n in range(1, 7)
             for r in read(f"{folder}/{s}-extra{n}.jsonl", catalogue_truth)[0]]
    y_train = np.array([catalogue_truth(r) for r in train])
    every = list(statistics(train[0]["diagnosis"]).keys())
    unmarked = [n for n in every if n not in CATALOGUE_MARKS]

    def logistic():
        return make_pipeline(StandardScaler(), LogisticRegression(C=1.0, max_iter=3000))

    def trees():
        return GradientBoostingClassifier(max_depth=3, n_estimators=200, random_state=1)

    print(f"Trained on {len(train)} loops (routine and fast, calibration draws 1-6).\n")
    print("| verdict | routine calibration set | routine benchmark set | fast calibration set | fast benchmark set | ISDB right | 108-loop set right |")
    print("|---|---|---|---|---|---|---|")
    plans = [("the rules (today's `diagnose`)", None, None, False)]
    plans += [(f"{kind}, {which}", make, names, False)
              for which, names in (("every statistic", every), ("without the catalogue's marks", unmarked))
              for kind, make in (("logistic regression", logistic), ("gradient boosted trees", trees))]
    plans += [("the rules, `undetermined` decided by the logistic regression without the marks (0.7 / 0.3)", logistic, unmarked, True)]
    for label, make, names, tie in plans:
        model = None
        if make is not None:
            model = make().fit(matrix(train, names), y_train)

        def verdicts(rows):
            if model is None:
                return [r["diagnosis"]["verdict"] for r in rows]
            p = model.predict_proba(matrix(rows, names))[:, 1]
            if tie:
                return [tie_break(r, q) for r, q in zip(rows, p)]
            return ["stiction" if q >= 0.5 else "no_stiction" for q in p]

        cells = [catalogue_cells(rows, y, verdicts(rows)) for rows, y in sets.values()]
        for subset in ("isdb", "oscillating"):
            rows = [r for r in diagnose if r["set"] == subset]
            right = sum((v == "stiction") == r["truth"] and v != "undetermined"
                        for r, v in zip(rows, verdicts(rows)))
            cells.append(f"{right} of {len(rows)}")
        print(f"| {label} | " + " | ".join(cells) + " |")
    print("\nCells: balanced accuracy (sticky valves called `stiction`, the look-alike class least often "
          "not called `stiction`).")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/combination")
