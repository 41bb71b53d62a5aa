"""The Go2 on three feet from the command line (issue 66): ``excite --swing`` writes the set-points of the reference
:func:`~wbfriction.excite.tripod.tripod_reference` builds, ``simulate --play`` rebuilds it from the table and plays
it in the ideal quadruped simulator, and ``estimate`` and ``fit`` run on the log as on a gait's recover each swing
joint's injected friction; what does not apply is refused in one line naming the option.

The friction injected (a ``--friction`` TOML, every joint) is the quadruped simulators' default with F_c 1.25 times
and F_v 0.75 times it, so that the design's prior is not the answer; ``fit --model thesis``: the family injected
(the default ``auto`` picks Coulomb-viscous for the swing calf here, whose sign step is not the injected
``tanh(40 qd)``: its F_v 41 % off on this 4 s recording, measured). :data:`TOLERANCE`: 1 %, from what
``tests/excite/test_tripod.py`` measured at the 0.25 ms physics step: worst F_v 0.62 % (F_c 0.13 %) over the four
legs on 8 s; this test's 4 s front right leg, measured: F_v 0.58 % on the calf, F_c within 0.05 %. At the gaits'
0.5 ms step the calf's F_v is 2.28 % off on the same table (measured): the test passes no ``--substeps``, so it
also checks that a played stance takes the finer step by default.
"""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from helpers import run_cli_printed
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.tripod import TripodOptions, tripod_reference
from wbfriction.fit.params_file import read_params
from wbfriction.logs.metadata import read_metadata, with_metadata
from wbfriction.logs.setpoint_table import read_setpoint_table
from wbfriction.logs.tables import write_table
from wbfriction.model import load_robot
from wbfriction.rigs.played import played_tripod
from wbfriction.sim.quadruped import default_quadruped_friction

# excite (the design and the IK) 6 s, the reference again 5 s, simulate 3 s, estimate and fit 5 s
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("excite_tripod_cli")]

TOLERANCE = 1.0
"""Each swing joint's F_c and F_v within 1 % [%] (module docstring)."""
DESIGN = ("--duration", "4", "--period", "4")
"""4 s on three feet, one period of each swing joint's series."""


@pytest.fixture(scope="module")
def go2():
    return load_robot("go2_walking")


def friction_toml(path, go2) -> dict:
    """Write the injected friction (module docstring) of every joint; returns it per joint."""
    lines, truth = [], {}
    for joint, p in default_quadruped_friction(go2).items():
        values = {"F_v": 0.75 * p.F_v, "F_c": 1.25 * p.F_c, "S": p.S, "v_s": p.v_s, "tau_os": p.tau_os, "a": p.a}
        lines += [f"[friction.{joint}]", *(f"{k} = {v!r}" for k, v in values.items()), ""]
        truth[joint] = values
    path.write_text("\n".join(lines))
    return truth


def test_a_three_feet_stance_designed_played_estimated_and_fitted(cli, capsys, go2, tmp_path):
    out = cli("excite", "--robot", "go2_walking", "--swing", "FR", *DESIGN, "-o", tmp_path / "s.parquet", "-o",
              tmp_path / "s.csv", "--json", tmp_path / "s.json", "--figure", tmp_path / "s.png")
    assert "The FR leg swung, on FL, RL, RR" in out and "inside the stance triangle's edges" in " ".join(out.split())
    doc = json.loads((tmp_path / "s.json").read_text())
    swing = ("FR_hip_joint", "FR_thigh_joint", "FR_calf_joint")
    assert doc["swing_foot"] == "FR_foot" and doc["stance_feet"] == ["FL_foot", "RL_foot", "RR_foot"]
    assert tuple(doc["swing"]) == swing and doc["base_height"] == 0.3
    for name, least in doc["limits"].items():  # every margin the design checks, beyond its limit
        assert doc[name] > least, name
    for s in doc["swing"].values():  # within its band, its friction predicted ok by its bound
        assert s["band"][0] <= s["reached"][0] < s["reached"][1] <= s["band"][1]
        assert 0 < s["share"]["F_c"] < 1 and 0 < s["share"]["F_v"] < 1 and s["bound"]["F_c"] > 0
    assert (tmp_path / "s.png").stat().st_size > 10_000

    # the table holds the reference the library builds, every actuated joint, in the encoders' coordinates
    excitation = tripod_reference(go2, TripodOptions(swing="FR", design=ExciteOptions(
        duration=4.0, rate=500.0, period=4.0, harmonics=5, range_share=1.0)))
    ref = excitation.reference
    parquet, csv = (read_setpoint_table(tmp_path / f"s.{s}", go2) for s in ("parquet", "csv"))
    np.testing.assert_array_equal(parquet.q_des, ref.q + go2.offset_vector)
    np.testing.assert_array_equal(parquet.qd_des, ref.qd)
    np.testing.assert_array_equal(csv.q_des, parquet.q_des)
    np.testing.assert_array_equal(parquet.time, ref.time)
    assert (parquet.swing, parquet.base_height, parquet.stance) == ("FR_foot", 0.3, None)
    assert parquet.fourier_joints == excitation.joints == swing and parquet.fourier is not None
    np.testing.assert_array_equal(parquet.fourier["a"], excitation.trajectory.a)
    # ... and the play rebuilds that reference from it, sample for sample
    played_ref = played_tripod(go2, tmp_path / "s.parquet")
    for name in ("base", "q", "qd", "qdd", "base_v", "base_a", "feet", "contact"):
        np.testing.assert_array_equal(getattr(played_ref, name), getattr(ref, name), err_msg=name)
    assert played_ref.options == ref.options

    truth = friction_toml(tmp_path / "truth.toml", go2)
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2_walking", "--play", tmp_path / "s.csv",
                                   "--friction", tmp_path / "truth.toml", "-o", tmp_path / "played.parquet")
    assert code == 0 and "(2000 samples, 4 s, FR_foot swung on three feet, joint torques)" in " ".join(err.split())
    played = pq.read_table(tmp_path / "played.parquet")
    assert played.num_rows == 2000
    assert not played.column("contact.FR_foot").to_numpy().any()
    assert all(played.column(f"contact.{f}").to_numpy().all() for f in ("FL_foot", "RL_foot", "RR_foot"))
    calf = go2.actuated.index("FR_calf_joint")
    np.testing.assert_allclose(played.column("q.FR_calf_joint").to_numpy(), parquet.q_des[:, calf], atol=5e-3)

    cli("estimate", tmp_path / "played.parquet", "--robot", "go2_walking", "-o", tmp_path / "friction.parquet")
    cli("fit", tmp_path / "friction.parquet", "--model", "thesis", "-o", tmp_path / "params.json")
    fits = read_params(tmp_path / "params.json")
    errors = {(j, n): 100 * abs(getattr(fits[j].params, n) / truth[j][n] - 1) for j in swing for n in ("F_c", "F_v")}
    print("\n" + "\n".join(f"  {j} {n}: {e:.3f} %" for (j, n), e in errors.items()))
    assert max(errors.values()) < TOLERANCE, errors
    # ok, or, the truth's Stribeck term being nil (S = 0), its speed v_s left at a bound: nothing determines it
    verdicts = {j: str(fits[j].verdict()) for j in swing}
    assert all(v == "ok" or v.endswith("at a bound of the fit: v_s") for v in verdicts.values()), verdicts

    # a table edited after excite wrote it: refused before the simulation
    table = pq.read_table(tmp_path / "s.parquet")
    column = table.column_names.index("q_des.FR_calf_joint")
    edited = table.set_column(column, "q_des.FR_calf_joint", pa.array(parquet.q_des[:, calf] + 1e-5))
    pq.write_table(edited, tmp_path / "edited.parquet")
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2_walking", "--play", tmp_path / "edited.parquet",
                                   "-o", tmp_path / "z.parquet")
    assert code == 2 and "q_des.FR_calf_joint is 1e-05 rad from the three-feet stance its series make" in " ".join(
        err.split()), err
    assert not (tmp_path / "z.parquet").exists()


def test_what_a_three_feet_stance_does_not_take_is_one_line(capsys, go2, tmp_path):
    for args, line in [
        (("--robot", "talos", "--swing", "FR"), "--swing: robot 'talos' is a biped on soles: it takes"),
        (("--robot", "go2_walking", "--stance", "left"),
         "--stance: robot 'go2_walking' stands on point feet (a walking quadruped): it takes"),
        (("--robot", "panda", "--swing", "FR"),
         "--swing: robot 'panda' is a fixed-base arm (torque-driven, an excitation trajectory): it takes"),
        (("--robot", "go2_walking", "--amplitude", "0.5"),
         "--amplitude: robot 'go2_walking' stands on point feet (a walking quadruped): it takes"),
        (("--robot", "go2_walking", "--swing", "XX"), "--swing 'XX': one of FL, FR, RL, RR"),
        (("--robot", "go2_walking", "--duration", "4", "--period", "3"), "--period 3: the recording of 4 s must hold"),
    ]:
        code, _, err = run_cli_printed(capsys, "excite", *args, "-o", tmp_path / "x.parquet")
        assert code == 2 and line in " ".join(err.split()), (args, err)
    # a table of every Go2 joint, but not a three-feet stance's: no swing foot, no series; and motion options
    n = 10
    columns = {"time": np.arange(n) / 500.0,  # standing: within the joints' limits (a calf at 0 is beyond them)
               **{f"q_des.{j}": np.full(n, a) for j, a in zip(go2.actuated, go2.reference_angles)}}
    path = tmp_path / "plain.parquet"
    write_table(with_metadata(pa.table(columns), {"generator": "wbfriction.excite", "robot": go2.name}), path)
    assert read_metadata(pq.read_table(path)).get("swing") is None
    for args, line in [
        ((), "plain.parquet: no swing foot or swing series: a quadruped plays what 'excite --swing' writes"),
        (("--gait", "trot"), "--gait: the set-points played (plain.parquet) fix the motion: it takes no motion"),
        (("--speed", "0.3"), "--speed: the set-points played (plain.parquet) fix the motion: it takes no motion"),
        (("--duration", "3"), "--duration: the set-points played (plain.parquet) fix the motion: it takes no motion"),
        (("--simulator", "mujoco", "--integrator", "explicit"), "--integrator: robot 'go2_walking' stands on point"),
    ]:
        code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2_walking", "--play", path, *args, "-o",
                                       tmp_path / "y.parquet")
        assert code == 2 and line in " ".join(err.split()), (args, err)
    assert not (tmp_path / "x.parquet").exists() and not (tmp_path / "y.parquet").exists()
