"""Where a log's torques come from, said the same way in every output (:attr:`Log.torque_source
<wbfriction.logs.log.Log.torque_source>`; the PD law's: :mod:`wbfriction.logs.pd`)."""

from __future__ import annotations

from typing import Literal

from wbfriction.logs.pd import PdSetpoints
from wbfriction.model.robot import Robot

TorqueSource = Literal["sensor", "driver", "current", "pd"]
"""Where a log's torques come from (:attr:`Log.torque_source <wbfriction.logs.log.Log.torque_source>`)."""
TORQUE_SOURCES: dict[str, str] = {
    "sensor": "joint torque sensors (tau.<joint>)",
    "driver": "the motor drivers' own estimates (tau_est.<joint>)",
    "current": "motor currents times the torque constants (current.<joint>)",
    "pd": "the drivers' PD law on q_des.<joint>"}
"""What each torque source is, as the outputs say it (:data:`TorqueSource`)."""


def torque_record(robot: Robot, source: TorqueSource, setpoints: PdSetpoints | None) -> dict[str, object]:
    """Where a log's torques come from, for every output's metadata: ``source`` (:data:`TorqueSource`), ``what``
    (:data:`TORQUE_SOURCES`), and for the PD law its delay [s], what the delay holds back (``delayed``:
    :mod:`wbfriction.model.pd`) and where its gains come from; where the log ``identify`` found the delay on did not
    tell what it holds back (:attr:`~wbfriction.model.pd.PdDriver.delayed_known` false), ``delayed_known`` false
    and per joint the viscous coefficient the two differ by (``viscous_equivalent`` [N·m·s/rad], ``kp delay``),
    which the friction's F_v carries (:func:`~wbfriction.fit.joints.fit_estimate`); a log of measured torques that
    also holds set-points, ``setpoints`` "not used" (the measured torque is taken, the PD law is not)."""
    record: dict[str, object] = {"source": source, "what": TORQUE_SOURCES[source]}
    if source != "pd" and setpoints is not None:
        record |= {"setpoints": "not used"}
    if source == "pd" and robot.pd is not None and setpoints is not None:
        logged = setpoints.kp is not None or setpoints.kd is not None
        record |= {"delay": robot.pd.delay, "delayed": robot.pd.delayed,
                   "gains": "kp/kd columns" if logged else "the robot's [pd]"}
        if not robot.pd.delayed_known:
            record |= {"delayed_known": False, "viscous_equivalent": robot.pd.viscous_equivalent()}
    return record
