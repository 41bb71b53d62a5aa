"""The choices of an actuator identification (``wbfriction identify --actuator pd``), in a module that imports
nothing heavy: the command line shows their defaults without loading NumPy."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

from wbfriction.exceptions import OptionError
from wbfriction.quantities import check_option

WINDOW = 0.04
"""Default window [s] the momentum balance is summed over (module :mod:`wbfriction.actuator.rows`): long enough
that a window's change of momentum outweighs the driver's velocity noise (2 σ_qd² M² against the friction's
impulse, which grows with the window), short against a ramp's reversal period (0.2 s and more on the robots this
is for), so that the rotor's inertia is seen at every reversal. A physical choice, not fitted on data."""
MAX_DELAY = 0.05
"""Default longest delay searched [s]: ten periods of a 200 Hz log; a bus and driver delay of Unitree-class
robots is 5-20 ms (the peer's Aliengo: 13 ms)."""
OFFSET_BOUND = 0.3
"""Default bound on an encoder offset [rad] (17°): beyond it a joint was calibrated on another tooth, which the
identification should not pretend to resolve."""
TANH_SLOPE = 100.0
"""Default slope ``a`` [s/rad] of the Coulomb term ``F_c tanh(a qd)`` in the identification's nuisance friction
(the family fitted afterwards has its own). Chosen among 100, 300 and 1000 across the MuJoCo hung Go2 (noise-free
and a real driver's noise, two seeds: worst error 5.5, 4.8, 3.3 % at 100 against 5.0, 11.4, 8.6 % at 300 and 4.9,
12.6, 9.3 % at 1000) and the real Aliengo (its held-out balance 0.4-0.6 % better at 100): issue 55's note."""
STEEPER = 3.0
"""The identification's values are solved again with the Coulomb term this many times as steep (300 s/rad at the
default slope, the next of the slopes :data:`TANH_SLOPE` was chosen among), the delay kept: how far they move is a
model error the residuals do not show (the friction's true transition is not the nuisance model's), added to their
standard errors in quadrature (issue 63). On the hung Go2 in MuJoCo (5 s, a real driver's noise) the thighs' F_v
lie 6-10 plain standard errors from the truth and move 5-7 of them; a factor of 1/3 moves them 13-38, more than
they are off."""
PASSES = 3
"""Default passes of the encoder offsets' linearisation (the gravity at ``q - o`` is linearised about the
previous pass's ``o``)."""
VELOCITIES = ("auto", "positions", "logged")
"""The velocities the dynamics may take (:attr:`ActuatorOptions.velocity`)."""


@dataclass(frozen=True)
class ActuatorOptions:
    """How PD-driven actuators are identified (:func:`~wbfriction.actuator.identification.identify_actuators`).

    Attributes:
        window: the window the momentum balance is summed over [s] (:data:`WINDOW`), > 0.
        max_delay: the longest set-point delay searched [s] (:data:`MAX_DELAY`), >= 0.
        delay: a known delay [s] instead of the search, or None.
        offset_bound: the largest encoder offset [rad] (:data:`OFFSET_BOUND`), > 0; 0 keeps the TOML's offsets.
        tanh_slope: the nuisance Coulomb term's slope [s/rad] (:data:`TANH_SLOPE`), > 0.
        passes: passes of the offsets' linearisation (:data:`PASSES`), >= 1.
        holdout: the share of the log, at its end, kept out of the fit to check its prediction, in [0, 0.5).
        velocity: the velocity of the dynamics: ``positions`` (the encoders' positions' central difference),
            ``logged`` (the drivers' ``qd.<joint>``), or ``auto``: both identified, the one whose balance closes
            better kept (a driver's velocity may be filtered and lag: the real Aliengo's closes 2.8 times worse
            than its positions'; a central difference errs where a reversal is sharp against the period).
        delayed: what the drivers' delay holds back: ``setpoints`` (Isaac Lab's ``DelayedPDActuator``), ``torque``
            (the whole law, PACE's actuator), or ``auto``: both identified, the one whose balance closes better
            kept (:mod:`wbfriction.model.pd`).

    Raises:
        OptionError: a value out of its range, naming the option as the command line spells it.
    """

    window: float = WINDOW
    max_delay: float = MAX_DELAY
    delay: float | None = None
    offset_bound: float = OFFSET_BOUND
    tanh_slope: float = TANH_SLOPE
    passes: int = PASSES
    holdout: float = 0.2
    velocity: str = "auto"
    delayed: str = "auto"

    def __post_init__(self) -> None:
        checks = (("--window", self.window, self.window > 0, "a window > 0 [s]"),
                  ("--offset-bound", self.offset_bound, self.offset_bound >= 0, "a bound >= 0 [rad] (0: none fitted)"),
                  ("--tanh-slope", self.tanh_slope, self.tanh_slope > 0, "a slope > 0 [s/rad]"),
                  ("--holdout", self.holdout, 0 <= self.holdout < 0.5, "a share in [0, 0.5)"))
        for option, value, ok, expected in checks:
            if not (isinstance(value, numbers.Real) and math.isfinite(value) and ok):
                raise OptionError(option, value, expected)
        check_option("--delay", "pd_delay", self.delay)
        check_option("--max-delay", "pd_delay", self.max_delay)
        if self.delayed not in ("auto", "setpoints", "torque"):
            raise OptionError("--delayed", self.delayed, "one of auto, setpoints, torque")
        if self.velocity not in VELOCITIES:
            raise OptionError("--velocity", self.velocity, f"one of {', '.join(VELOCITIES)}")
        if not (isinstance(self.passes, int) and self.passes >= 1):
            raise OptionError("--passes", self.passes, "a number of passes >= 1")
