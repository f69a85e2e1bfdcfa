"""The trees' trainer (crates/stiction-lab/scripts/train_combined.py) beside the trees it wrote:
its placeholder, which lets the build report a changed list of statistics to train on, reads the
list the embedded trees read, and never decides."""

import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[3]
FOREST = ROOT / "crates/stiction-core/src/diagnose/combined/forest.json"
TRAINER = ROOT / "crates/stiction-lab/scripts/train_combined.py"


def test_the_placeholder_reads_the_statistics_the_embedded_trees_read(tmp_path):
    out = tmp_path / "forest.json"
    run = subprocess.run(
        [sys.executable, str(TRAINER), "--placeholder", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    placeholder = json.loads(out.read_text())
    embedded = json.loads(FOREST.read_text())
    assert placeholder["features"] == embedded["features"]
    # one leaf far below the threshold: it never turns a verdict
    assert placeholder["trees"] == [[[0, 0.0, 0, 0, 0.0]]]
    assert 1 / (1 + 2.718281828 ** -placeholder["baseline"]) < placeholder["threshold"]
