"""The choices of the hung PD-driven robot's simulation (:mod:`wbfriction.sim.hung`): its set-points, its drivers'
sensor noise and the run, in a module that imports only the standard library (the command line shows the defaults
in its help without loading NumPy or MuJoCo).

**The noise of a real driver** (:data:`REAL_DRIVER`), measured on the real Unitree Aliengo log of
``real-data/unitree_aliengo/aliengo_traj_0.pt`` (hung, 200 Hz, 23.5 s; the drivers' own ``dof_vel``):

* the encoder: the logged angles lie on a lattice of 1.198e-5 rad on the hip and thigh joints (``2 pi / 2^19``:
  the fit of the angles' steps to multiples of it leaves 0.04-0.05 of a step, float32's rounding) and of 3.835e-5
  rad on the calves (``2 pi / (5 * 2^15)``: 0.004 of a step). Nothing else: no white noise beyond the lattice's
  (``position_std = 0``).
* the driver's velocity: its difference from the angles' central difference (two periods, 10 ms), away from the
  reversals (no sign change within 100 ms, ``|v| > 0.2`` rad/s), is white (lag-one autocorrelation -0.15 on the
  hips) and grows with the speed alike on every joint: RMS 0.08 rad/s at 0.2-0.6 rad/s, 0.11-0.16 at 0.6-1,
  0.16-0.22 at 1-2, 0.27-0.46 above (every joint within 0.01 of the others in the slow band). The growth is the
  motion within the central difference's 10 ms (the real set-points are staircases whose steps kick the joints),
  not the driver's: its velocity's white noise is the slow band's, 0.08 rad/s on every joint.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal, get_args

from wbfriction.choices import check_choice, check_range
from wbfriction.exceptions import InputError, OptionError
from wbfriction.sim.options import FRICTION_MODES, FrictionMode

SetpointKind = Literal["ramps", "chirps", "both"]
"""The set-points' shape (:class:`SetpointOptions`)."""
SETPOINT_KINDS: tuple[SetpointKind, ...] = get_args(SetpointKind)

PerJoint = float | Mapping[str, float]
"""A level for every joint, or per joint or joint group (every joint named once)."""


@dataclass(frozen=True)
class SetpointOptions:
    """The set-points each joint's driver is sent (:func:`wbfriction.sim.hung.setpoints`), about a standing leg's
    posture (the robot's reference angles, else the middle of each joint's range).

    Attributes:
        kind: ``"ramps"``: triangle ramps (the real Aliengo log's: a constant speed between reversals), each joint
            its own, reversing after a random time in :attr:`reversal`, at a random level in the far half of its
            band; ``"chirps"``: a sine of each joint's band whose frequency sweeps linearly over :attr:`chirp`
            (each joint's sweep scaled by a random factor in [0.8, 1.2], so the joints move apart); ``"both"``:
            ramps over the first half, back at the posture at its end, then chirps.
        amplitude: how far each joint moves either side of its posture, as a share of half its range (0.25: a
            quarter of half the range each way), the band kept 5 % of the range off the limits.
        reversal: shortest and longest time between two reversals of a ramp [s].
        chirp: the chirps' first and last frequencies [Hz].
        velocity: command ``qd_des`` = the set-point's slope; False: zeros (as the real log and most users do).
        hold: each set-point held over so many samples (a staircase: the real Aliengo's are, a new value every 5-6
            samples of its 200 Hz log); 1: a new value at every sample.
        seed: seed of the random times, levels and sweeps.
    """

    kind: SetpointKind = "both"
    amplitude: float = 0.25
    reversal: tuple[float, float] = (0.2, 1.5)
    chirp: tuple[float, float] = (0.2, 2.0)
    velocity: bool = False
    hold: int = 1
    seed: int = 0

    def __post_init__(self) -> None:
        check_choice("kind", self.kind, SETPOINT_KINDS)
        check_range("hold", self.hold, low=1)
        check_range("amplitude", self.amplitude, low=0.0, high=1.0)
        if not 0 < self.reversal[0] <= self.reversal[1]:
            raise OptionError("--reversal", self.reversal, "two times 0 < shortest <= longest [s]")
        if not 0 < self.chirp[0] <= self.chirp[1]:
            raise OptionError("--chirp", self.chirp, "two frequencies 0 < first <= last [Hz]")


NOISE_FLAGS = {"encoder_resolution": "--encoder-bits", "position_std": "--position-noise",
               "velocity_std": "--velocity-noise"}
"""The command line's option of each noise level (:class:`DriverNoise`)."""


@dataclass(frozen=True)
class DriverNoise:
    """What a driver's sensors add (all off by default: noise-free is exactly noise-free).

    Every level is one number for every joint or a mapping of joint or group names to numbers
    (:func:`wbfriction.sim.hung.per_joint`).

    Attributes:
        encoder_resolution: the encoder's step [rad]: the reading is rounded to its multiples; None: exact.
        position_std: white noise on the encoder's reading before its rounding [rad].
        velocity_std: white noise on the driver's velocity [rad/s].
        seed: seed of the noise (drawn at every physics step: the driver's PD runs on the noisy readings).
    """

    encoder_resolution: PerJoint | None = None
    position_std: PerJoint = 0.0
    velocity_std: PerJoint = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("encoder_resolution", "position_std", "velocity_std"):
            value = getattr(self, name)
            if isinstance(value, Mapping):
                object.__setattr__(self, name, value := dict(value))  # the metadata is JSON
            values = [] if value is None else list(value.values()) if isinstance(value, Mapping) else [value]
            for v in values:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0 \
                        or (name == "encoder_resolution" and v == 0):
                    raise OptionError(NOISE_FLAGS[name], value, "levels >= 0 (a resolution > 0)")


HIP_THIGH_RESOLUTION = 2.0 * math.pi / 2**19
"""The real Aliengo's hip and thigh encoder step at the joint [rad] (module docstring)."""
CALF_RESOLUTION = 2.0 * math.pi / (5 * 2**15)
"""The real Aliengo's calf encoder step at the joint [rad] (module docstring)."""
REAL_DRIVER = DriverNoise(encoder_resolution={"hip": HIP_THIGH_RESOLUTION, "thigh": HIP_THIGH_RESOLUTION,
                                              "calf": CALF_RESOLUTION},
                          position_std=0.0, velocity_std=0.08)
"""The noise of a real driver, measured on the real Aliengo (module docstring), for a robot whose joint groups are
Unitree's ``hip``, ``thigh`` and ``calf`` (the built-in ``go2``)."""


@dataclass(frozen=True)
class HungOptions:
    """Parameters of :func:`wbfriction.sim.hung.simulate_hung`.

    Attributes:
        duration: simulated time [s].
        rate: the log's and the set-points' rate [Hz].
        substeps: physics steps per period: the drivers' PD and the friction run at every one (5 at 200 Hz: 1 ms,
            a fifth of a period: the resolution a delay is simulated and identified to).
        setpoints: :class:`SetpointOptions`.
        noise: :class:`DriverNoise` (off by default; :data:`REAL_DRIVER`: a real driver's).
        delay: the drivers' delay [s] (any, not only whole physics steps: the set-point a physics step applies is the
            delayed zero-order hold's mean over the step); None: the robot's ``[pd]`` delay.
        armature: the drives' armature per joint [kg·m^2]; None: the robot's ``[armature]``.
        encoder_offset: the logged angle minus the model's per joint [rad]; None: the robot's ``[encoder_offset]``.
        friction: ``"model"`` (any family's ``tau_f = -f(qd)`` applied at every physics step) or ``"mujoco"``
            (MuJoCo's ``frictionloss`` and ``damping``: Coulomb-viscous, a joint that sticks),
            :func:`wbfriction.sim.mujoco_sim.set_mujoco_friction`.
        friction_timeconst: with ``friction = "mujoco"``, the friction-loss constraint's time constant [s] (None:
            two physics steps).
    """

    duration: float = 25.0
    rate: float = 200.0
    substeps: int = 5
    setpoints: SetpointOptions = SetpointOptions()
    noise: DriverNoise = DriverNoise()
    delay: float | None = None
    armature: Mapping[str, float] | None = None
    encoder_offset: Mapping[str, float] | None = None
    friction: FrictionMode = "model"
    friction_timeconst: float | None = None

    def __post_init__(self) -> None:
        check_range("duration", self.duration, low=0.0, strict=True)
        check_range("rate", self.rate, low=0.0, strict=True)
        check_range("substeps", self.substeps, low=1)
        check_choice("friction", self.friction, FRICTION_MODES)
        if self.delay is not None and not (math.isfinite(self.delay) and self.delay >= 0):
            raise OptionError("--delay", self.delay, "a delay >= 0")
        if self.friction_timeconst is not None and not self.friction_timeconst > 0:
            raise OptionError("--friction-timeconst", self.friction_timeconst, "a time constant > 0 [s]")
        for name in ("armature", "encoder_offset"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, value := dict(value))  # the metadata is JSON
            if value is not None and not all(isinstance(v, (int, float)) and math.isfinite(v)
                                             and (v >= 0 or name == "encoder_offset") for v in value.values()):
                raise InputError(f"{name}: every value must be a finite number{' >= 0' * (name == 'armature')}, "
                                 f"got {dict(value)!r}")
