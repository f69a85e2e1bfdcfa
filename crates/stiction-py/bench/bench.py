"""Benchmark: stiction.diagnose_many beside `stiction batch` and a Python loop over the CLI.

    python crates/stiction-py/bench/bench.py --loops 1000 --samples 2000 --threads 2 \
        --cli target/release/stiction [--cli-loops 50] [--spark 10000]

Simulates LOOPS closed loops (Stenman valves with bands 0 to 4 % of span, PV noise, some with
an external disturbance), writes each as a CSV file for `stiction batch` and the CLI loop, and
times, with the same thread count:
  - stiction.diagnose_many on the long DataFrame (GIL released, rayon pool of THREADS);
  - `stiction batch DIR -o OUT --threads THREADS --sp sp` on the files;
  - a Python loop calling `stiction diagnose FILE --sp sp --json` per loop (CLI_LOOPS of them,
    scaled to LOOPS);
  - optionally stiction.spark.diagnose on a local SparkSession (local[THREADS]) on SPARK loops
    (the simulated loops repeated under new ids).
Prints a Markdown table (loops per second and the time for LOOPS loops).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
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


def bench_spark(frame: pd.DataFrame, loops: int, threads: int) -> tuple[float, int]:
    from pyspark.sql import SparkSession

    from stiction import spark as stiction_spark

    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    spark = (
        SparkSession.builder.master(f"local[{threads}]")
        .appName("stiction-bench")
        .config("spark.sql.shuffle.partitions", str(max(2, threads * 4)))
        .config("spark.ui.enabled", "false")
        .config("spark.sql.execution.arrow.pyspark.enabled", "true")
        .config("spark.driver.memory", "4g")
        .getOrCreate()
    )
    spark.sparkContext.setLogLevel("ERROR")
    base = frame["loop_id"].unique()
    reps = -(-loops // len(base))
    big = pd.concat(
        [frame.assign(loop_id=frame["loop_id"] + f"_{r}") for r in range(reps)], ignore_index=True
    )
    keep = sorted(big["loop_id"].unique())[:loops]
    big = big[big["loop_id"].isin(set(keep))]
    sdf = spark.createDataFrame(big).repartition(threads * 4, "loop_id").cache()
    sdf.count()
    secs, n = timed(lambda: stiction_spark.diagnose(sdf, sp="sp").count())
    spark.stop()
    return secs, n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--loops", type=int, default=1000)
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cli", default=os.environ.get("STICTION_BIN", "target/release/stiction"))
    ap.add_argument("--cli-loops", type=int, default=50)
    ap.add_argument("--spark", type=int, default=0, help="loops for the Spark run (0: skip)")
    a = ap.parse_args()

    secs, frame = timed(lambda: fleet(a.loops, a.samples))
    print(f"simulated {a.loops} loops x {a.samples} samples in {secs:.1f} s", file=sys.stderr)
    work = Path(tempfile.mkdtemp(prefix="stiction-bench-"))
    files = work / "loops"
    files.mkdir()
    for loop_id, g in frame.groupby("loop_id", sort=False):
        g.drop(columns="loop_id").to_csv(files / f"{loop_id}.csv", index=False)
    rows = []

    t_many, many = timed(lambda: stiction.diagnose_many(frame, sp="sp", threads=a.threads, progress=False))
    rows.append(("stiction.diagnose_many (DataFrame)", a.loops, t_many))

    out = work / "batch"
    cmd = [a.cli, "batch", str(files), "-o", str(out), "--threads", str(a.threads), "--sp", "sp"]
    t_batch, done = timed(lambda: subprocess.run(cmd, capture_output=True, text=True))
    if done.returncode not in (0, 3):
        sys.exit(f"batch failed: {done.stderr}")
    rows.append(("stiction batch (CSV files)", a.loops, t_batch))

    subset = sorted(files.glob("*.csv"))[: a.cli_loops]

    def cli_loop():
        for f in subset:
            json.loads(subprocess.run([a.cli, "diagnose", str(f), "--sp", "sp", "--json"], capture_output=True, text=True, check=True).stdout)

    t_cli, _ = timed(cli_loop)
    rows.append((f"Python loop over `stiction diagnose --json` ({len(subset)} loops, scaled)", len(subset), t_cli))

    if a.spark:
        t_spark, n = bench_spark(frame, a.spark, a.threads)
        rows.append((f"stiction.spark.diagnose, local[{a.threads}]", n, t_spark))

    # the same answers: diagnose_many's rows against batch's summary
    summary = pd.read_csv(out / "summary.csv")
    same = (summary.set_index("loop_id")["verdict"].sort_index() == many.set_index("loop_id")["verdict"].sort_index()).all()

    print(f"\n{a.loops} loops x {a.samples} samples, {a.threads} threads, {os.cpu_count()} cores; verdicts of diagnose_many and batch identical: {same}\n")
    print("| how | loops timed | seconds | loops/s | time for %d loops | vs batch |" % a.loops)
    print("|---|---:|---:|---:|---:|---:|")
    for name, n, s in rows:
        per = s / n
        print(f"| {name} | {n} | {s:.1f} | {n / s:.1f} | {per * a.loops:.1f} s | {per * a.loops / t_batch:.2f}x |")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
