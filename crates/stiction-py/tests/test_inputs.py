"""DataFrame, numpy and Series inputs, DatetimeIndex, models, and errors."""

import numpy as np
import pandas as pd
import pytest

import stiction


@pytest.fixture(scope="module")
def loop(sticky_csv):
    return pd.read_csv(sticky_csv)


def test_numpy_arrays_equal_dataframe(loop):
    a = stiction.diagnose(loop, sp="sp", quantify=False)
    b = stiction.diagnose(op=loop["op"].to_numpy(), pv=loop["pv"].to_numpy(), sp=loop["sp"].to_numpy(), ts=1.0, quantify=False)
    strip = lambda d: {k: v for k, v in d.items() if k != "seconds"}
    assert strip(a.to_dict()) == strip(b.to_dict())
    assert a.verdict == "stiction" and a.probability > 0.5 and a.why and all(a.why)


def test_datetime_index_gives_the_sampling_time(loop):
    df = loop.drop(columns="t")
    df.index = pd.date_range("2024-03-01 12:00", periods=len(df), freq="2s", tz="Europe/Berlin")
    d = stiction.diagnose(df, sp="sp", quantify=False)
    assert d.ts == 2.0
    # a Series with a DatetimeIndex as op= gives the time too
    s = stiction.diagnose(op=df["op"], pv=df["pv"].to_numpy(), quantify=False)
    assert s.ts == 2.0
    # a time column of datetimes, rows shuffled: sorted back, with a note
    df2 = df.reset_index(names="stamp").sample(frac=1.0, random_state=1)
    d2 = stiction.diagnose(df2, sp="sp", time="stamp", quantify=False)
    assert d2.ts == 2.0 and d2.verdict == d.verdict
    assert any("not in time order" in n for n in d2.notes)


def test_multiindex_columns_are_named_by_tuples(loop, tmp_path):
    # a frame pivoted by tag and signal has MultiIndex columns: a tuple names one
    df = loop.copy()
    df.columns = pd.MultiIndex.from_tuples([("FIC101", c) for c in df.columns])
    d = stiction.diagnose(df, op=("FIC101", "op"), pv=("FIC101", "pv"), sp=("FIC101", "sp"), time=("FIC101", "t"), quantify=False)
    a = stiction.diagnose(loop, sp="sp", quantify=False)
    assert (d.verdict, d.ts, list(d.analysed)) == (a.verdict, a.ts, list(a.analysed))
    with pytest.raises(stiction.StictionError, match="no column"):
        stiction.diagnose(df, op=("FIC102", "op"), pv=("FIC101", "pv"))
    page = stiction.report(df, op=("FIC101", "op"), pv=("FIC101", "pv"), path=tmp_path / "p.html", quantify=False)
    assert "FIC101 / op" in page.read_text()


def test_gaps_and_modes(loop):
    df = loop.copy()
    df["op"] = df["op"].astype(object)
    df.loc[5, "op"] = "Bad Input"
    df["mode"] = ["MAN" if k < 100 else "auto" for k in range(len(df))]
    d = stiction.diagnose(df, sp="sp", mode="mode", quantify=False)
    assert d.analysed[0] >= 100


def test_a_short_gap_is_bridged_not_a_split(loop):
    df = loop.copy()
    df["pv"] = df["pv"].astype(object)
    df.loc[300, "pv"] = "Bad Input"
    d = stiction.diagnose(df, sp="sp", quantify=False)
    assert list(d.analysed) == [0, len(df)]
    assert any("1 short gap (1 sample with a missing value) bridged" in w for w in d.warnings)
    q = stiction.quantify(df)
    assert any("1 short gap (1 sample with a missing value) bridged" in n for n in q.notes)
    assert q.params["d"] == pytest.approx(stiction.quantify(loop).params["d"], rel=0.05)


def test_a_merge_of_recorded_values_goes_on_a_grid(loop):
    # op stored at even seconds, pv at odd ones, as an outer join of two tags' recorded values
    df = loop.copy()
    df.loc[df.index % 2 == 1, "op"] = np.nan
    df.loc[(df.index % 2 == 0) & (df.index > 0), "pv"] = np.nan
    d = stiction.diagnose(df, sp="sp", quantify=False)
    assert any("stored at their own times" in n for n in d.notes), d.notes
    assert d.verdict == stiction.diagnose(loop, sp="sp", quantify=False).verdict


def test_models_and_simulate():
    op = np.sin(np.linspace(0, 20, 500))
    mv = stiction.Stenman(d=0.5).simulate(op)
    assert isinstance(mv, np.ndarray) and mv.shape == op.shape
    assert np.ptp(mv) < np.ptp(op)
    assert stiction.Kano(S=1.0, J=0.5).params == {"S": 1.0, "J": 0.5}
    assert repr(stiction.He(fs=1.0, fd=0.5)) == "He(fs=1, fd=0.5)"
    # a non-contiguous view is read too (copied once)
    np.testing.assert_array_equal(stiction.Choudhury(S=1, J=0.2).simulate(op[::2]), stiction.Choudhury(S=1, J=0.2).simulate(op[::2].copy()))
    df = stiction.simulate("stenman", "closed", d=2, samples=300)
    assert list(df.columns) == ["t", "sp", "op", "mv", "pv"] and len(df) == 300


def test_errors_name_the_column_and_the_fix(loop):
    with pytest.raises(ValueError, match=r"no column 'OP1' for the controller output op; the columns are t, sp, op, mv, pv"):
        stiction.diagnose(loop, op="OP1")
    df = loop.copy()
    df["pv"] = df["pv"].astype(object)
    df.loc[7, "pv"] = "12,5x"
    with pytest.raises(stiction.StictionError, match=r"row 7, column 'pv' \(process variable pv\): '12,5x' is not a number"):
        stiction.diagnose(df)
    with pytest.raises(ValueError, match=r"window=50: a window needs at least 200 samples"):
        stiction.diagnose(loop, window=50)
    with pytest.raises(ValueError, match=r"ts=-1: the sampling time must be a positive number"):
        stiction.diagnose(loop, ts=-1.0)
    with pytest.raises(ValueError, match=r"pv has 10 samples but op has 20"):
        stiction.diagnose(op=np.zeros(20), pv=np.zeros(10))
    with pytest.raises(ValueError, match=r"method='exact' solves the Stenman model only"):
        stiction.estimate(np.zeros(100), np.zeros(100), model="kano", method="exact")
    with pytest.raises(ValueError, match=r"unknown setting 'antz'"):
        stiction.estimate(np.zeros(100), np.zeros(100), antz=3)
    # a search setting out of range names the keyword the user typed (ACO_R's q is locality=)
    with pytest.raises(ValueError, match=r"^ants=0: ants must be at least 1$"):
        stiction.estimate(np.zeros(100), np.zeros(100), method="aco", ants=0)
    with pytest.raises(ValueError, match=r"^locality=0: locality must be "):
        stiction.estimate(np.zeros(100), np.zeros(100), model="kano", method="aco-r", locality=0.0)
    with pytest.raises(ValueError, match=r"^ants=0: ants must be at least 1$"):
        stiction.quantify(loop, method="aco", ants=0)
    with pytest.raises(ValueError, match=r"model Stenman needs params d=VALUE|needs params d"):
        stiction.simulate("stenman")
    df = loop.copy()
    df["mode"] = "sometimes"
    with pytest.raises(ValueError, match=r"row 0, column 'mode': 'sometimes' is not a controller mode"):
        stiction.diagnose(df, mode="mode")


def test_a_record_without_its_setpoint_has_the_setpoint_read_off():
    # a healthy PI loop whose setpoint stepped, judged without its sp column
    df = stiction.simulate(
        "stenman", "closed", d=0.0, noise=0.05, seed=3, samples=1500,
        sp="steps:amplitude=2,hold=300,offset=50,seed=1",
    )
    d = stiction.diagnose(df.drop(columns="sp"), quantify=False)
    read = d.setpoint_read_off
    assert read["steps"] and all(k % 300 <= 2 for k in read["steps"])
    assert len(read["levels"]) == len(read["steps"]) + 1
    assert any("setpoint steps read off the record" in w for w in d.warnings)
    # with the column given, nothing is read off
    assert "setpoint_read_off" not in stiction.diagnose(df, sp="sp", quantify=False).keys()
