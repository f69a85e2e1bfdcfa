"""diagnose_many: one ranked row per loop, a failing loop as a row, the same for any thread count."""

import pandas as pd

import stiction


def test_rows_ranked_and_a_failing_loop(fleet):
    out = stiction.diagnose_many(fleet, by="loop_id", sp="sp", threads=2, progress=False)
    assert list(out.columns) == stiction.MANY_COLUMNS
    assert (out["same_period_loops"] >= 0).all()
    assert sorted(out["loop_id"]) == ["FIC101", "FIC102", "LIC201", "TIC301"]
    failed = out[out["verdict"] == "failed"]
    assert list(failed["loop_id"]) == ["TIC301"]
    assert "column 'op'" in failed["reason"].iloc[0] and "'abc' is not a number" in failed["reason"].iloc[0]
    assert out["verdict"].iloc[-1] == "failed"
    # ranked: severity never increases
    assert list(out["severity"]) == sorted(out["severity"], reverse=True)
    # a row equals the single diagnosis of that loop
    one = fleet[fleet["loop_id"] == "FIC101"]
    d = stiction.diagnose(one, sp="sp")
    row = out.set_index("loop_id").loc["FIC101"]
    assert row["verdict"] == d.verdict and row["probability"] == d.probability
    # the reason column: the diagnosis's reasons in words
    assert row["reason"] == "; ".join(d.why)
    assert row["band_percent_of_span"] == d.band_percent
    # the record's small band, from its OP noise, as the diagnosis reports it
    assert row["small_band_percent_of_span"] == d.reach["small_band_percent_of_span"] > 0


def test_the_same_for_any_thread_count(fleet):
    one = stiction.diagnose_many(fleet, sp="sp", threads=1, progress=False).drop(columns="seconds")
    two = stiction.diagnose_many(fleet, sp="sp", threads=2, progress=False).drop(columns="seconds")
    pd.testing.assert_frame_equal(one, two)


def test_numeric_loop_ids_stay_numbers(fleet):
    f = fleet[fleet["loop_id"] != "TIC301"].copy()
    f["unit"] = f["loop_id"].map({"FIC101": 101, "FIC102": 102, "LIC201": 201})
    out = stiction.diagnose_many(f, by="unit", sp="sp", quantify=False, progress=False)
    assert sorted(out["loop_id"]) == [101, 102, 201]


def test_loops_at_one_period_count_each_other(fleet):
    # the sticky loop twice under two ids (one cycle seen in two loops), and the healthy one
    one = fleet[fleet["loop_id"] == "FIC101"]
    twice = pd.concat([one, one.assign(loop_id="FIC101b")], ignore_index=True)
    out = stiction.diagnose_many(twice, sp="sp", quantify=False, progress=False).set_index("loop_id")
    assert out.loc["FIC101", "same_period_loops"] == 1
    assert out.loc["FIC101b", "same_period_loops"] == 1
    alone = stiction.diagnose_many(one, sp="sp", quantify=False, progress=False)
    assert list(alone["same_period_loops"]) == [0]
