"""The KUKA LWR4+ of the real data (a fixed-base arm), built here as a Robot without the project's loader;
random friction and identified-like inertias."""

from __future__ import annotations

import os
from pathlib import Path

import pinocchio as pin
import pytest

from wbfriction.friction.models import FrictionParams
from wbfriction.model.robot import Robot

REPO = Path(__file__).resolve().parents[2]


def real_data() -> Path | None:
    """The real-data folder (env WBFRICTION_REAL_DATA, else ``../shared/real-data`` beside the checkout)."""
    folder = Path(os.environ.get("WBFRICTION_REAL_DATA", REPO / ".." / "shared" / "real-data"))
    return folder if folder.is_dir() else None


def kuka_robot(urdf: Path, locked: dict[str, float] | None = None) -> Robot:
    """The LWR4+ as the project models a fixed base: a free-flyer root welded at the identity
    (the root link's frame its contact), every revolute joint actuated; ``locked`` joints removed
    from the model at their positions (Pinocchio's reduced model)."""
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    locked = locked or {}
    if locked:
        q = pin.neutral(model)
        for name, value in locked.items():
            q[model.idx_qs[model.getJointId(name)]] = value
        model = pin.buildReducedModel(model, [model.getJointId(n) for n in locked], q)
    actuated = tuple(model.names[2:])
    root = next(f.name for f in model.frames if f.parentJoint == 1 and f.type == pin.FrameType.BODY)
    return Robot(name="kuka_lwr4", model=model, urdf=urdf, actuated=actuated, torque_controlled=actuated,
                 position_controlled=(), contact_frames=(root,), floating_base=False, locked_joints=dict(locked))


@pytest.fixture(scope="session")
def kuka_urdf() -> Path:
    folder = real_data()
    path = None if folder is None else folder / "kuka_lwr4" / "kuka_lwr4.urdf"
    if path is None or not path.is_file():
        pytest.skip("no real data: set WBFRICTION_REAL_DATA or put shared/real-data beside the checkout "
                    "(needs kuka_lwr4/kuka_lwr4.urdf)")
    return path


@pytest.fixture(scope="session")
def kuka(kuka_urdf) -> Robot:
    return kuka_robot(kuka_urdf)


@pytest.fixture(scope="session")
def make_kuka(kuka_urdf):
    """``make_kuka(locked)``: the LWR4+ with some joints locked (:func:`kuka_robot`)."""
    return lambda locked=None: kuka_robot(kuka_urdf, locked)


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
