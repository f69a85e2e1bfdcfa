"""The Spark part of bench.py (``--spark N``): stiction.spark.diagnose on a local SparkSession
beside `stiction batch` on the same loops, and where Spark's time per loop goes, measured.

Runs, on N simulated loops (a Parquet file for Spark, one long-format CSV for batch; writing
them is not timed, nor is loading and caching the Spark DataFrame):
  1. `stiction batch fleet.csv --threads THREADS --sp sp`;
  2. ``stiction.spark.diagnose(sdf, sp="sp").count()`` on local[THREADS] (ranked, as users run it);
  3. the same ``groupBy("loop_id").applyInPandas`` with a function that returns one row without
     diagnosing: what Spark costs without the diagnosis (the shuffle, Arrow both ways, pandas,
     the Python workers, task scheduling);
  4. the same again with diagnose_many inside, timed inside the function: per loop the time in
     diagnose_many and the diagnosis' own time (``seconds``), and per Python worker the gaps
     between one call's end and the next call's start (Arrow to pandas and back, the exchange
     with the JVM, waiting for the next task);
  5. in this process, Arrow's conversion of a loop's rows to pandas and of a row back.
"""

from __future__ import annotations

import os
import sys
import time

import pandas as pd

import stiction


def _timed(f):
    t0 = time.perf_counter()
    out = f()
    return time.perf_counter() - t0, out


def session(threads: int):
    from pyspark.sql import SparkSession

    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    spark = (
        SparkSession.builder.master(f"local[{threads}]")
        .appName("stiction-bench")
        .config("spark.sql.shuffle.partitions", str(max(2, threads * 4)))
        .config("spark.ui.enabled", "false")
        .config("spark.sql.execution.arrow.pyspark.enabled", "true")
        .config("spark.driver.memory", "6g")
        .getOrCreate()
    )
    spark.sparkContext.setLogLevel("ERROR")
    return spark


def noop(pdf: pd.DataFrame) -> pd.DataFrame:
    return pd.DataFrame({"loop_id": [pdf["loop_id"].iloc[0]], "rows": [len(pdf)]})


def instrumented(pdf: pd.DataFrame) -> pd.DataFrame:
    start = time.time()
    t0 = time.perf_counter()
    rows = stiction.diagnose_many(pdf, by="loop_id", sp="sp", threads=1, progress=False)
    took = time.perf_counter() - t0
    return pd.DataFrame({
        "loop_id": rows["loop_id"], "verdict": rows["verdict"], "native_s": rows["seconds"],
        "udf_s": [took], "start": [start], "end": [time.time()], "pid": [os.getpid()],
    })


def arrow_per_loop(frame: pd.DataFrame, loops: int = 200) -> tuple[float, float]:
    """Seconds per loop: its rows from Arrow to pandas and the one-row result back, as the
    Python worker does for applyInPandas (measured here on LOOPS loops)."""
    import pyarrow as pa

    groups = [g for _, g in frame.groupby("loop_id", sort=False)][:loops]
    batches = [pa.RecordBatch.from_pandas(g, preserve_index=False) for g in groups]
    t_in, _ = _timed(lambda: [b.to_pandas() for b in batches])
    row = stiction.diagnose_many(groups[0], sp="sp", progress=False)
    t_out, _ = _timed(lambda: [pa.RecordBatch.from_pandas(row, preserve_index=False) for _ in batches])
    return t_in / len(batches), t_out / len(batches)


def worker_gaps(parts: pd.DataFrame) -> float:
    """Seconds a Python worker spent between one call of the function and the next, in all."""
    total = 0.0
    for _, p in parts.sort_values("start").groupby("pid"):
        total += float((p["start"].to_numpy()[1:] - p["end"].to_numpy()[:-1]).sum())
    return total


def run(a, work, fleet, run_batch, table) -> None:
    from pyspark import cloudpickle

    from stiction import spark as stiction_spark

    # noop and instrumented go to the Python workers by value: this module is not importable there
    cloudpickle.register_pickle_by_value(sys.modules[__name__])

    n, samples, threads = a.spark, a.spark_samples or a.samples, a.threads
    secs, frame = _timed(lambda: fleet(n, samples))
    print(f"spark: simulated {n} loops x {samples} samples in {secs:.1f} s", file=sys.stderr)
    parquet, long_csv = work / "fleet.parquet", work / "fleet.csv"
    frame.to_parquet(parquet, index=False)
    frame.to_csv(long_csv, index=False)
    t_batch = run_batch(a.cli, long_csv, work / "batch-spark", threads)
    print(f"spark: batch {t_batch:.1f} s", file=sys.stderr)

    spark = session(threads)
    sdf = spark.read.parquet(str(parquet)).repartition(threads * 4, "loop_id").cache()
    t_load, _ = _timed(sdf.count)
    t_spark, rows = _timed(lambda: stiction_spark.diagnose(sdf, sp="sp").count())
    print(f"spark: load {t_load:.1f} s, stiction.spark.diagnose {t_spark:.1f} s", file=sys.stderr)
    grouped = sdf.groupBy("loop_id")
    t_noop, _ = _timed(lambda: grouped.applyInPandas(noop, schema="loop_id string, rows long").count())
    schema = ("loop_id string, verdict string, native_s double, udf_s double, start double, "
              "end double, pid long")
    t_inst, parts = _timed(lambda: grouped.applyInPandas(instrumented, schema=schema).toPandas())
    spark.stop()
    arrow_in, arrow_out = arrow_per_loop(frame)

    table([
        (f"stiction.spark.diagnose, local[{threads}] (ranked)", rows, t_spark),
        ("stiction batch (one long-format CSV)", n, t_batch),
        (f"Spark with a no-op function in place of the diagnosis, local[{threads}]", n, t_noop),
        (f"Spark with diagnose_many timed inside, local[{threads}]", n, t_inst),
    ], n, t_batch)
    ms = lambda s: f"{1000 * s:.2f} ms"  # noqa: E731
    per = lambda s: s * threads / n  # noqa: E731  wall seconds x threads, per loop
    native, udf = parts["native_s"].mean(), parts["udf_s"].mean()
    gaps = worker_gaps(parts) / n
    print(f"\nper loop, in core time (wall x {threads} / {n} loops; {samples} samples a loop):")
    print(f"- stiction.spark.diagnose: {ms(per(t_spark))}; batch: {ms(per(t_batch))}")
    print(f"- Spark without the diagnosis (no-op function): {ms(per(t_noop))}")
    print(f"- instrumented run: {ms(per(t_inst))}, of which")
    print(f"  - the diagnosis (Rust, `seconds`): {ms(native)}")
    print(f"  - diagnose_many around it (pandas to numpy, the row back to pandas): {ms(udf - native)}")
    print(f"  - the Python worker between calls (Arrow to pandas and back, the JVM exchange, waiting): {ms(gaps)}")
    print(f"  - the rest (JVM: shuffle read, Arrow batches, scheduling; idle cores): {ms(per(t_inst) - udf - gaps)}")
    print(f"- Arrow alone, measured in this process: {ms(arrow_in)} a loop's rows to pandas, {ms(arrow_out)} the row back")
    print(f"- loading and caching the {n} loops in Spark (not in the figures above): {t_load:.1f} s")
    print(f"- Python workers used: {parts['pid'].nunique()}; verdicts as batch's: "
          f"{same_verdicts(parts, work / 'batch-spark' / 'summary.csv')}")


def same_verdicts(parts: pd.DataFrame, summary_csv) -> bool:
    summary = pd.read_csv(summary_csv).set_index("loop_id")["verdict"].sort_index()
    ours = parts.set_index("loop_id")["verdict"].sort_index()
    return bool(len(summary) == len(ours) and (summary == ours).all())
