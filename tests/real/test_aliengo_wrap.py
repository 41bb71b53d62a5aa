"""The real Aliengo's continuous thighs logged across the wrap (issue 65, class 8): the same motion, its angles and
set-points wrapped to (−π, π] or to [0, 2π), gives the same friction table, fit and held-out prediction.

The Aliengo's thighs are URDF ``continuous`` joints; hung, they swing over 0.49-1.18 rad, where both conventions
write the same numbers. Their encoders' zero is moved 2.3 rad here (``[encoder_offset]``: the logged angle is the
model's plus 2.3 rad, 2.79-3.48 rad, across π), the log's ``q.<thigh>`` and ``q_des.<thigh>`` columns written each
way, the rest as logged. Estimated on the momentum route (as ``wbfriction dataset aliengo`` prints), fitted on the
first 60 % with the ripple tried, the last 40 % predicted. Before the fix, in (−π, π] the drivers' set-points were
read a turn from the angles wherever the two sat on either side of π: the PD law gave ``kp 2π`` = 157 N·m, clipped at
the drives' limits, a rigid-body torque of 25.3 N·m RMS on every thigh for the log's 0.61-0.63 (the thighs were then
fitted as not excited; the [0, 2π) fit predicted the (−π, π] held-out rows to 25.8 N·m RMS). Now every way: 0.235-0.239
N·m on the thighs. About 6 s.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from helpers import REAL_DATA, assert_same_tables, needs_data
from wbfriction import datasets
from wbfriction.fit.options import FitOptions, TermOptions
from wbfriction.friction.options import EstimateOptions
from wbfriction.model.loading import RobotSpec
from wbfriction.pipeline.estimate_step import estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.pipeline.predict_step import predict_file

pytestmark = needs_data("unitree_aliengo")

ZERO = 2.3
"""The thighs' encoder offset [rad]: their logged angles cross π."""
WRAPS = {"pi": lambda x: x - 2 * np.pi * np.ceil((x - np.pi) / (2 * np.pi)), "2pi": lambda x: np.mod(x, 2 * np.pi)}
THIGHS = [f"{leg}_thigh_joint" for leg in ("FL", "FR", "RL", "RR")]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Per wrap: the friction tables of both halves and the fit of the first (a Coulomb-viscous model: the automatic
    choice between models turns on differences of 1e-12 N·m in the table, below what either log can tell)."""
    folder = tmp_path_factory.mktemp("aliengo_wrap")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(datasets.DATA_ENV, str(REAL_DATA))
        written = datasets.write_dataset("aliengo", folder / "data")
    config = folder / "data" / "moved.toml"
    config.write_text(written.config.read_text() + "\n[encoder_offset]\n" + "".join(f"{j} = {ZERO}\n" for j in THIGHS))
    spec = RobotSpec.given("", config=config)
    robot = spec.load()
    out: dict[str, dict[str, object]] = {wrap: {} for wrap in WRAPS}
    for role in ("train", "held_out"):
        table = pq.read_table(written.logs[role])
        for wrap, reduce in WRAPS.items():
            moved = table
            for name in [f"{p}.{j}" for p in ("q", "q_des") for j in THIGHS]:
                moved = moved.set_column(moved.column_names.index(name), name,
                                         pa.array(reduce(table[name].to_numpy() + ZERO)))
            log, friction = folder / f"{role}_{wrap}.parquet", folder / f"{role}_{wrap}_friction.parquet"
            pq.write_table(moved, log)
            estimate_file(spec, log, friction, EstimateOptions(route="momentum"), robot=robot)
            out[wrap][role] = friction
    for wrap in WRAPS:
        out[wrap]["params"] = folder / f"params_{wrap}.json"
        fit_file(out[wrap]["train"], out[wrap]["params"],
                 FitOptions(model="coulomb-viscous", terms=TermOptions(terms=("ripple",))))
    return out


def test_the_thighs_cross_the_wrap_one_way_only(runs):
    logged = {w: pq.read_table(runs[w]["train"].parent / f"train_{w}.parquet") for w in WRAPS}
    for j in THIGHS:
        jumps = {w: np.abs(np.diff(t[f"q.{j}"].to_numpy())).max() for w, t in logged.items()}
        assert jumps["pi"] > 6.0 and jumps["2pi"] < 0.1, (j, jumps)


def test_the_same_table_fit_and_held_out_prediction_either_way(runs):
    for role in ("train", "held_out"):
        assert_same_tables(*(pq.read_table(runs[w][role]) for w in WRAPS), role)
    predictions = {(fit, held): predict_file(runs[held]["held_out"], runs[fit]["params"])
                   for fit in WRAPS for held in WRAPS}
    reference = predictions["2pi", "2pi"]
    for p in predictions.values():
        np.testing.assert_allclose(p.rms, reference.rms, rtol=1e-6)
        np.testing.assert_allclose(p.rms_rigid_body, reference.rms_rigid_body, rtol=1e-9)
        assert p.status == reference.status
    thighs = [reference.joints.index(j) for j in THIGHS]
    assert max(reference.rms_rigid_body[thighs]) < 1.0 and max(reference.rms[thighs]) < 0.3  # not kp 2π's
