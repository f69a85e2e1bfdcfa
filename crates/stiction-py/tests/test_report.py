"""stiction.report: the page of `stiction report`, from the same code, written to a file."""

import re
import subprocess

import numpy as np
import pandas as pd
import pytest

import stiction


def timeless(html):
    """The page without the times the runs took: the footer's diagnosis time and the estimate's
    time in the convergence table."""
    html = re.sub(r"diagnosis in [^<]* s</footer>", "diagnosis in (time) s</footer>", html)
    return re.sub(r'(<th scope="row">Time</th><td>)[^<]*(</td>)', r"\1(time)\2", html)


def test_report_writes_a_page_with_the_verdict(sticky_csv, tmp_path):
    path = tmp_path / "fic101.html"
    got = stiction.report(pd.read_csv(sticky_csv), sp="sp", path=path)
    assert got == path and path.is_file()
    html = path.read_text(encoding="utf-8")
    assert html.startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
    assert "<h1>fic101: stiction</h1>" in html
    assert '<span class="verdict-word">Stiction</span>' in html
    assert "Stiction band:" in html and "<svg" in html
    assert "Columns: OP <code>op</code>, PV <code>pv</code>, SP <code>sp</code>" in html
    assert not list(tmp_path.glob(".*.tmp")), "no temporary file is left"


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (["--sp", "sp"], dict(sp="sp")),
        (["--sp", "sp", "--window", "500", "--no-quantify"], dict(sp="sp", window=500, quantify=False)),
    ],
    ids=["sticky", "healthy-windows"],
)
def test_report_equals_the_cli_page(cli, sticky_csv, healthy_csv, tmp_path, flags, kwargs):
    csv = sticky_csv if "window" not in kwargs else healthy_csv
    theirs = tmp_path / "cli.html"
    subprocess.run([cli, "report", str(csv), *flags, "-o", str(theirs)], check=True, capture_output=True)
    ours = stiction.report(pd.read_csv(csv), path=tmp_path / "py.html", name=str(csv), **kwargs)
    want = theirs.read_text(encoding="utf-8")
    got = ours.read_text(encoding="utf-8")
    assert timeless(got) == timeless(want)
    assert ("Verdict per window" in got) == ("window" in kwargs)


def test_report_from_arrays_without_column_names(tmp_path):
    df = stiction.simulate("stenman", "closed", d=0.0, noise=0.05, seed=4, samples=800)
    path = stiction.report(op=df["op"].to_numpy(), pv=df["pv"].to_numpy(), ts=1.0, path=str(tmp_path / "a.html"))
    html = path.read_text(encoding="utf-8")
    assert "<h1>a: " in html and "Columns:" not in html


def test_report_bad_input_is_one_sentence(sticky_csv, tmp_path):
    df = pd.read_csv(sticky_csv)
    with pytest.raises(stiction.StictionError, match=r"path= is required"):
        stiction.report(df)
    with pytest.raises(ValueError, match=r"the folder '.*nowhere' does not exist"):
        stiction.report(df, path=tmp_path / "nowhere" / "x.html")
    with pytest.raises(ValueError, match=r"is a folder"):
        stiction.report(df, path=tmp_path)
    with pytest.raises(ValueError, match=r"no column 'OP1' for the controller output op"):
        stiction.report(df, op="OP1", path=tmp_path / "x.html")
    with pytest.raises(ValueError, match=r"window=50: a window needs at least"):
        stiction.report(df, window=50, path=tmp_path / "x.html")
    with pytest.raises(ValueError, match=r"ts=-1"):
        stiction.report(op=np.ones(500), pv=np.ones(500), ts=-1, path=tmp_path / "x.html")
    assert not (tmp_path / "x.html").exists()


def test_report_says_how_the_record_was_read(sticky_csv, tmp_path):
    # op stored at even seconds, pv at odd ones: put on a grid, and the page says so
    df = pd.read_csv(sticky_csv)
    df.loc[df.index % 2 == 1, "op"] = np.nan
    df.loc[(df.index % 2 == 0) & (df.index > 0), "pv"] = np.nan
    path = tmp_path / "merged.html"
    stiction.report(df, sp="sp", path=path, quantify=False)
    html = path.read_text(encoding="utf-8")
    assert "How the record was read:" in html
    assert "stored at their own times" in html
