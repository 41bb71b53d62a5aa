"""What a walking robot's logger does to the samples (issue 82): a simulated quadruped's run written as the raw log a
real robot writes, with the truth beside it in columns no robot's log has.

**The clocks.** The drives update at the simulation's sample period (``T_d``, 2 ms), the IMU at its own
(:attr:`LoggerOptions.imu_period`, 5 ms), and the logger ticks at :attr:`LoggerOptions.period` (1.22 ms), all
starting at the run's first sample. Logger tick ``i`` (at ``i P``) writes the latest drive sample, ``k = floor(i P /
T_d)``, so that a row repeats the previous one wherever no drive sample came in between (``1 - P / T_d`` of the rows:
39 % at the defaults), and the IMU's latest update ``j = floor(i P / P_imu)``, which read the state of the simulation's
latest sample at its instant, ``m = floor(j P_imu / T_d)`` (the IMU repeats on ``1 - P / P_imu`` of the rows: 76 %).
The IMU's updates thus hold the states of the 2 ms samples, not of their own instants (``imu_sample_true`` says
which).

**The columns** (no ``time`` unless :attr:`LoggerOptions.stamps` is ``"logger"``: the nominal period is the metadata's
``logger.period`` [s]):

* ``q.<joint>`` [rad] the encoders' angles (their offset, noise and rounding), or ``q_cos.<joint>``,
  ``q_sin.<joint>`` (:attr:`LoggerOptions.angles`);
* ``qd.<joint>`` [rad/s] the drives' velocities (where the run has them);
* ``current.<joint>`` [A]: the motor's torque over its true torque constant, ``tau / (k_t (1 + e_j))``, with ``k_t``
  the robot's ``[torque_constants]`` (the nominal one) and ``e_j`` drawn uniformly in ``±``
  :attr:`LoggerOptions.kt_error` (the metadata's ``logger_true.torque_constant_error``): the current times the
  nominal constant is the torque ``1 / (1 + e_j)`` off. The torque is the one the motor applies, the run's command
  (MuJoCo's actuator on a joint whose armature models the rotor: the rotor's inertia is in it), plus its noise;
* ``imu.roll``, ``imu.pitch``, ``imu.yaw`` [rad]: the IMU frame's orientation in the world (``pin.rpy.matrixToRpy``
  of its rotation: ``R = Rz(yaw) Ry(pitch) Rx(roll)``), turned by a random rotation of
  :attr:`LoggerOptions.orientation_std` per axis; ``imu.gyro_x`` ... ``imu.gyro_z`` [rad/s] the run's gyro (its
  noise); ``imu.acc_x`` ... ``imu.acc_z`` [m/s^2] only with :attr:`LoggerOptions.accelerometer`;
* ``foot_count.<frame>`` (with :attr:`LoggerOptions.foot_counts`): a raw foot-force sensor's counts, ``round(o_c +
  s_c f_c + s_c n)``, ``f_c`` the ground's true normal force on the foot [N], ``n`` white noise of
  :attr:`LoggerOptions.count_std` [N], offsets ``o_c`` in [20, 120] counts and scales ``s_c`` in [0.8, 1.6]
  counts/N drawn per foot (``logger_true.foot_counts``);
* no contact flag, no foot force, no base pose.

**The truth** (:data:`~wbfriction.logs.columns.TRUTH_PREFIXES`, :data:`~wbfriction.logs.columns.TRUTH_COLUMNS`: the
estimator never reads them): ``time_true`` [s] and ``sample_true`` (the time and index of the drive sample the row
holds: the repeats are the rows whose ``sample_true`` is the previous row's), ``imu_sample_true`` (the sample the
IMU's update holds), ``tau_f_true.<joint>``, ``qd_true.<joint>``, ``contact_true.<frame>`` (1 where the simulator's
ground holds the foot: a contact with a nonzero normal force), ``base_true.x`` ... ``base_true.qw`` (the base's
pose) and ``base_qd_true.*`` (its twist, Pinocchio's free-flyer convention). Metadata: the run's (``friction_true``,
``armature_true``, ...), ``logger`` (what the robot's user knows: the period, the angles' form, whether stamped) and
``logger_true`` (the clocks, the drawn errors, the seed).

Each random draw has its own stream of :attr:`LoggerOptions.seed` (the torque constants, the orientation's noise,
the counts' calibration, their noise), so that asking for foot counts changes no other column.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Literal, get_args

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError, OptionError
from wbfriction.logs.columns import BASE_QD_TRUE_COLUMNS, BASE_TRUE_COLUMNS
from wbfriction.logs.metadata import with_metadata

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.quadruped import QuadrupedRun

Angles = Literal["angles", "cos-sin"]
ANGLES: tuple[Angles, ...] = get_args(Angles)
Stamps = Literal["none", "logger"]
STAMPS: tuple[Stamps, ...] = get_args(Stamps)
RPY_COLUMNS = ("imu.roll", "imu.pitch", "imu.yaw")
"""The IMU frame's orientation in the world [rad] (``pin.rpy.matrixToRpy``)."""
GYRO_COLUMNS = ("imu.gyro_x", "imu.gyro_y", "imu.gyro_z")
ACC_COLUMNS = ("imu.acc_x", "imu.acc_y", "imu.acc_z")
ORIENTATION_STD = 1e-3
"""The noisy twin's IMU orientation noise [rad] per axis (0.06°), white at the IMU's updates: an on-board attitude
filter's sample-to-sample scatter (a MEMS unit's roll and pitch hold within a few tenths of a degree; the scatter
between updates, which a derivative sees, is far smaller)."""
COUNT_OFFSET = (20.0, 120.0)
"""The range of the raw foot-force counts' offsets drawn per foot [counts]."""
COUNT_SCALE = (0.8, 1.6)
"""The range of their scales drawn per foot [counts/N]."""
STREAMS = {"torque_constants": 1, "orientation": 2, "counts": 3, "count_noise": 4}
"""Each random draw's stream of the seed (``np.random.default_rng([seed, stream])``)."""


@dataclass(frozen=True)
class LoggerOptions:
    """What a robot's logger does (module docstring).

    Attributes:
        period: the logger's period [s] (its nominal rate, the metadata's ``logger.period``).
        imu_period: the IMU's update period [s].
        angles: :data:`Angles`: ``angles`` (``q.<joint>``) or ``cos-sin`` (``q_cos.<joint>``, ``q_sin.<joint>``).
        kt_error: the torque constants' error bound: each joint's true constant is the nominal one times ``1 + e``,
            ``e`` uniform in ``[-kt_error, kt_error]``.
        stamps: :data:`Stamps`: ``none`` (no ``time`` column) or ``logger`` (the logger's tick times [s]).
        accelerometer: log ``imu.acc_*``.
        foot_counts: log raw foot-force counts ``foot_count.<frame>``.
        orientation_std: the IMU orientation's noise [rad] per axis (:data:`ORIENTATION_STD` the noisy twin's).
        count_std: the foot counts' noise [N] (times each foot's scale: counts).
        seed: the draws' seed.

    Raises:
        OptionError: a period not > 0, a torque-constant error outside [0, 0.5), a noise < 0, a choice not of
            :data:`ANGLES` or :data:`STAMPS`.
    """

    period: float = 1.22e-3
    imu_period: float = 5e-3
    angles: Angles = "angles"
    kt_error: float = 0.03
    stamps: Stamps = "none"
    accelerometer: bool = False
    foot_counts: bool = False
    orientation_std: float = 0.0
    count_std: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for flag, value in (("period", self.period), ("imu_period", self.imu_period)):
            if not (np.isfinite(value) and value > 0):
                raise OptionError(flag, value, "> 0 [s]")
        if not 0 <= self.kt_error < 0.5:
            raise OptionError("--kt-error", self.kt_error, "in [0, 0.5) (a share of the nominal torque constant)")
        for flag, value in (("orientation_std", self.orientation_std), ("count_std", self.count_std)):
            if not (np.isfinite(value) and value >= 0):
                raise OptionError(flag, value, ">= 0")
        for flag, choice, choices in (("--angles", self.angles, ANGLES), ("stamps", self.stamps, STAMPS)):
            if choice not in choices:
                raise OptionError(flag, choice, f"one of {', '.join(choices)}")

    def rng(self, stream: str) -> np.random.Generator:
        """The random generator of one draw (:data:`STREAMS`)."""
        return np.random.default_rng([self.seed, STREAMS[stream]])


@dataclass(frozen=True)
class LoggerClocks:
    """Which samples each logger tick holds (module docstring).

    Attributes:
        sample: the drive sample of each row (rows,).
        imu_sample: the sample the IMU's latest update holds at each row (rows,).
        imu_update: the IMU's update of each row (rows,), numbered from 0.
        tick: the logger's tick times from the run's first sample [s] (rows,).
        update_sample: the sample each IMU update holds, from the first to the last the rows hold (updates,).
    """

    sample: np.ndarray
    imu_sample: np.ndarray
    imu_update: np.ndarray
    tick: np.ndarray
    update_sample: np.ndarray

    def repeats(self) -> np.ndarray:
        """Whether each row repeats the previous row's drive sample (rows,) (the first row: False)."""
        return np.r_[False, self.sample[1:] == self.sample[:-1]]

    def imu_repeats(self) -> np.ndarray:
        """Whether each row repeats the previous row's IMU update (rows,)."""
        return np.r_[False, self.imu_update[1:] == self.imu_update[:-1]]


def logger_clocks(n: int, drive_period: float, options: LoggerOptions) -> LoggerClocks:
    """The logger's ticks over ``n`` drive samples of ``drive_period`` [s]: every tick before the last drive sample's
    period ends (module docstring).

    Raises:
        InputError: fewer than two drive samples.
    """
    if n < 2:
        raise InputError(f"a raw log needs at least two drive samples, got {n}")
    eps = 1e-9  # a tick on a sample's instant holds that sample (rounding)
    ticks = np.arange(int(np.ceil(n * drive_period / options.period)) + 1)
    sample = np.floor(ticks * (options.period / drive_period) + eps).astype(np.int64)
    ticks = ticks[sample < n]
    sample = sample[sample < n]
    update = np.floor(ticks * (options.period / options.imu_period) + eps).astype(np.int64)
    updates = np.arange(int(update[-1]) + 1)
    update_sample = np.minimum(np.floor(updates * (options.imu_period / drive_period) + eps).astype(np.int64), n - 1)
    return LoggerClocks(sample, update_sample[update], update, ticks * options.period, update_sample)


def torque_constant_errors(robot: Robot, options: LoggerOptions) -> np.ndarray:
    """Each torque-controlled joint's torque-constant error ``e`` (n_tc,): uniform in ``±kt_error``, its own
    stream."""
    return options.rng("torque_constants").uniform(-options.kt_error, options.kt_error, len(robot.torque_controlled))


def imu_orientation(robot: Robot, q: np.ndarray, options: LoggerOptions) -> np.ndarray:
    """The IMU frame's world orientation as roll, pitch, yaw (n, 3) [rad] at the configurations ``q`` (n, nq) (the
    IMU's updates in order, from the first), each turned by a rotation ``exp(std * n)``, ``n`` (3,) standard normal
    (its noise, from its stream: update ``j`` takes draw ``j``)."""
    import pinocchio as pin

    assert robot.imu is not None
    model, frame = robot.model, robot.imu.frame
    data = model.createData()
    noise = options.rng("orientation").normal(0.0, options.orientation_std, (len(q), 3)) \
        if options.orientation_std > 0 else None
    out = np.empty((len(q), 3))
    for i, qi in enumerate(q):
        pin.forwardKinematics(model, data, qi)
        pin.updateFramePlacement(model, data, frame)
        R = data.oMf[frame].rotation
        if noise is not None:
            R = R @ pin.exp3(noise[i])
        out[i] = pin.rpy.matrixToRpy(R)
    return out


def foot_counts(normal: np.ndarray, options: LoggerOptions) -> tuple[np.ndarray, dict]:
    """Raw foot-force counts (N, n_feet) of the feet's true normal forces ``normal`` (N, n_feet) [N] (module
    docstring), and their calibration (the metadata's ``offset``, ``scale`` per foot, in the feet's order)."""
    n_feet = normal.shape[1]
    rng = options.rng("counts")
    offset = rng.uniform(COUNT_OFFSET[0], COUNT_OFFSET[1], size=n_feet)
    scale = rng.uniform(COUNT_SCALE[0], COUNT_SCALE[1], size=n_feet)
    noise = options.rng("count_noise").normal(0.0, options.count_std, normal.shape) if options.count_std > 0 \
        else np.zeros(normal.shape)
    counts = np.round(offset + scale * (normal + noise))
    return counts, {"offset": np.asarray(offset).tolist(), "scale": np.asarray(scale).tolist()}


def check_raw_robot(robot: Robot) -> None:
    """Refuse, before any simulation, a robot whose raw log cannot be written: one line naming what it lacks.

    Raises:
        InputError: no ``[imu]``; a torque-controlled joint without its ``[torque_constants]`` (the currents'
            nominal constant) or without its ``[armature]`` (the rotor a motor's current also drives).
    """
    where = f"robot '{robot.name}'"
    if robot.imu is None:
        raise InputError(f"{where}: a raw log holds the IMU's orientation and rate: the robot TOML needs an [imu]")
    missing = [j for j in robot.torque_controlled if j not in robot.torque_constants]
    if missing:
        raise InputError(f"{where}: a raw log's currents need every joint's nominal torque constant: "
                         f"[torque_constants] lacks '{missing[0]}' (the built-in go2_logged's TOML has them)")
    armature = robot.model.armature[robot.act_v_index]
    bare = [j for j, a in zip(robot.actuated, armature) if not a > 0]
    if bare:
        raise InputError(f"{where}: a motor's current drives its rotor too: [armature] lacks '{bare[0]}' (the "
                         "rotor's reflected inertia, kg·m^2)")


def write_raw_log(run: QuadrupedRun, robot: Robot, options: LoggerOptions = LoggerOptions()) -> pa.Table:
    """The raw log a robot's logger writes of ``run`` (module docstring), with the truth beside it.

    Args:
        run: a walking quadruped's run (:func:`~wbfriction.sim.quadruped_mujoco.simulate_quadruped_mujoco`, or the
            ideal simulator's), its log with the IMU's readings.
        robot: the robot simulated (its ``[torque_constants]``, ``[imu]``, contact frames, encoder offsets).
        options: :class:`LoggerOptions`.

    Returns:
        A table, one row per logger tick (module docstring's columns), its metadata under ``wbfriction``.

    Raises:
        InputError: what :func:`check_raw_robot` refuses; a run without the IMU's readings.
    """
    check_raw_robot(robot)
    log = run.log
    if log.imu is None:
        raise InputError(f"robot '{robot.name}': the run logged no IMU reading (QuadrupedOptions.imu)")
    period = float(run.reference.dt)  # the drives' update period: the simulation's sample period
    clocks = logger_clocks(len(log), period, options)
    k, m = clocks.sample, clocks.imu_sample
    cols: dict[str, np.ndarray] = {}
    if options.stamps == "logger":
        cols["time"] = log.time[0] + clocks.tick
    errors = torque_constant_errors(robot, options)
    cols.update(_joint_columns(run, robot, options, k, errors))
    rpy = imu_orientation(robot, run.q[clocks.update_sample], options)[clocks.imu_update]
    cols.update({c: rpy[:, i] for i, c in enumerate(RPY_COLUMNS)})
    cols.update({c: log.imu[m, i] for i, c in enumerate(GYRO_COLUMNS)})
    if options.accelerometer:
        cols.update({c: log.imu[m, 3 + i] for i, c in enumerate(ACC_COLUMNS)})
    calibration = None
    if options.foot_counts:
        counts, calibration = foot_counts(run.force[..., 2], options)
        cols.update({f"foot_count.{f}": counts[k, c] for c, f in enumerate(robot.contact_frames)})
        calibration = {"feet": list(robot.contact_frames), **calibration}
    cols.update(_truth_columns(run, robot, clocks))
    meta = dict(log.metadata)
    meta["logger"] = {"period": options.period, "angles": options.angles, "stamps": options.stamps}
    meta["logger_true"] = {
        "options": asdict(options), "drive_period": period, "imu_period": options.imu_period,
        "rows": len(k), "repeated_rows": int(clocks.repeats().sum()),
        "imu_repeated_rows": int(clocks.imu_repeats().sum()),
        "torque_constant_error": dict(zip(robot.torque_controlled, errors.tolist())),
        "torque_constants_true": {j: robot.torque_constants[j] * (1.0 + e)
                                  for j, e in zip(robot.torque_controlled, errors)},
        "foot_counts": calibration, "orientation_std": options.orientation_std}
    return with_metadata(pa.table(cols), meta)


def _joint_columns(run: QuadrupedRun, robot: Robot, options: LoggerOptions, k: np.ndarray,
                   errors: np.ndarray) -> dict[str, np.ndarray]:
    """The joints' columns of the rows holding drive samples ``k``: the angles (or their cosines and sines), the
    drives' velocities, the currents (module docstring; ``errors`` the torque constants')."""
    log = run.log
    q = log.q + robot.offset_vector if robot.encoder_offset else log.q  # the encoders' angles
    cols: dict[str, np.ndarray] = {}
    for i, j in enumerate(robot.actuated):
        if options.angles == "angles":
            cols[f"q.{j}"] = q[k, i]
        else:
            cols[f"q_cos.{j}"], cols[f"q_sin.{j}"] = np.cos(q[k, i]), np.sin(q[k, i])
    if log.qd_logged is not None:
        cols.update({f"qd.{j}": log.qd_logged[k, i] for i, j in enumerate(robot.actuated)})
    for i, j in enumerate(robot.torque_controlled):
        cols[f"current.{j}"] = log.tau[k, i] / (robot.torque_constants[j] * (1.0 + errors[i]))
    return cols


def _truth_columns(run: QuadrupedRun, robot: Robot, clocks: LoggerClocks) -> dict[str, np.ndarray]:
    """The truth of the rows (module docstring): the drive sample's time and index, the IMU's sample, the friction,
    the joints' velocities, the contacts, the base's pose and twist."""
    log, k = run.log, clocks.sample
    cols: dict[str, np.ndarray] = {"time_true": log.time[k], "sample_true": k, "imu_sample_true": clocks.imu_sample}
    if log.tau_f_true is not None:
        cols.update({f"tau_f_true.{j}": log.tau_f_true[k, i] for i, j in enumerate(robot.torque_controlled)})
    qd = run.v[:, robot.act_v_index]
    cols.update({f"qd_true.{j}": qd[k, i] for i, j in enumerate(robot.actuated)})
    contact = (run.force[..., 2] != 0).astype(np.int8)
    cols.update({f"contact_true.{f}": contact[k, c] for c, f in enumerate(robot.contact_frames)})
    cols.update({c: run.q[k, i] for i, c in enumerate(BASE_TRUE_COLUMNS)})
    cols.update({c: run.v[k, i] for i, c in enumerate(BASE_QD_TRUE_COLUMNS)})
    return cols


def logged_summary(table: pa.Table, what: str) -> str:
    """What ``simulate`` says of a raw log: its rows and period, the share repeating the drives' sample and the IMU's
    update, ``what`` was simulated, its torques' form."""
    from wbfriction.logs.metadata import read_metadata

    true = read_metadata(table)["logger_true"]
    rows = true["rows"]
    return (f"{rows} rows at {true['options']['period'] * 1e3:g} ms, {true['repeated_rows'] / rows:.0%} repeating the "
            f"drives' sample, {true['imu_repeated_rows'] / rows:.0%} the IMU's; {what}, motor currents; the truth "
            "beside it")
