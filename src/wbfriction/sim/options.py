"""The choices a user makes about the simulators and their sensors, in a module that imports nothing heavy:
the command line shows their defaults in its help without loading NumPy, Pinocchio or MuJoCo (the methods that
draw sensor errors import NumPy when they run)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, get_args

from wbfriction.choices import check_choice
from wbfriction.exceptions import InputError

if TYPE_CHECKING:
    import numpy as np

@dataclass(frozen=True)
class SensorNoise:
    """Sensor imperfections (all off by default).

    Attributes:
        position_std: standard deviation of the joint-position noise [rad].
        encoder_bits: encoder resolution in bits per turn (e.g. 19), or None for none.
        torque_std: standard deviation of the torque-sensor noise [N·m].
        seed: seed of the noise generator (same seed, same noise).
    """

    position_std: float = 0.0
    encoder_bits: int | None = None
    torque_std: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.position_std < 0 or self.torque_std < 0:
            raise InputError("sensor noise standard deviations must be >= 0")
        if self.encoder_bits is not None and not 1 <= self.encoder_bits <= 52:
            raise InputError(f"encoder bits must be between 1 and 52, got {self.encoder_bits}")

    @property
    def resolution(self) -> float | None:
        """Encoder step [rad], or None."""
        return None if self.encoder_bits is None else 2.0 * math.pi / 2.0**self.encoder_bits


    @property
    def active(self) -> bool:
        """Whether the sensors change anything."""
        return self.position_std > 0 or self.encoder_bits is not None or self.torque_std > 0

    def draw(self, n: int, n_q: int, n_tau: int) -> tuple[np.ndarray, np.ndarray]:
        """The position (n, n_q) [rad] and torque (n, n_tau) [N·m] noise of ``n`` samples,
        from :attr:`seed` (zeros where a noise is off)."""
        import numpy as np

        rng = np.random.default_rng(self.seed)
        eps_q = rng.normal(0.0, self.position_std, (n, n_q)) if self.position_std > 0 else np.zeros((n, n_q))
        eps_tau = rng.normal(0.0, self.torque_std, (n, n_tau)) if self.torque_std > 0 else np.zeros((n, n_tau))
        return eps_q, eps_tau

    def encoder(self, q: np.ndarray) -> np.ndarray:
        """Positions [rad] as the encoder reads them: rounded to its resolution, if any."""
        import numpy as np

        return q if self.resolution is None else np.round(q / self.resolution) * self.resolution


Integrator = Literal["semi-implicit", "explicit"]
"""Euler integration of the ideal simulator."""
INTEGRATORS: tuple[Integrator, ...] = get_args(Integrator)
Projection = Literal["sample", "touch-down"]
"""When the ideal simulator projects the state onto the contact constraints (:class:`IdealOptions`)."""
PROJECTIONS: tuple[Projection, ...] = get_args(Projection)


@dataclass(frozen=True)
class IdealOptions:
    """Parameters of :func:`~wbfriction.sim.ideal.simulate_ideal`.

    Attributes:
        substeps: physics steps per control period (the study uses 10: see
            :data:`wbfriction.studies.simulation.SIMULATOR`).
        integrator: one of :data:`INTEGRATORS`. With one explicit Euler step per sample
            the central second difference at ``k`` is the acceleration of sample ``k - 1``,
            which no torque alignment matches (the thesis's setting: F_v up to 25 % off in
            the study); with several substeps the log approaches continuous time.
        bandwidth: joint PD bandwidth [Hz]; damping: its damping ratio.
        gain_blend: time over which PD gains rise to those of a new contact state [s]
            (a landing leg's small tracking error times the stance gains would
            otherwise pull the foot on the ground); falling gains apply at once.
        baumgarte: (Kp [1/s^2], Kd [1/s]) of the contact and position-control constraints.
        log_base: write the base pose to the log (and its true twist and acceleration).
        force_torque: write what the robot's force-torque sensors measure
            (:attr:`~wbfriction.model.robot.Robot.ft_sensors`, columns ``wrench.<sensor>.*``: the
            contact wrenches and the motion of the part below each sensor,
            :func:`~wbfriction.model.force_torque.sensor_readings`).
        imu: write what the robot's IMU reads (:attr:`~wbfriction.model.robot.Robot.imu`, columns
            ``imu.*``, :func:`~wbfriction.model.imu.imu_readings`).
        projection: ``"sample"``: project the velocity onto the constraints at every
            logged sample (the logged state satisfies ``J v = 0`` exactly: ground truth to
            1e-9 N·m); ``"touch-down"``: only at contact changes, Baumgarte correcting the
            drift (truth to about 1e-4 N·m).
        temperature: the joints' temperature at the log's start and end [°C], a linear warm-up logged as
            ``temperature.<joint>`` (what a ``temperature`` term of the injected friction sees); None: not logged.
    """

    substeps: int = 1
    integrator: Integrator = "semi-implicit"
    bandwidth: float = 15.0
    damping: float = 0.9
    gain_blend: float = 0.1
    baumgarte: tuple[float, float] = (400.0, 40.0)
    log_base: bool = True
    projection: Projection = "sample"
    force_torque: bool = False
    imu: bool = False
    temperature: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        check_choice("integrator", self.integrator, INTEGRATORS)
        check_choice("projection", self.projection, PROJECTIONS)
        if self.substeps < 1:
            raise InputError(f"substeps must be at least 1, got {self.substeps}")


FrictionMode = Literal["model", "mujoco"]
"""How the MuJoCo simulator applies friction (:mod:`wbfriction.sim.mujoco_sim`)."""
FRICTION_MODES: tuple[FrictionMode, ...] = get_args(FrictionMode)


@dataclass(frozen=True)
class MujocoOptions:
    """Parameters of :func:`~wbfriction.sim.mujoco_sim.simulate_mujoco`.

    Attributes:
        substeps: physics steps per control period (the physics step is ``dt / substeps``).
        bandwidth: PD bandwidth [Hz]; damping: its damping ratio.
        max_gains: (kp [N·m/rad], kd [N·m·s/rad]) caps of every joint's gains.
        gain_blend: time over which rising gains ramp to a new contact state's [s].
        contact_threshold: normal force above which a sole counts as in contact [N].
        friction: ``"model"`` (eq. 3.5 as a joint torque) or ``"mujoco"`` (MuJoCo's
            ``frictionloss`` and ``damping``), :mod:`wbfriction.sim.mujoco_sim`.
        sensors: sensor noise of the controller's and the log's measurements.
        delay: time from a measurement to the command computed from it acting [s], a
            whole number of control periods.
        balance: (K [N·m/rad], D [N·m·s/rad]) of the base-attitude stabiliser on the
            stance ankles (:func:`~wbfriction.sim.control.attitude_ankle_torques`); None:
            the robot's :attr:`~wbfriction.model.robot.Robot.balance_gains`.
        fall_height: the simulation stops with an error when the base drops below this
            share of its initial height.
        log_base: write the base pose to the log (and its true twist and acceleration).
        force_torque: write what the robot's force-torque sensors measure (``wrench.<sensor>.*``):
            MuJoCo's ``force`` and ``torque`` sensors between each sensor's link and the sole plate
            below it (:func:`~wbfriction.sim.mujoco_model.build_mujoco_robot`), averaged over the
            physics steps around the sample (:func:`~wbfriction.sim.mujoco_sim.matched_weights`), as
            a sensor that filters before it samples (a soft contact's force varies within a period:
            its reading at one step, against accelerations differentiated over two periods, was 6
            times further off, 0.155 against 0.025 N·m median RMS, measured).
        sole_timeconst: the soles' contact time constant [s] (MuJoCo's ``solref[0]``: how soft the
            contact is); None: MuJoCo's default (0.02 s). A compliant rubber sole: larger.
        friction_timeconst: with ``friction = "mujoco"``, the friction-loss constraint's time constant [s]
            (MuJoCo's ``solreffriction``; :mod:`~wbfriction.sim.mujoco_sim`); None: two physics steps, the stiffest
            MuJoCo integrates (0.02 s, MuJoCo's default, makes its friction lead the velocity by 10 ms).
        torque_drift: rate [N·m/s] at which each torque sensor's offset drifts from zero over the walk
            (the sign per joint drawn from ``sensors.seed``): a slow sensor drift, off by default.
        ft_offset: standard deviations of constant offsets of the force-torque sensors' forces [N] and
            torques [N·m], drawn per sensor and axis from ``sensors.seed``; off by default.
        imu: write what the robot's IMU reads (``imu.*``: MuJoCo's ``gyro`` and ``accelerometer`` at its
            frame, averaged over the physics steps around the sample as the wrenches).
        imu_noise: standard deviations of the gyro's [rad/s] and the accelerometer's [m/s^2] white noise.
        imu_bias: standard deviations of their constant biases, drawn per axis from ``sensors.seed``.
        temperature: the joints' temperature at the log's start and end [°C], a linear warm-up logged as
            ``temperature.<joint>`` (what a ``temperature`` term of the injected friction sees); None: not logged.
    """

    substeps: int = 4
    bandwidth: float = 10.0
    damping: float = 0.9
    max_gains: tuple[float, float] = (3000.0, 60.0)
    gain_blend: float = 0.1
    contact_threshold: float = 50.0
    friction: FrictionMode = "model"
    sensors: SensorNoise = SensorNoise()
    delay: float = 0.0
    balance: tuple[float, float] | None = None
    fall_height: float = 0.5
    log_base: bool = True
    force_torque: bool = True
    sole_timeconst: float | None = None
    friction_timeconst: float | None = None
    torque_drift: float = 0.0
    ft_offset: tuple[float, float] = (0.0, 0.0)
    imu: bool = True
    imu_noise: tuple[float, float] = (0.0, 0.0)
    imu_bias: tuple[float, float] = (0.0, 0.0)
    temperature: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.substeps < 1:
            raise InputError(f"substeps must be at least 1, got {self.substeps}")
        if self.contact_threshold <= 0:
            raise InputError("the contact threshold must be a positive force [N]")
        check_choice("mujoco_friction", self.friction, FRICTION_MODES)
        if self.delay < 0:
            raise InputError(f"the delay must be >= 0 s, got {self.delay}")
        if self.sole_timeconst is not None and not self.sole_timeconst > 0:
            raise InputError(f"the soles' contact time constant must be > 0 s, got {self.sole_timeconst}")
        if self.friction_timeconst is not None and not self.friction_timeconst > 0:
            raise InputError(f"--friction-timeconst must be > 0 s, got {self.friction_timeconst}")
        if self.torque_drift < 0 or min(self.ft_offset) < 0 or min(self.imu_noise) < 0 or min(self.imu_bias) < 0:
            raise InputError("the torque drift rate and the standard deviations of the force-torque offsets and "
                             "of the IMU's noise and biases must be >= 0")

    def imu_errors(self, n: int) -> np.ndarray:
        """The IMU's white noise plus constant biases over ``n`` periods (n, 6): gyro [rad/s], accelerometer
        [m/s^2], from :attr:`imu_noise`, :attr:`imu_bias` and the sensors' seed (zeros where off)."""
        import numpy as np

        rng = np.random.default_rng([self.sensors.seed, 6])
        noise = rng.normal(0.0, 1.0, (n, 6)) * np.repeat(np.asarray(self.imu_noise, dtype=float), 3)
        return noise + rng.normal(0.0, 1.0, 6) * np.repeat(np.asarray(self.imu_bias, dtype=float), 3)

    def imperfections(self, n: int, dt: float, n_tau: int, n_sensors: int) -> tuple[np.ndarray, np.ndarray]:
        """The torque sensors' drifting offsets (n, n_tau) [N·m] over ``n`` periods of ``dt`` and the force-torque
        sensors' constant offsets (n_sensors, 6) [N, N·m], from :attr:`torque_drift`, :attr:`ft_offset` and the
        sensors' seed (zeros where off)."""
        import numpy as np

        rng = np.random.default_rng([self.sensors.seed, 23])
        drift = np.arange(n)[:, None] * dt * self.torque_drift * rng.choice([-1.0, 1.0], n_tau)
        scale = np.repeat(np.asarray(self.ft_offset, dtype=float), 3)
        return drift, rng.normal(0.0, 1.0, (n_sensors, 6)) * scale

    def delay_periods(self, dt: float) -> int:
        """:attr:`delay` in control periods of ``dt`` seconds.

        Raises:
            InputError: the delay is not a whole number of periods.
        """
        d = self.delay / dt
        if abs(d - round(d)) > 1e-6:
            raise InputError(f"the delay ({self.delay * 1e3:g} ms) must be a multiple of the control period "
                             f"({dt * 1e3:g} ms)")
        return int(round(d))
