"""to_dict() equals the CLI's --json on the same file (the `seconds` a run took aside)."""

import json
import subprocess

import numpy as np
import pandas as pd

import stiction


def run_json(cli, *args):
    out = subprocess.run([cli, *map(str, args), "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def without_seconds(d):
    """The result without the times the runs took (`seconds`, at any depth)."""
    if isinstance(d, dict):
        return {k: without_seconds(v) for k, v in d.items() if k != "seconds"}
    if isinstance(d, list):
        return [without_seconds(v) for v in d]
    return d


def test_diagnose_equals_cli(cli, sticky_csv):
    want = run_json(cli, "diagnose", sticky_csv, "--sp", "sp")
    got = stiction.diagnose(pd.read_csv(sticky_csv), sp="sp")
    assert list(got.to_dict()) == list(want), "the same keys in the same order"
    assert without_seconds(got.to_dict()) == without_seconds(want)
    assert got.verdict == "stiction"
    assert 1.5 < got.band["band_percent_of_span"] < 2.5
    # P, the reasons and the next step, typed and in the CLI's words
    assert 0.0 < got.probability <= 1.0
    assert got.why and all(got.why) and got.why == [r["text"] for r in want["reasons"]]
    assert all(r["kind"] for r in got.reasons)
    assert got.next_step["action"] == "travel_test" and got.next_step["text"]
    read = got.statistics_frame()
    assert list(read.columns) == ["statistic", "value", "contribution"] and len(read) > 0
    assert f"P {got.probability:.2f}" in repr(got)


def test_diagnose_healthy_equals_cli_with_windows(cli, healthy_csv):
    want = run_json(cli, "diagnose", healthy_csv, "--sp", "sp", "--window", "500", "--no-quantify")
    got = stiction.diagnose(pd.read_csv(healthy_csv), sp="sp", window=500, quantify=False)
    assert without_seconds(got.to_dict()) == without_seconds(want)
    assert got.verdict == "no_stiction"
    w = got.windows
    assert len(w) == 3 and "probability" in w.columns and "reasons" in w.columns
    assert all(r["text"] for reasons in w["reasons"] for r in reasons)
    assert abs(got.reach["large_band_percent_of_span"] - 3 * got.reach["small_band_percent_of_span"]) < 1e-9
    assert len(got.windows) == len(want["windows"]) == 3
    assert list(got.windows["verdict"]) == [w["verdict"] for w in want["windows"]]


def test_quantify_equals_cli(cli, sticky_csv):
    want = run_json(cli, "quantify", sticky_csv)
    got = stiction.quantify(pd.read_csv(sticky_csv))
    assert without_seconds(got.to_dict()) == without_seconds(want)
    assert got.status == "ok"


def test_estimate_and_simulate_equal_cli(cli, tmp_path):
    path = tmp_path / "open.csv"
    subprocess.run(
        [cli, "simulate", "--model", "stenman", "--param", "d=0.5", "--noise", "0.01", "--seed", "2", "-o", path],
        check=True, capture_output=True,
    )
    ours = stiction.simulate("stenman", d=0.5, noise=0.01, seed=2)
    theirs = pd.read_csv(path)
    for c in ("t", "op", "mv"):
        np.testing.assert_array_equal(ours[c].to_numpy(), theirs[c].to_numpy())
    for method in ("exact", "aco"):
        want = run_json(cli, "estimate", path, "--method", method, "--seed", "3")
        got = stiction.estimate(theirs["op"], theirs["mv"], method=method, seed=3)
        assert without_seconds(got.to_dict()) == without_seconds(want), method


def test_thorough_equals_cli(cli, tmp_path):
    """thorough=True runs the hidden-valve family, as --thorough does; the words are the CLI's."""
    f = tmp_path / "steps.csv"
    subprocess.run(
        [cli, "simulate", "--loop", "closed", "--param", "d=2", "--samples", "1500", "--noise", "0.05",
         "--seed", "3", "--sp", "steps:amplitude=4,hold=200,offset=50,seed=2", "--pi", "Kc=0.3,Ti=20",
         "-o", str(f)],
        check=True, capture_output=True,
    )
    want = run_json(cli, "diagnose", f, "--sp", "sp", "--thorough", "--no-quantify")
    got = stiction.diagnose(pd.read_csv(f), sp="sp", quantify=False, thorough=True)
    assert without_seconds(got.to_dict()) == without_seconds(want)
    assert any(x["family"] == "hidden_valve" for x in want["families"])
    plain = stiction.diagnose(pd.read_csv(f), sp="sp", quantify=False)
    assert not any(x["family"] == "hidden_valve" for x in plain.to_dict()["families"])
