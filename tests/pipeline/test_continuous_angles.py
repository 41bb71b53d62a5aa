"""A continuous joint's angle is known modulo 2π (issue 65, class 8): the same motion logged with its angle wrapped to
(−π, π] and to [0, 2π) gives the same friction table, the same fit and the same held-out prediction, up to rounding.

The Panda with its last joint made ``continuous``, its encoder's zero put so that the joint's logged angle runs from
2.76 to 3.44 rad on the fitted log (2.26 to 3.94 on the held-out one): across π, where a logger in (−π, π] wraps it and
one in [0, 2π) does not; a two-harmonic position ripple in its friction. Both logs are estimated in chunks (each chunk
unwrapped from its own first row) with the automatic differentiation and route, fitted with the ripple, and the
held-out one predicted. Before issue 65, class 8: the (−π, π] table held the fitted angles on two branches (−6.62 to
0.34 rad), the ripple's range came out wider than a turn, and the same held-out rows predicted 0.2172 N·m against
0.2185 from the [0, 2π) log's fit; the noise and differentiation were decided on first rows holding the wrap.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import wbfriction
from helpers import assert_same_tables
from wbfriction.fit.options import FitOptions, TermOptions
from wbfriction.fit.terms import TermFit
from wbfriction.friction.models import CoulombViscousParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.tables import read_metadata, write_table
from wbfriction.model import load_robot
from wbfriction.model.loading import RobotSpec
from wbfriction.pipeline.chunks import Chunking, plan_chunks
from wbfriction.pipeline.estimate_step import estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.pipeline.predict_step import predict_file
from wbfriction.sim.arm import ArmOptions, ExcitationOptions, simulate_arm

JOINT = "panda_joint7"
VELOCITY = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.1)
RIPPLE = TermFit(VELOCITY, ("ripple",), 2, {"ripple_sin1": 0.1, "ripple_cos1": 0.05, "ripple_sin2": 0.04,
                                             "ripple_cos2": -0.03})
OFFSET = 3.1
"""The encoder's zero [rad]: the joint's logged angle is the model's plus this, across π."""
CHUNKING = Chunking(rows=2000, overlap=500, workers=1)
"""Four chunks, each read from 500 rows before its first: each unwrapped from its own first row read."""
WRAPS = {"pi": lambda x: x - 2 * np.pi * np.ceil((x - np.pi) / (2 * np.pi)), "2pi": lambda x: np.mod(x, 2 * np.pi)}
"""A logger's angle in (−π, π] and in [0, 2π), written each from its definition."""


def _continuous_panda(folder: Path) -> Path:
    """The Panda's TOML with its last joint continuous (its URDF beside it) and that joint's encoder offset."""
    panda = load_robot("panda")
    urdf = folder / "panda_continuous.urdf"
    urdf.write_text(Path(panda.urdf).read_text().replace(f'<joint name="{JOINT}" type="revolute">',
                                                         f'<joint name="{JOINT}" type="continuous">'))
    toml = (Path(wbfriction.__file__).parent / "model/robots/panda.toml").read_text()
    config = folder / "panda_continuous.toml"
    config.write_text(toml.replace('urdf = "example-robot-data:panda_description/urdf/panda.urdf"',
                                   f'urdf = "{urdf.name}"') + f"\n[encoder_offset]\n{JOINT} = {OFFSET}\n")
    return config


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Per wrap: the friction tables of the fitted (seed 0) and held-out (seed 1, wider motion) logs, and the fit."""
    folder = tmp_path_factory.mktemp("continuous")
    config = _continuous_panda(folder)
    spec = RobotSpec.given("", config=config)
    robot = spec.load()
    assert list(robot.layout.q2_joint) == [robot.actuated.index(JOINT)]
    panda = load_robot("panda")
    others = {j: VELOCITY for j in panda.actuated if j != JOINT}
    out: dict[str, dict[str, Path]] = {wrap: {} for wrap in WRAPS}
    for seed, role in ((0, "train"), (1, "held_out")):
        table = simulate_arm(panda, others, terms={JOINT: RIPPLE}, options=ArmOptions(
            duration=8.0, substeps=2, torque_std=0.05, seed=seed, encoder_bits=None,
            excitation=ExcitationOptions(seed=seed, period=4.0, velocity_share=0.6 if seed == 0 else 0.9))).table
        column = table.column_names.index(f"q.{JOINT}")
        logged = table.column(column).to_numpy() + OFFSET
        for wrap, reduce in WRAPS.items():
            log, friction = folder / f"{role}_{wrap}.parquet", folder / f"{role}_{wrap}_friction.parquet"
            write_table(table.set_column(column, f"q.{JOINT}", pa.array(reduce(logged))), log)
            estimate_file(spec, log, friction, EstimateOptions(), chunking=CHUNKING,
                          robot=robot)
            out[wrap][role] = friction
    for wrap in WRAPS:
        out[wrap]["params"] = folder / f"params_{wrap}.json"
        fit_file(out[wrap]["train"], out[wrap]["params"], FitOptions(model="coulomb-viscous",
                                                                      terms=TermOptions(terms=("ripple",))))
    return out


def test_the_logs_cross_the_wrap_one_way_only(runs):
    """The premise: logged in (−π, π], the angle jumps by 2π; in [0, 2π), it does not; and the fitted log's chunks
    start on either side of the wrap in (−π, π] (unwrapped from there, they reach the table on two branches)."""
    for role in ("train", "held_out"):
        folder = runs["pi"][role].parent
        jumps = {wrap: np.abs(np.diff(pq.read_table(folder / f"{role}_{wrap}.parquet")[f"q.{JOINT}"].to_numpy())).max()
                 for wrap in WRAPS}
        assert jumps["pi"] > 6.0 and jumps["2pi"] < 0.1, jumps
    logged = pq.read_table(runs["pi"]["train"].parent / "train_pi.parquet")[f"q.{JOINT}"].to_numpy()
    starts = logged[[c.read_start for c in plan_chunks(np.ones((len(logged), 1)), CHUNKING)]]
    assert starts.min() < 0 < starts.max(), starts


def _assert_same(a, b, where: str) -> None:
    """``a`` and ``b`` (JSON values) the same, their numbers to rounding."""
    if isinstance(a, dict) and isinstance(b, dict):
        assert sorted(a) == sorted(b), where
        for k in a:
            _assert_same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list) and isinstance(b, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-15, nan_ok=True), where
    else:
        assert a == b, where


def test_the_same_friction_table_either_way(runs):
    """Every column equal to rounding (the logged angles themselves differ by a rounding of 2π: 4e-16 rad, 2e-9
    rad/s² once differentiated twice at 1 kHz); the joint's angle in (−π, π], the same on every row; the same
    decisions (the noise, the route, the differentiation: measured on the first rows, the wrap once counted as noise,
    the joint's content ending at 147 Hz instead of 26)."""
    for role in ("train", "held_out"):
        a, b = (pq.read_table(runs[wrap][role]) for wrap in WRAPS)
        decided = [{k: v for k, v in read_metadata(t, "").items() if k not in ("source", "provenance")} for t in (a, b)]
        _assert_same(*decided, role)
        assert_same_tables(a, b, role, atol=1e-7)
        q = a[f"q.{JOINT}"].to_numpy()
        assert -np.pi < q.min() and q.max() <= np.pi


def test_the_same_fit_and_held_out_prediction_either_way(runs):
    """The ripple kept by both fits, on the same arc of angles (2.6-4.3 rad as logged, less the offset), with the
    same coefficients; the held-out rows, either way logged, predicted by either fit to the same RMS."""
    fits = {wrap: json.loads(runs[wrap]["params"].read_text())["joints"][JOINT]["terms"] for wrap in WRAPS}
    assert fits["pi"]["kept"] == fits["2pi"]["kept"] == ["ripple"]
    np.testing.assert_allclose(fits["pi"]["q_range"], fits["2pi"]["q_range"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(fits["pi"]["ranges"]["angle"], fits["2pi"]["ranges"]["angle"], rtol=0, atol=1e-9)
    logged = pq.read_table(runs["2pi"]["train"].parent / "train_2pi.parquet")[f"q.{JOINT}"].to_numpy() - OFFSET
    low, high = fits["pi"]["q_range"]  # the model's angles the joint swept (the rows left out at reversals aside)
    assert logged.min() - 1e-9 <= low < high <= logged.max() + 1e-9 and high - low > 0.95 * np.ptp(logged), (low, high)
    for name, value in fits["2pi"]["coefficients"].items():
        assert fits["pi"]["coefficients"][name] == pytest.approx(value, rel=1e-7, abs=1e-9), name
    rms = {(fit, held): predict_file(runs[held]["held_out"], runs[fit]["params"]) for fit in WRAPS for held in WRAPS}
    values = {k: p.rms[p.joints.index(JOINT)] for k, p in rms.items()}
    assert max(values.values()) - min(values.values()) < 1e-9 * max(values.values()), values
    assert len({p.status[p.joints.index(JOINT)] for p in rms.values()}) == 1
