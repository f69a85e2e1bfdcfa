"""stiction.spark.diagnose on a local SparkSession: the same rows as diagnose_many."""

import os
import shutil
import sys

import pandas as pd
import pytest

import stiction


def spark_or_skip():
    try:
        import pyspark  # noqa: F401
        import pyarrow  # noqa: F401
    except ImportError as e:
        pytest.skip(f"pyspark with pyarrow is not installed ({e}); pip install pyspark pyarrow to run the Spark test")
    if shutil.which("java") is None and not os.environ.get("JAVA_HOME"):
        pytest.skip("no Java (java on PATH or JAVA_HOME): Spark needs a JVM")
    from pyspark.sql import SparkSession

    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    os.environ.setdefault("PYSPARK_DRIVER_PYTHON", sys.executable)
    return (
        SparkSession.builder.master("local[2]")
        .appName("stiction-test")
        .config("spark.sql.shuffle.partitions", "2")
        .config("spark.ui.enabled", "false")
        .getOrCreate()
    )


def test_spark_equals_diagnose_many(fleet):
    spark = spark_or_skip()
    small = fleet[fleet["loop_id"] != "TIC301"].copy()
    small["op"] = small["op"].astype(float)
    sdf = spark.createDataFrame(small)
    from stiction import spark as stiction_spark

    got = stiction_spark.diagnose(sdf, by="loop_id", sp="sp", quantify=False).toPandas()
    want = stiction.diagnose_many(small, by="loop_id", sp="sp", quantify=False, progress=False)
    # Spark judges each loop apart: no loop to share a period with, so no such column
    want = want[stiction.FLEET_COLUMNS]
    assert list(got.columns) == stiction.FLEET_COLUMNS
    got = got.drop(columns="seconds").reset_index(drop=True)
    want = want.drop(columns="seconds").reset_index(drop=True)
    got["samples"] = got["samples"].astype("int64")
    want["samples"] = want["samples"].astype("int64")
    pd.testing.assert_frame_equal(got, want, check_dtype=False)
