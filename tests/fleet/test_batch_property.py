"""Any sequence of batch runs leaves the results folder a serial run of the last manifest writes into an empty
one (issue 37): robot ids as text, start times, duplicated bytes, corrected rows, other options, failures and
interruptions. The computation of each log is replaced by a fast function of its key (what is tested here is the
bookkeeping; the computation's own truth is tests/fleet/test_batch.py's)."""

from __future__ import annotations

import shutil
import tempfile
from datetime import UTC, datetime, timedelta
from pathlib import Path

import pyarrow as pa
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from wbfriction.fit.options import FitOptions
from wbfriction.fleet.batch import run_batch
from wbfriction.fleet.manifest import read_manifest
from wbfriction.fleet.options import BatchOptions
from wbfriction.fleet.results import read_results, rows_sha256
from wbfriction.fleet.schema import RESULT_SCHEMA
from wbfriction.fleet.task import LogOutcome

LOGS = ("a", "b", "c")
"""The logs; each has a copy of its bytes, ``<name>-copy.parquet``."""
IDS = ("001", "1", "007", "7", "arm-1")
MODELS = ("", "thesis", "stribeck", "coulomb-viscous")


def fake_process_log(entry, key, options, scratch, table=None, executor=None, chunk_workers=1) -> LogOutcome:
    """Two joints' rows, a function of the key (log bytes, options); a ``stribeck`` fit always fails."""
    if options.fit.model == "stribeck":
        return LogOutcome(entry, key, error=f"{entry.log}: cannot fit")
    rows: dict[str, list] = {name: [] for name in RESULT_SCHEMA.names}
    for joint in ("j0", "j1"):
        row = {name: float("nan") for name in RESULT_SCHEMA.names}
        row.update(robot_id=key.robot_id, log=key.log, start_time=key.start_time, key=key.key,
                   log_sha256=key.log_sha256, robot_sha256=key.robot_sha256, options_sha256=key.options_sha256,
                   joint=joint, model=options.fit.model, route="acceleration", status="ok", n_samples=100,
                   version="test",
                   F_c=int(key.log_sha256[:8], 16) / 1e9 + len(options.fit.model), F_c_se=0.01)
        for name in RESULT_SCHEMA.names:
            rows[name].append(row[name])
    return LogOutcome(entry, key, pa.Table.from_pydict(rows, schema=RESULT_SCHEMA))


@st.composite
def manifests(draw) -> str:
    """A manifest's text: each log listed as itself, its copy or both, with a robot id, a day and a model."""
    lines = ["log,robot_id,start_time,robot,model"]
    for name in LOGS:
        files = draw(st.sampled_from([[name], [f"{name}-copy"], [name, f"{name}-copy"]]))
        for file in files:
            day = datetime(2026, 3, 1, tzinfo=UTC) + timedelta(days=draw(st.integers(0, 3)))
            lines.append(f"{file}.parquet,{draw(st.sampled_from(IDS))},{day.isoformat()},panda,"
                         f"{draw(st.sampled_from(MODELS))}")
    return "\n".join(lines) + "\n"


def _parts(results: Path) -> dict[str, str]:
    """Each result file by its path in the folder, as the digest of its rows."""
    import pyarrow.parquet as pq

    return {p.relative_to(results).as_posix(): rows_sha256(pq.read_table(p).replace_schema_metadata(None))
            for p in sorted(results.glob("*/*.parquet"))}


class Stop(Exception):
    pass


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(runs=st.lists(st.tuples(manifests(), st.sampled_from(["auto", "thesis"]), st.integers(0, 4)),
                     min_size=1, max_size=4),
       last=st.tuples(manifests(), st.sampled_from(["auto", "thesis"])))
def test_any_sequence_of_runs_equals_one_run_of_the_last_manifest(runs, last):
    with tempfile.TemporaryDirectory() as tmp, pytest.MonkeyPatch.context() as mp:
        mp.setattr("wbfriction.fleet.batch.process_log", fake_process_log)
        folder = Path(tmp)
        for i, name in enumerate(LOGS):
            pa.parquet.write_table(pa.table({"x": [float(i)]}), folder / f"{name}.parquet")
            shutil.copy(folder / f"{name}.parquet", folder / f"{name}-copy.parquet")
        results = folder / "results"

        def run(text: str, model: str, stop_after: int | None, into: Path) -> None:
            (folder / "m.csv").write_text(text)
            done = []

            def progress(outcome):
                done.append(outcome)
                if stop_after is not None and len(done) >= stop_after:
                    raise Stop

            try:
                run_batch(read_manifest(folder / "m.csv"), into, BatchOptions(fit=FitOptions(model=model)),
                          engine="serial", progress=progress)
            except Stop:
                pass

        for text, model, stop_after in runs:
            run(text, model, stop_after, results)
        run(*last, None, results)
        run(*last, None, folder / "fresh")
        final = _parts(results)
        assert final == _parts(folder / "fresh")
        event(f"{len(final)} results, {len(runs)} runs before the last")
        if final:
            mine, fresh = read_results(results), read_results(folder / "fresh")
            assert rows_sha256(mine.table) == rows_sha256(fresh.table)
            assert [(s.path.relative_to(results), s.reason) for s in mine.left_out] == \
                [(s.path.relative_to(folder / "fresh"), s.reason) for s in fresh.left_out]
            event(f"{len(mine.left_out)} copies counted once")
