"""The KUKA LWR4+ of the real data (a fixed-base arm), loaded with examples/kuka_lwr4.toml; random friction
and identified-like inertias."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin
import pytest

from helpers import KUKA_CONFIG, KUKA_URDF
from wbfriction.fit.result import FitResult
from wbfriction.friction.models import FrictionParams
from wbfriction.model import load_robot
from wbfriction.model.robot import Robot


def kuka_robot(locked: dict[str, float] | None = None) -> Robot:
    """The LWR4+ as the project loads a fixed base (examples/kuka_lwr4.toml), with ``locked`` joints
    removed from the model at their positions."""
    if not locked:
        return load_robot(urdf=KUKA_URDF, config=KUKA_CONFIG)
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        cfg = Path(folder) / "kuka.toml"
        cfg.write_text('name = "kuka_lwr4"\nfloating_base = false\n[locked_joints]\n'
                       + "".join(f"{n} = {v!r}\n" for n, v in locked.items()))
        return load_robot(urdf=KUKA_URDF, config=cfg)


@pytest.fixture(scope="session")
def kuka_urdf() -> Path:
    if not KUKA_URDF.is_file():
        pytest.skip(f"no real data at {KUKA_URDF}: set WBFRICTION_DATA or put shared/real-data beside the "
                    "checkout")
    return KUKA_URDF


@pytest.fixture(scope="session")
def kuka(kuka_urdf) -> Robot:
    return kuka_robot()


@pytest.fixture(scope="session")
def make_kuka(kuka_urdf):
    """``make_kuka(locked)``: the LWR4+ with some joints locked (:func:`kuka_robot`)."""
    return lambda locked=None: kuka_robot(locked)


def _random_friction(joints, rng) -> dict[str, FrictionParams]:
    return {n: FrictionParams(F_v=rng.uniform(0.05, 3.0), F_c=rng.uniform(0.05, 5.0), S=rng.uniform(0, 1),
                              v_s=rng.uniform(0.01, 0.2), tau_os=rng.uniform(-1, 1)) for n in joints}


def _identified(model: pin.Model, rng) -> pin.Model:
    """The model with every body changed as an identification would: mass, centre of mass and
    rotational inertia (turned and scaled, so still a rigid body)."""
    out = pin.Model(model)
    for j in range(1, model.njoints):
        I = model.inertias[j]
        turn = pin.rpy.rpyToMatrix(*rng.uniform(-0.3, 0.3, 3))
        out.inertias[j] = pin.Inertia(I.mass * rng.uniform(0.8, 1.2), I.lever + rng.normal(0, 0.01, 3),
                                      turn @ I.inertia @ turn.T * rng.uniform(0.8, 1.2))
    return out


@pytest.fixture(scope="session")
def random_friction():
    """``random_friction(joints, rng)``: model (3.5) with random dissipative parameters per joint."""
    return _random_friction


@pytest.fixture(scope="session")
def identified():
    """``identified(model, rng)``: the model with every body changed as an identification would."""
    return _identified


def _fit_of(joint: str, status: str, F_v: float = 0.2, F_c: float = 1.0) -> FitResult:
    """A fit whose verdict is ``status`` by the rules of :mod:`wbfriction.fit.status`: a joint that moved
    (95th percentile of |qd| 1 rad/s), a converged solver and standard errors of 5 % (ok); F_v's standard
    error 3 times its value (weak); v_s left on a bound (at bound); |qd| at most 0.0025 rad/s (not excited);
    a solver that did not converge (failed)."""
    params = FrictionParams(F_v=F_v, F_c=F_c, S=0.3, v_s=0.05, tau_os=0.01)
    stderr = {"F_v": 0.05 * F_v, "F_c": 0.05 * F_c, "S": 0.01, "v_s": 0.001, "tau_os": 0.001}
    fit = FitResult(joint, 2000, params=params, stderr=stderr, success=True, message="`ftol` termination "
                    "condition is satisfied.", speed=1.0, at_bound={n: False for n in params.names})
    if status == "weak":
        fit.stderr["F_v"] = 3.0 * F_v
    elif status == "at bound":
        fit.at_bound["v_s"] = True
    elif status == "not excited":
        fit.speed = 0.0025
    elif status == "failed":
        fit.success, fit.message = False, "The maximum number of function evaluations is exceeded."
    assert fit.verdict().status == status
    return fit


@pytest.fixture(scope="session")
def fit_of():
    """``fit_of(joint, status, F_v=0.2, F_c=1.0)``: a fit whose verdict is ``status`` (:func:`_fit_of`)."""
    return _fit_of
