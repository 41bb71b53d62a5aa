"""A PD-driven robot's log: the set-points its drivers were sent, and the torque their PD law applied.

Columns (every PD-driven joint of :attr:`Robot.pd <wbfriction.model.robot.Robot.pd>`; :mod:`wbfriction.model.pd`):

=====================  ==========  ==================================================
``q_des.<joint>``      rad         the position set-point commanded at the sample
``qd_des.<joint>``     rad/s       optional velocity set-point (default 0)
``tau_ff.<joint>``     N·m         optional feed-forward torque (default 0)
``kp.<joint>``         N·m/rad     optional gain, where it changes (default the TOML's ``[pd]``)
``kd.<joint>``         N·m·s/rad   optional gain, where it changes (default the TOML's ``[pd]``)
``tau_est.<joint>``    N·m         optional: the driver's own torque estimate (from its current)
=====================  ==========  ==================================================

Where the torque comes from, one source for every joint, the first that the log has (:mod:`wbfriction.logs.torque`):
``tau.<joint>`` (a joint torque sensor), ``tau_est.<joint>`` (the driver's estimate: measured beats modelled),
``current.<joint>`` (times the torque constants), and the PD law on the set-points (``q_des.<joint>``, the drivers'
delay and limits from the TOML). The law runs on the logged angle (the encoder's) and the driver's velocity
(``qd.<joint>``; without it, the positions' central difference); the dynamics then take the model's angle, the
logged one less the TOML's ``[encoder_offset]``.

A continuous joint's set-point is logged as its angle is, wrapped (in (−π, π] or [0, 2π)), while its angle is read
unwrapped (:func:`~wbfriction.logs.log.unwrap_positions`): the set-point is moved by whole turns onto the angle's
branch (:func:`setpoints_on_branch`), so that the law's error ``q_des - q`` is the physical one, within half a turn,
and the set-point runs on continuously where its delay interpolates it (a 2π error was a torque of ``kp 2π``,
157 N·m on the Aliengo's thighs, clipped at the drives' limits: 25 N·m RMS where the log said 0.6).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError
from wbfriction.logs.tables import numeric_columns
from wbfriction.model.layout import principal_angle
from wbfriction.model.pd import PdDriver, pd_torque
from wbfriction.model.robot import Robot
from wbfriction.quantities import RANGES, first_outside

PD_PREFIXES = ("q_des", "qd_des", "tau_ff", "kp", "kd", "tau_est")
"""The column prefixes of a PD-driven robot's log (module docstring)."""


@dataclass(frozen=True, eq=False)
class PdSetpoints:
    """What a log says its PD drivers were sent, each (N, n_pd) in :attr:`PdDriver.joints
    <wbfriction.model.pd.PdDriver.joints>` order: ``q_des`` [rad] (a continuous joint's on the branch of its
    unwrapped angle, :func:`setpoints_on_branch`), ``qd_des`` [rad/s], ``tau_ff`` [N·m] (None: not
    logged, zero), ``kp`` [N·m/rad] and ``kd`` [N·m·s/rad] (None: the TOML's), and the driver's velocity ``qd``
    [rad/s] the law runs on (logged, or the positions' central difference)."""

    q_des: np.ndarray
    qd: np.ndarray
    qd_des: np.ndarray | None = None
    tau_ff: np.ndarray | None = None
    kp: np.ndarray | None = None
    kd: np.ndarray | None = None

    def rows(self, start: int, stop: int) -> PdSetpoints:
        """The rows ``[start, stop)``."""
        cut = lambda x: None if x is None else x[start:stop]  # noqa: E731
        return PdSetpoints(self.q_des[start:stop], self.qd[start:stop], cut(self.qd_des), cut(self.tau_ff),
                           cut(self.kp), cut(self.kd))

    def torque(self, driver: PdDriver, time: np.ndarray, q_logged: np.ndarray, delay: float | None = None
               ) -> np.ndarray:
        """The drivers' torque (N, n_pd) [N·m] (:func:`~wbfriction.model.pd.pd_torque`) on the logged angles
        ``q_logged`` (N, n_pd) [rad], with the drivers' delay or ``delay`` [s]."""
        return pd_torque(driver, time, q_logged, self.qd, self.q_des, self.qd_des, self.tau_ff, kp=self.kp,
                         kd=self.kd, delay=delay)


def pd_columns_named(robot: Robot) -> dict[str, set[str] | None]:
    """The joints each PD column prefix may name: the PD-driven joints for the set-points and gains (None without
    ``[pd]``: :func:`read_setpoints` then refuses them with the reason), the torque-controlled joints for the
    drivers' estimates."""
    joints = set(robot.pd.joints) if robot.pd is not None else None
    named: dict[str, set[str] | None] = dict.fromkeys(PD_PREFIXES, joints)
    named["tau_est"] = set(robot.torque_controlled)
    return named


def read_setpoints(table: pa.Table, robot: Robot, time: np.ndarray, q_logged: np.ndarray, qd_logged: np.ndarray | None,
                   source: str, first_row: int) -> PdSetpoints | None:
    """The set-points of a log with ``q_des.<joint>`` columns (None without any).

    Args:
        table: the log's table.
        robot: the robot (its :attr:`~wbfriction.model.robot.Robot.pd`).
        time: the sample times (N,) [s].
        q_logged: the logged angles of every actuated joint (N, n_act) [rad] (the encoder's, offset included;
            continuous joints unwrapped: their set-points are put on its branch, :func:`setpoints_on_branch`).
        qd_logged: the logged velocities (N, n_act) [rad/s], or None.
        source: the file, for errors.
        first_row: the table's first row in its file.

    Raises:
        ColumnError: ``q_des`` columns without a ``[pd]`` in the robot's TOML, or for some PD-driven joints only;
            an optional column logged for some joints only.
    """
    names = set(table.column_names)
    if not any(c.startswith("q_des.") for c in names):
        return None
    if robot.pd is None:
        col = next(c for c in table.column_names if c.startswith("q_des."))
        raise ColumnError(source, col, None, f"column '{col}' is a PD set-point, but robot '{robot.name}' has no "
                          "[pd] gains in its TOML (kp, kd: wbfriction.model.pd)")
    joints = robot.pd.joints

    def group(prefix: str, required: bool) -> np.ndarray | None:
        return _every_or_none(table, prefix, joints, source, first_row, required)

    index = [robot.actuated.index(j) for j in joints]
    if qd_logged is not None:
        qd = qd_logged[:, index]
    else:
        qd = np.gradient(q_logged[:, index], time, axis=0)
    q_des = group("q_des", True)
    assert q_des is not None
    q_des = setpoints_on_branch(q_des, q_logged[:, index], np.isin(index, robot.layout.q2_joint))
    gains = {prefix: group(prefix, False) for prefix in ("kp", "kd")}
    for prefix, values in gains.items():
        if values is not None:
            _check_gains(prefix, values, joints, source, first_row)
    return PdSetpoints(q_des, qd, group("qd_des", False), group("tau_ff", False), gains["kp"], gains["kd"])


def _check_gains(prefix: str, values: np.ndarray, joints: tuple[str, ...], source: str, first_row: int) -> None:
    """Refuse a logged gain outside its physical range (:data:`~wbfriction.quantities.RANGES`: a negative gain
    pushes the joint away from its set-point), naming the column and row."""
    bad = first_outside(prefix, values)
    if bad is not None:
        row, k = divmod(bad, len(joints))
        rng, col = RANGES[prefix], f"{prefix}.{joints[k]}"
        raise ColumnError(source, col, first_row + row, f"column '{col}' at row {first_row + row}: "
                          f"{values[row, k]:g} {rng.unit} is outside {rng.span()}: {rng.why}")


def setpoints_on_branch(q_des: np.ndarray, q: np.ndarray, continuous: np.ndarray) -> np.ndarray:
    """Position set-points ``q_des`` (N, n) [rad] with those of the continuous joints (``continuous`` (n,) bool)
    moved by whole turns onto the branch of the joints' unwrapped angles ``q`` (N, n) [rad]:
    ``q + principal_angle(q_des - q)`` (:func:`~wbfriction.model.layout.principal_angle`; module docstring); the
    others as given (``q_des`` itself without a continuous joint)."""
    continuous = np.asarray(continuous, dtype=bool)
    if not continuous.any():
        return q_des
    out = np.array(q_des, dtype=float)
    out[:, continuous] = q[:, continuous] + principal_angle(q_des[:, continuous] - q[:, continuous])
    return out


def driver_estimate(table: pa.Table, robot: Robot, source: str, first_row: int) -> np.ndarray | None:
    """The drivers' own torque estimates ``tau_est.<joint>`` of the torque-controlled joints (N, n_tc) [N·m], or
    None if the log has none.

    Raises:
        ColumnError: ``tau_est`` logged for some torque-controlled joints only.
    """
    return _every_or_none(table, "tau_est", robot.torque_controlled, source, first_row)


def _every_or_none(table: pa.Table, prefix: str, joints: tuple[str, ...], source: str, first_row: int,
                   required: bool = False) -> np.ndarray | None:
    """The columns ``<prefix>.<joint>`` of every joint (N, n), or None if the log has none and they are not
    ``required``.

    Raises:
        ColumnError: the columns of some joints only, naming the first one missing.
    """
    cols = [f"{prefix}.{j}" for j in joints]
    there = [c in table.column_names for c in cols]
    if not any(there) and not required:
        return None
    if not all(there):
        missing = cols[there.index(False)]
        raise ColumnError(source, missing, None, f"missing column '{missing}': {prefix}.* is logged for some joints "
                          "only; log it for every one, or for none")
    return numeric_columns(table, cols, source, first_row)


def pd_law_torque(robot: Robot, setpoints: PdSetpoints, time: np.ndarray, q_logged: np.ndarray, source: str
                  ) -> np.ndarray:
    """The torque-controlled joints' torques (N, n_tc) [N·m] from the PD law (module docstring).

    Raises:
        ColumnError: a torque-controlled joint that is not PD-driven (it has no torque column either).
    """
    assert robot.pd is not None
    missing = [n for n in robot.torque_controlled if n not in robot.pd.joints]
    if missing:
        raise ColumnError(source, f"tau.{missing[0]}", None, f"missing column 'tau.{missing[0]}': '{missing[0]}' "
                          "is torque-controlled but not PD-driven (not in [pd] joints) and has no torque column")
    index = [robot.actuated.index(j) for j in robot.pd.joints]
    tau = setpoints.torque(robot.pd, time, q_logged[:, index])
    pos = {j: i for i, j in enumerate(robot.pd.joints)}
    return tau[:, [pos[n] for n in robot.torque_controlled]]


def setpoint_columns(setpoints: PdSetpoints, joints: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The log columns of ``setpoints`` (the inverse of :func:`read_setpoints`; the driver's velocity is the log's
    ``qd.<joint>``, written with the other rates)."""
    cols: dict[str, np.ndarray] = {}
    for prefix in ("q_des", "qd_des", "tau_ff", "kp", "kd"):
        x = getattr(setpoints, prefix)
        if x is not None:
            cols.update({f"{prefix}.{j}": x[:, i] for i, j in enumerate(joints)})
    return cols
