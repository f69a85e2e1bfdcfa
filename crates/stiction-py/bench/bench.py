"""Benchmark: stiction.diagnose_many beside `stiction batch` and a Python loop over the CLI.

    python crates/stiction-py/bench/bench.py --loops 1000 --samples 2000 --threads 2 \
        --cli target/release/stiction [--cli-loops 0] [--rounds 1] \
        [--spark 10000 [--spark-samples 2000]]

Simulates LOOPS closed loops (Stenman valves with bands 0 to 4 % of span, PV noise, some with
an external disturbance) into one long DataFrame, writes each loop as a CSV file for `stiction
batch` (not timed: a batch user has the files), and times, with the same thread count THREADS:
  - stiction.diagnose_many on the long DataFrame (GIL released, rayon pool of THREADS);
  - `stiction batch DIR -o OUT --threads THREADS --sp sp` on the files;
  - a Python loop over the same DataFrame, one loop after the other: write the loop's CSV, run
    `stiction diagnose FILE --sp sp --json` (RAYON_NUM_THREADS=THREADS, as the pool of the other
    two), parse the JSON. CLI_LOOPS of them (0: all), scaled to LOOPS.
ROUNDS > 1 runs the three in turn that many times (the machine's load then weighs on each
alike) and reports each one's median. The release build of the wheel and of the CLI is the fair
comparison (`pip install ./crates/stiction-py`, `cargo build --release -p stiction-cli`).

--spark N: stiction.spark.diagnose on N loops (of SPARK_SAMPLES samples) on a local SparkSession
(local[THREADS]) beside `stiction batch` on the same loops (one long-format CSV), and what Spark
costs per loop: a run with a no-op function in place of the diagnosis (grouping, Arrow, the
Python workers, task scheduling) and, inside the function, the time of diagnose_many and of the
diagnosis itself. See spark_bench.py.
Prints Markdown tables (loops per second, the time for LOOPS loops, the ratio to batch).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

import stiction


def fleet(loops: int, samples: int) -> pd.DataFrame:
    parts = []
    for k in range(loops):
        d = [0.0, 0.5, 1.0, 2.0, 4.0][k % 5]
        dist = "sine:amplitude=0.5,period=80" if k % 7 == 3 else None
        df = stiction.simulate("stenman", "closed", d=d, noise=0.05, seed=k + 1, samples=samples, disturbance=dist)
        df.insert(0, "loop_id", f"L{k:05d}")
        parts.append(df)
    return pd.concat(parts, ignore_index=True)


def timed(f):
    t0 = time.perf_counter()
    out = f()
    return time.perf_counter() - t0, out


def run_batch(cli: str, inputs: Path, out: Path, threads: int) -> float:
    """`stiction batch` on a folder or a long-format file: its wall time."""
    shutil.rmtree(out, ignore_errors=True)
    cmd = [cli, "batch", str(inputs), "-o", str(out), "--threads", str(threads), "--sp", "sp"]
    secs, done = timed(lambda: subprocess.run(cmd, capture_output=True, text=True))
    if done.returncode not in (0, 3):
        sys.exit(f"batch failed: {done.stderr}")
    return secs


def cli_loop(cli: str, frame: pd.DataFrame, ids: list, scratch: Path, threads: int) -> list:
    """What a Python user without the package does: per loop, sequentially, write its CSV, run
    `stiction diagnose FILE --json`, parse. Returns the verdicts."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    wanted = set(ids)
    verdicts = []
    for loop_id, g in frame.groupby("loop_id", sort=False):
        if loop_id not in wanted:
            continue
        path = scratch / f"{loop_id}.csv"
        g.drop(columns="loop_id").to_csv(path, index=False)
        out = subprocess.run([cli, "diagnose", str(path), "--sp", "sp", "--json"], capture_output=True, text=True, check=True, env=env)
        verdicts.append(json.loads(out.stdout)["verdict"])
        path.unlink()
    return verdicts


def table(rows: list, loops: int, t_batch: float) -> None:
    print("| how | loops timed | seconds | loops/s | time for %d loops | vs batch |" % loops)
    print("|---|---:|---:|---:|---:|---:|")
    for name, n, s in rows:
        per = s / n
        print(f"| {name} | {n} | {s:.1f} | {n / s:.1f} | {per * loops:.1f} s | {per * loops / t_batch:.2f}x |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--loops", type=int, default=1000)
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cli", default=os.environ.get("STICTION_BIN", "target/release/stiction"))
    ap.add_argument("--cli-loops", type=int, default=0, help="loops of the CLI loop (0: all)")
    ap.add_argument("--rounds", type=int, default=1, help="run the three in turn this many times; medians")
    ap.add_argument("--spark", type=int, default=0, help="loops for the Spark run (0: skip)")
    ap.add_argument("--spark-samples", type=int, default=0, help="samples per Spark loop (default: --samples)")
    a = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="stiction-bench-"))
    try:
        if a.loops:
            bench_fleet(a, work)
        if a.spark:
            import spark_bench

            spark_bench.run(a, work, fleet, run_batch, table)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def bench_fleet(a: argparse.Namespace, work: Path) -> None:
    secs, frame = timed(lambda: fleet(a.loops, a.samples))
    print(f"simulated {a.loops} loops x {a.samples} samples in {secs:.1f} s", file=sys.stderr)
    files = work / "loops"
    files.mkdir()
    for loop_id, g in frame.groupby("loop_id", sort=False):
        g.drop(columns="loop_id").to_csv(files / f"{loop_id}.csv", index=False)
    scratch = work / "cli"
    scratch.mkdir()
    ids = sorted(frame["loop_id"].unique())
    subset = ids if a.cli_loops <= 0 else ids[:: max(1, len(ids) // a.cli_loops)][: a.cli_loops]
    times = {"many": [], "batch": [], "cli": []}
    for r in range(a.rounds):
        t, many = timed(lambda: stiction.diagnose_many(frame, sp="sp", threads=a.threads, progress=False))
        times["many"].append(t)
        times["batch"].append(run_batch(a.cli, files, work / "batch", a.threads))
        t, cli_verdicts = timed(lambda: cli_loop(a.cli, frame, subset, scratch, a.threads))
        times["cli"].append(t)
        print(f"round {r + 1}: diagnose_many {times['many'][-1]:.1f} s, batch {times['batch'][-1]:.1f} s, "
              f"CLI loop {t:.1f} s ({len(subset)} loops)", file=sys.stderr)
    med = {k: statistics.median(v) for k, v in times.items()}
    # the same answers: diagnose_many's rows against batch's summary and the CLI's JSON
    summary = pd.read_csv(work / "batch" / "summary.csv").set_index("loop_id")["verdict"].sort_index()
    ours = many.set_index("loop_id")["verdict"].sort_index()
    same = bool((summary == ours).all()) and list(ours.loc[subset]) == cli_verdicts
    rows = [
        ("stiction.diagnose_many (one long DataFrame)", a.loops, med["many"]),
        ("stiction batch (a CSV file per loop)", a.loops, med["batch"]),
        (f"Python loop: write CSV, `stiction diagnose FILE --json`, parse ({len(subset)} loops)", len(subset), med["cli"]),
    ]
    load = os.getloadavg()
    print(f"\n{a.loops} loops x {a.samples} samples, {a.threads} threads, {os.cpu_count()} cores, "
          f"{a.rounds} round(s) (medians); load average {load[0]:.1f}; verdicts identical in all three: {same}")
    per_round = [f"{m / b:.2f}x / {c * a.loops / len(subset) / m:.1f}x"
                 for m, b, c in zip(times["many"], times["batch"], times["cli"])]
    print("diagnose_many vs batch / CLI loop vs diagnose_many, per round: " + ", ".join(per_round) + "\n")
    table(rows, a.loops, med["batch"])


if __name__ == "__main__":
    main()
