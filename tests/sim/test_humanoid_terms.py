"""Friction beyond velocity on a walking humanoid (issue 40): TALOS's combined walk on the ideal simulator and on
MuJoCo, with a position ripple on the hip pitches, a load- and temperature-dependent Coulomb level on the knees
(the joints warming 25 -> 55 °C over the walk) and a viscous level by direction on the ankle pitches, given as a
friction TOML (what ``wbfriction simulate --friction`` reads). The log, noise-free, through ``estimate`` and
``fit --terms all``: exactly the injected terms kept, each coefficient within 5 % (the ripple: its shape over the
angles walked, its coefficients being told from the offset only over a whole turn), no term on the other leg
joints. (Measured: worst 2.2 % on the ideal simulator, the hips' ripple shape; 0.6 % on MuJoCo. With the studies'
sensor noise on MuJoCo, the knees' load within 1 % but their temperature slopes and the ankles' direction within
about 10 %, and the hips' ripple, 0.02 N·m over the angles walked, not kept: the issue's note.)"""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions, TermOptions
from wbfriction.fit.targets import load_friction_spec
from wbfriction.fit.terms import fourier
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.studies.common import leg_joints

FRICTION_TOML = """
[friction.hip_pitch]
model = "coulomb-viscous"
F_v = 0.2
F_c = 0.8
tau_os = 0.1
[friction.hip_pitch.terms]
ripple = [[0.1, 0.05]]

[friction.knee]
model = "coulomb-viscous"
F_v = 0.2
F_c = 1.0
tau_os = 0.1
[friction.knee.terms]
F_L = 0.01
F_cT = -0.008
F_vT = -0.004
reference_temperature = 40.0

[friction.ankle_pitch]
model = "coulomb-viscous"
F_v = 0.2
F_c = 0.2
tau_os = 0.05
[friction.ankle_pitch.terms]
dF_v = 0.05

[friction.hip_roll]
model = "coulomb-viscous"
F_v = 0.2
F_c = 1.0
tau_os = 0.1

[temperature]
start = 25.0
end = 55.0
"""


@pytest.fixture(scope="module")
def spec(talos, tmp_path_factory):
    path = tmp_path_factory.mktemp("terms") / "friction.toml"
    path.write_text(FRICTION_TOML)
    return load_friction_spec(path, talos.groups, talos.torque_controlled)


def test_the_toml_reads_as_written(spec):
    knee = spec.terms["leg_left_4_joint"]
    assert knee.kept == ("load", "temperature") and knee.reference_temperature == 40.0
    assert knee.coefficients == {"F_L": 0.01, "F_cT": -0.008, "F_vT": -0.004}
    hip = spec.terms["leg_right_3_joint"]
    assert hip.kept == ("ripple",) and hip.harmonics == 1 and hip.coefficients == {"ripple_sin1": 0.1,
                                                                                   "ripple_cos1": 0.05}
    assert spec.terms["leg_left_5_joint"].kept == ("direction",) and spec.temperature == (25.0, 55.0)
    assert "leg_left_2_joint" in spec.params and "leg_left_2_joint" not in spec.terms


@pytest.mark.slow
@pytest.mark.parametrize("simulator", ["ideal", "mujoco"])
def test_the_injected_terms_are_recovered_and_no_other(talos, spec, simulator):
    from dataclasses import replace

    from wbfriction.sim import simulate_ideal
    from wbfriction.sim.mujoco_sim import simulate_mujoco
    from wbfriction.sim.options import MujocoOptions
    from wbfriction.studies.common import SIMULATOR
    from wbfriction.walking import GaitOptions, walking_reference

    ref = walking_reference(talos, GaitOptions(gait="combined", steps=4))
    if simulator == "ideal":
        sim = simulate_ideal(talos, ref, spec.params, replace(SIMULATOR, temperature=spec.temperature),
                             terms=spec.terms)
    else:
        sim = simulate_mujoco(talos, ref, spec.params, MujocoOptions(temperature=spec.temperature), terms=spec.terms)
    assert sim.log.temperature is not None
    est = estimate_log(talos, sim.log, EstimateOptions())
    legs = [j for j, _, _ in leg_joints(talos)]
    fits = {f.joint: f for f in fit_estimate(est, FitOptions(model="coulomb-viscous", terms=TermOptions(
        reference_temperature=40.0)), joints=legs)}
    errors = {}
    for joint in legs:
        terms = fits[joint].terms
        truth = spec.terms.get(joint)
        assert terms is not None
        assert set(terms.kept) == (set() if truth is None else set(truth.kept)), (joint, terms.reasons)
        if truth is None:
            continue
        assert all(v.ok for v in terms.verdicts().values()), (joint, terms.verdicts())
        if "ripple" in truth.kept:  # its shape over the angles walked (the samples fitted), each less its mean
            i = est.joints.index(joint)
            assert est.q is not None
            q = est.q[est.valid[:, i] & (np.abs(est.qd[:, i]) > 0.02), i]
            got, want = (fourier(q, t.harmonics) @ np.array([t.coefficients[f"ripple_{f}{h}"]
                                                               for h in range(1, t.harmonics + 1)
                                                               for f in ("sin", "cos")]) for t in (terms, truth))
            errors[joint, "ripple"] = float(np.std((got - got.mean()) - (want - want.mean())) / np.std(want))
        for name, value in truth.coefficients.items():
            if not name.startswith("ripple"):
                errors[joint, name] = abs(terms.coefficients[name] / value - 1)
    print(f"\n{simulator}: worst relative error", {k: f"{100 * v:.2f} %" for k, v in errors.items()})
    assert max(errors.values()) < 0.05, errors
