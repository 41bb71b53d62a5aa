"""What a hung PD-driven robot's log determines of each joint, from how the joint moved (issue 63): a parameter
whose column the motion does not excite is not ``ok``, whatever its standard error says.

The balance's columns (:mod:`wbfriction.actuator.rows`) are built from the velocities, whose noise fills them even
where the joint holds still: a driver's velocity of 0.08 rad/s white noise gives ``int tanh(a qd)`` a column of
full height on a joint that never moved, and the least squares then "determines" F_c, F_v and the armature on
noise, with standard errors as small as on a ramp (a hung Go2 on still set-points: a thigh's F_v 24.5 ± 5.7 against
0.21). What the joint moved is read from the encoder's positions over each window (:attr:`BalanceRows.speed
<wbfriction.actuator.rows.BalanceRows.speed>`, ``Delta q_enc / window``: a 40 ms window's mean speed has the
noise of two readings over 40 ms, 1.2e-4 rad/s on 19-bit encoders), with the thresholds of the friction fit's
statuses (:mod:`wbfriction.fit.status`):

* **not excited**: the 95th percentile of the windows' ``|speed|`` below :data:`~wbfriction.fit.status.MIN_SPEED`:
  the joint hardly moved. Its armature, friction and offset are not in the log (the offset of a joint held still is
  one column with the friction that holds it, anywhere within ``±F_c``).
* **weak** (F_c and the offset): the joint moved one way (the windows faster than
  :data:`~wbfriction.fit.status.MIN_SPEED` the other way fewer than :data:`~wbfriction.fit.status.MIN_REVERSE`):
  its Coulomb friction and its offset's torque are then one column but for those few windows.

A drive's constant torque (``tau_os``, what ``refine`` moves in an exported MJCF: :mod:`wbfriction.replay.refine`)
is judged as the offset: a constant torque, one column with F_c on a joint that moved one way, anywhere within
``±F_c`` on one held still. ``refine`` takes the same windows of its stretch's logged angles
(:func:`stretch_motion`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.actuator.options import WINDOW
from wbfriction.actuator.rows import BalanceRows
from wbfriction.fit.status import MIN_REVERSE, MIN_SPEED, reverse_share

NOT_EXCITED = ("armature", "F_v", "F_c", "offset", "tau_os")
"""The parameters a joint that hardly moved does not determine."""
ONE_WAY = ("F_c", "offset", "tau_os")
"""The parameters a joint that moved one way does not separate."""


@dataclass(frozen=True)
class JointMotion:
    """How one joint moved over the windows used.

    Attributes:
        speed: the 95th percentile of the windows' ``|Delta q_enc| / window`` [rad/s].
        reverse: the share of the windows faster than :data:`~wbfriction.fit.status.MIN_SPEED` moving the less
            frequent way (:func:`~wbfriction.fit.status.reverse_share`).
    """

    speed: float
    reverse: float

    @property
    def excited(self) -> bool:
        """It moved (module docstring)."""
        return self.speed >= MIN_SPEED

    def verdict(self, kind: str) -> tuple[str, str] | None:
        """The status and reason the motion gives the parameter ``kind`` (``armature``, ``F_v``, ``F_c``,
        ``offset``), or None where it leaves the fit's own."""
        if not self.excited and kind in NOT_EXCITED:
            return "not excited", (f"{kind}: the joint hardly moved (|Δq| over a window at most {self.speed:.2g} "
                                   f"rad/s on 95 % of them, below {MIN_SPEED:g})")
        if self.reverse < MIN_REVERSE and kind in ONE_WAY:
            return "weak", (f"{kind}: the joint moved one way ({self.reverse:.1%} of its moving windows the other): "
                            "its Coulomb friction and offset are not separable")
        return None


def joint_motion(rows: BalanceRows) -> tuple[JointMotion, ...]:
    """Each joint's :class:`JointMotion` over its usable windows (module docstring)."""
    return tuple(window_motion(rows.speed[rows.usable[:, j], j]) for j in range(len(rows.joints)))


def window_motion(speed: np.ndarray) -> JointMotion:
    """One joint's :class:`JointMotion` from its windows' mean speeds ``speed`` (W,) [rad/s]; not excited without
    a window."""
    if len(speed) == 0:
        return JointMotion(0.0, 0.0)
    moving = speed[np.abs(speed) >= MIN_SPEED]
    return JointMotion(float(np.percentile(np.abs(speed), 95)), reverse_share(moving) if len(moving) else 0.0)


def stretch_motion(time: np.ndarray, q: np.ndarray, window: float = WINDOW) -> tuple[JointMotion, ...]:
    """Each joint's :class:`JointMotion` over a stretch of a log, its ``time`` (N,) [s] and logged angles ``q``
    (N, n) [rad]: cut into whole windows of ``window`` [s] (in samples, at the median period, as the balance's
    rows cut a log), each window's ``Delta q / Delta t``; a stretch shorter than one window is not excited."""
    period = float(np.median(np.diff(time))) if len(time) > 1 else np.inf
    m = max(1, int(round(window / period))) if np.isfinite(period) and period > 0 else len(time)
    ends = np.arange((len(time) - 1) // m + 1) * m
    speed = (q[ends[1:]] - q[ends[:-1]]) / (time[ends[1:]] - time[ends[:-1]])[:, None]
    return tuple(window_motion(speed[:, j]) for j in range(q.shape[1]))
