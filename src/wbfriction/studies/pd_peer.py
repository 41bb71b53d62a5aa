"""A PD-driven robot's peer identification scored as wbfriction's is (issue 55): the held-out torque its parameters
predict, through the same estimate and the same prediction.

The real Aliengo's and Go2's peer (iit-DLSLab, PACE-style: :class:`~wbfriction.datasets.pace_peer.PeerActuator`) gives
an armature, an encoder offset, a viscous and a Coulomb friction per joint and one delay. Its robot is the dataset's
``<robot>.toml`` with the peer's tables (``peer.toml``, written by ``wbfriction dataset aliengo`` or ``go2``: its delay
holding back the whole torque, as PACE's actuator does); its friction ``f(qd) = F_v qd + F_s sgn(qd)`` (Isaac Lab's
joint friction: a static level, equal to the dynamic one in their assets, and a viscous coefficient; a simulator's
Coulomb friction is a step). The held-out log is estimated with that robot as the route estimates it with the one
identified (:func:`~wbfriction.friction.estimate.estimate_log`, the momentum route, as the dataset's commands take), and
the peer's friction predicts its torque (:func:`~wbfriction.fit.predict.predict_torques`): the RMS of measured less
predicted, per joint, beside wbfriction's (:func:`peer_held_out`); and the same log's set-points replayed on the MJCF
wbfriction exported and on the peer's parameters as PACE simulates them, the joints' tracking error
(:func:`peer_rollouts`).

**The peer's footing.** The peer's parameters were fitted on the whole log: PACE's ``my_fit.py`` in the peer's
repository replays all of ``traj_0.pt`` at each CMA-ES generation (its ``data_dir``; ``time_steps`` the log's
length). The last 40 % is held out from wbfriction's route, not from the peer. :func:`refine_on_whole_log` refines
the route's MJCF on the same whole log, the peer's training data, so that both are scored on data both were fitted
on.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path

import pyarrow as pa

from wbfriction.datasets.pace_peer import PeerActuator
from wbfriction.fit.predict import predict_torques
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.families.coulomb_viscous import CoulombViscousParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.source import read_log
from wbfriction.model.loading import build_robot, resolve_file
from wbfriction.model.robot import Robot


def peer_robot_config(robot_toml: str | Path, peer_toml: str | Path) -> dict:
    """The robot's configuration with the peer's tables (``[armature]``, ``[encoder_offset]``, ``[pd]``) over it."""
    robot_toml, peer_toml = Path(robot_toml), Path(peer_toml)
    config = tomllib.loads(robot_toml.read_text(encoding="utf-8"))
    peer = tomllib.loads(peer_toml.read_text(encoding="utf-8"))
    for table in ("armature", "encoder_offset"):
        if table in peer:
            config[table] = peer[table]
    config["pd"] = {**config.get("pd", {}), **peer.get("pd", {})}
    return config


def peer_robot(robot_toml: str | Path, peer_toml: str | Path) -> Robot:
    """The robot with the peer's tables (:func:`peer_robot_config`), on the description its TOML names (beside it
    or an installed one, :func:`~wbfriction.model.loading.resolve_file`)."""
    robot_toml = Path(robot_toml)
    config = peer_robot_config(robot_toml, peer_toml) | {"_dir": str(robot_toml.parent)}
    return build_robot(resolve_file(config["urdf"], robot_toml.parent), config, str(peer_toml))


def peer_friction(peer: PeerActuator, joints: tuple[str, ...]) -> dict[str, CoulombViscousParams]:
    """The peer's friction per joint (module docstring)."""
    return {j: CoulombViscousParams(F_v=peer.viscous_friction[j], F_c=peer.coulomb_friction[j]) for j in joints}


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


def peer_rollouts(robot_toml: str | Path, peer_toml: str | Path, peer: PeerActuator, identified_toml: str | Path,
                  mjcf: str | Path, held_out: str | Path, horizon: float | None = 1.0,
                  others: Mapping[str, str | Path] | None = None) -> pa.Table:
    """The held-out log's set-points replayed (:func:`~wbfriction.replay.mjcf.replay_mjcf`, restarted from the log every
    ``horizon`` seconds) on the MJCF wbfriction exported (``mjcf``, for the robot ``identified_toml``), as MuJoCo
    runs it, and on the peer's parameters written by the same export and run as PACE simulates them (the PD law once
    a 5 ms period, its whole torque held back its delay truncated to whole periods): a row per joint, ``rms.ours`` and
    ``rms.peer`` [rad], the tracking error of the logged angles; ``others``: more MJCF files for the same robot (the
    ones ``wbfriction refine`` wrote) by label, each replayed as ``mjcf`` is, ``rms.<label>`` too.

    Raises:
        InputError: what reading the robots, the files or the log raises.
    """
    import tempfile

    from wbfriction.export.mjcf import write_mjcf
    from wbfriction.model.loading import load_robot
    from wbfriction.replay.mjcf import Replay, replay_mjcf
    from wbfriction.replay.rollout import rollout_table

    identified = load_robot(None, config=Path(identified_toml))
    files = {"ours": mjcf, **(others or {})}
    ours = [replay_mjcf(path, identified, held_out, Replay(label=label, horizon=horizon))
            for label, path in files.items()]
    robot = peer_robot(robot_toml, peer_toml)
    with tempfile.TemporaryDirectory(prefix="wbfriction-peer-") as tmp:
        path = Path(tmp) / "peer.xml"
        write_mjcf(robot, peer_friction(peer, robot.actuated), path, armature=peer.armature)
        theirs = replay_mjcf(path, robot, held_out, Replay(label="peer", horizon=horizon,
                                                           torque_delay=peer.applied_delay_steps))
    return rollout_table([*ours, theirs])


def refine_on_whole_log(identified_toml: str | Path, mjcf: str | Path, logs: Sequence[str | Path],
                        output: str | Path) -> Path:
    """``mjcf`` (exported for the robot ``identified_toml``) refined (:func:`~wbfriction.replay.refine.refine_mjcf`) on
    ``logs`` read one after the other as one log (a dataset's ``train.parquet`` then ``held_out.parquet``: the whole
    log the peer was fitted on, module docstring), written to ``output``.

    Raises:
        InputError: what reading the robot, the file or the logs raises; stretches whose times do not follow on.
    """
    from wbfriction.exceptions import InputError
    from wbfriction.logs.tables import read_table
    from wbfriction.model.loading import load_robot
    from wbfriction.replay.refine import refine_mjcf, write_refined

    tables = [read_table(path) for path in logs]  # any log format (the registry's)
    for before, after, path in zip(tables, tables[1:], logs[1:]):
        if after.num_rows and before.num_rows and after["time"][0].as_py() <= before["time"][-1].as_py():
            raise InputError(f"{path}: its times do not follow those of the log before it")
    robot = load_robot(None, config=Path(identified_toml))
    refinement = refine_mjcf(mjcf, robot, pa.concat_tables(tables))
    write_refined(mjcf, refinement, robot, output)
    return Path(output)
