"""A PD-driven robot's peer identification scored as wbfriction's is (issue 55): the held-out torque its parameters
predict, through the same estimate and the same prediction.

The real Aliengo's peer (iit-DLSLab, PACE-style: :class:`~wbfriction.datasets.aliengo.PeerActuator`) gives an
armature, an encoder offset, a viscous and a static friction per joint and one delay. Its robot is the dataset's
``aliengo.toml`` with the peer's tables (``peer.toml``, written by ``wbfriction dataset aliengo``: its delay holding
back the whole torque, as PACE's actuator does); its friction ``f(qd) = F_v qd + F_s sgn(qd)`` (Isaac Lab's joint
friction: a static level, equal to the dynamic one in their assets, and a viscous coefficient; a simulator's Coulomb
friction is a step). The held-out log is estimated with that robot as the route estimates it with the one
identified (:func:`~wbfriction.friction.estimate.estimate_log`, the momentum route, as the dataset's commands take),
and the peer's friction predicts its torque (:func:`~wbfriction.fit.predict.predict_torques`): the RMS of measured
less predicted, per joint, beside wbfriction's (:func:`peer_held_out`); and the same log's set-points replayed in
MuJoCo with either's parameters, the joints' tracking error (:func:`peer_rollouts`).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pyarrow as pa

from wbfriction.datasets.aliengo import PeerActuator
from wbfriction.fit.predict import predict_torques
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.families.coulomb_viscous import CoulombViscousParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.source import read_log
from wbfriction.model.loading import build_robot
from wbfriction.model.robot import Robot


def peer_robot_config(robot_toml: Path, peer_toml: Path) -> dict:
    """The robot's configuration with the peer's tables (``[armature]``, ``[encoder_offset]``, ``[pd]``) over it."""
    config = tomllib.loads(robot_toml.read_text(encoding="utf-8"))
    peer = tomllib.loads(peer_toml.read_text(encoding="utf-8"))
    for table in ("armature", "encoder_offset"):
        if table in peer:
            config[table] = peer[table]
    config["pd"] = {**config.get("pd", {}), **peer.get("pd", {})}
    return config


def peer_robot(robot_toml: Path, peer_toml: Path) -> Robot:
    """The robot with the peer's tables (:func:`peer_robot_config`)."""
    config = peer_robot_config(robot_toml, peer_toml) | {"_dir": str(robot_toml.parent)}
    return build_robot(robot_toml.parent / config["urdf"], config, str(peer_toml))


def peer_friction(peer: PeerActuator, joints: tuple[str, ...]) -> dict[str, CoulombViscousParams]:
    """The peer's friction per joint (module docstring)."""
    return {j: CoulombViscousParams(F_v=peer.viscous_friction[j], F_c=peer.static_friction[j]) for j in joints}


def peer_held_out(robot_toml: Path, peer_toml: Path, peer: PeerActuator, held_out: Path) -> dict[str, float]:
    """Per joint, the RMS [N·m] of the held-out log's torque less what the peer's parameters predict (module
    docstring).

    Raises:
        InputError: what reading the robot or the log raises.
    """
    robot = peer_robot(robot_toml, peer_toml)
    est = estimate_log(robot, read_log(held_out, robot), EstimateOptions(route="momentum"))
    prediction = predict_torques(est, peer_friction(peer, tuple(est.joints)))
    return {j: float(prediction.rms[i]) for i, j in enumerate(prediction.joints)}


def peer_rollouts(robot_toml: Path, peer_toml: Path, peer: PeerActuator, identified_toml: Path, params: Path,
                  held_out: Path) -> pa.Table:
    """The held-out log's set-points replayed in MuJoCo (:func:`~wbfriction.sim.rollout.rollout`) with wbfriction's
    identification (the robot ``identified_toml``, the friction of ``params``) and with the peer's, as the peer's
    simulator applies it (its delay truncated to whole 5 ms steps and applied to the whole torque, PACE's actuator):
    a row per joint, ``rms.ours`` and ``rms.peer`` [rad], the tracking error of the logged angles.

    Raises:
        InputError: what reading the robots, the parameters or the log raises.
    """
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.rollout import ActuatorParams, rollout, rollout_table

    ours = rollout(load_robot(None, config=identified_toml), held_out, ActuatorParams(friction=params, label="ours"))
    robot = peer_robot(robot_toml, peer_toml)
    theirs = rollout(robot, held_out, ActuatorParams(friction=peer_friction(peer, robot.actuated),
                                                     delay=peer.applied_delay, torque_delay=True, label="peer"))
    return rollout_table([ours, theirs])
