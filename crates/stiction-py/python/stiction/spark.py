"""Diagnose a fleet on Spark: ``stiction.spark.diagnose(spark_df, by="loop_id", ...)``.

Each loop is one group of ``groupBy(by).applyInPandas``: the executor that holds a loop's rows
runs :func:`stiction.diagnose_many` on them (one thread per task: Spark runs the tasks in
parallel) and returns that loop's fleet row. The result is a Spark DataFrame with the columns
of :data:`stiction.FLEET_COLUMNS`, ordered as ``stiction batch`` ranks. Every executor needs the
``stiction`` wheel installed (see the README: ``--py-files`` does not carry a native module).
"""

from __future__ import annotations

from typing import Any, Optional

import pandas as pd

from ._many import FLEET_COLUMNS, diagnose_many

_VERDICT_ORDER = ["stiction", "undetermined", "no_stiction", "insufficient_data", "failed"]


def schema(by_field: Any) -> Any:
    """The declared result schema: the ``by`` column as it is in the input, then the fleet row."""
    from pyspark.sql.types import (
        DoubleType,
        LongType,
        StringType,
        StructField,
        StructType,
    )

    kinds = {
        "source": StringType(),
        "verdict": StringType(),
        "probability": DoubleType(),
        "severity": DoubleType(),
        "band_percent_of_span": DoubleType(),
        "band_source": StringType(),
        "ellipse_percent_of_span": DoubleType(),
        "small_band_percent_of_span": DoubleType(),
        "period_s": DoubleType(),
        "regularity": DoubleType(),
        "reason": StringType(),
        "samples": LongType(),
        "seconds": DoubleType(),
        "error": StringType(),
    }
    fields = [StructField("loop_id", by_field.dataType, True)]
    fields += [StructField(name, kinds[name], True) for name in FLEET_COLUMNS[1:]]
    return StructType(fields)


def diagnose(
    spark_df: Any,
    by: str = "loop_id",
    op: str = "op",
    pv: str = "pv",
    sp: Optional[str] = None,
    mode: Optional[str] = None,
    mv: Optional[str] = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    quantify: bool = True,
    *,
    time: Optional[str] = None,
    op_range: Any = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
    rank: bool = True,
) -> Any:
    """Diagnose every loop of a long Spark DataFrame (``by`` names the loop): a Spark DataFrame
    with one row per loop, the columns of ``diagnose_many`` (``loop_id`` holds the ``by`` values).
    ``rank``: order the rows as ``stiction batch`` ranks (a sort over the loops; skip it for a
    fleet too large to sort). Time as in ``diagnose_many`` (a timestamp column works).
    """
    from pyspark.sql import functions as F

    if by not in spark_df.columns:
        from ._signals import StictionError

        raise StictionError(
            f"no column '{by}' for the loop id; the columns are {', '.join(spark_df.columns)}. "
            "Name the right one with by='COLUMN'"
        )
    out_schema = schema(spark_df.schema[by])
    settings = dict(
        op=op, pv=pv, sp=sp, mode=mode, mv=mv, ts=ts, integrating=integrating, quantify=quantify,
        time=time, op_range=tuple(op_range), estimate_start=estimate_start, thorough=thorough,
    )

    def one_loop(pdf: pd.DataFrame) -> pd.DataFrame:
        # one loop a group: no other loop to share a period with
        rows = diagnose_many(pdf, by=by, threads=1, progress=False, **settings)[FLEET_COLUMNS]
        rows["samples"] = rows["samples"].astype("Int64")
        return rows

    result = spark_df.groupBy(by).applyInPandas(one_loop, schema=out_schema)
    if not rank:
        return result
    order = F.create_map(*[x for i, v in enumerate(_VERDICT_ORDER) for x in (F.lit(v), F.lit(i))])
    return result.orderBy(F.desc("severity"), order[F.col("verdict")], F.col("loop_id").cast("string"))
