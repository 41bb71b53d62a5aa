"""The choices a user makes about the friction estimate, its fit and its checks, in a module that imports
nothing heavy: the command line shows their defaults in its help without loading NumPy, SciPy or Pinocchio.
Each choice is checked here, where it is defined: the API and the command line refuse the same values with
the same line, and share the same defaults."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Literal, get_args

from wbfriction.choices import check_choice, check_range, flag
from wbfriction.exceptions import OptionError
from wbfriction.signals.options import (
    ALIGNMENT_OPTIONS,
    DIFF_OPTIONS,
    MASKS,
    NOISE_TARGET,
    VELOCITIES,
    AlignmentOption,
    DiffOption,
    FilterOptions,
    Mask,
    Velocity,
)

BaseMotion = Literal["auto", "contact", "logged", "imu"]
"""Where the base's motion comes from: the rigid contacts (the thesis's route), the logged base pose
differentiated like the joints, the IMU (its gyro and accelerometer, the logged base orientation), or
``auto`` (:func:`~wbfriction.friction.measured.resolve_base_motion`)."""
BASE_MOTIONS: tuple[BaseMotion, ...] = get_args(BaseMotion)

Route = Literal["acceleration", "momentum"]
"""How the friction is reached from the motion (issue 38): the thesis's ``acceleration`` route (positions
differentiated twice, :mod:`~wbfriction.friction.estimate`) or the ``momentum`` route (once,
:mod:`~wbfriction.friction.momentum`)."""
ROUTES: tuple[Route, ...] = get_args(Route)
RouteOption = Literal["auto", "acceleration", "momentum"]
"""A route, or ``auto``: chosen from the log's position noise (:func:`~wbfriction.friction.route.resolve_route`)."""
ROUTE_OPTIONS: tuple[RouteOption, ...] = get_args(RouteOption)


@dataclass(frozen=True)
class MomentumOptions:
    """The momentum route's smoothing (:mod:`~wbfriction.friction.momentum`); None: chosen from the data
    (:func:`~wbfriction.signals.choice.choose_momentum_smoothing`).

    Attributes:
        velocity_window: Savitzky-Golay window of the velocity (order 4) [samples, odd, >= 7].
        window: the momentum window's length ``2m + 1`` [samples, odd, >= 3]
            (:class:`~wbfriction.signals.window.MomentumWindow`).

    Raises:
        OptionError: a window that is not odd or too short (named by its option).
    """

    velocity_window: int | None = None
    window: int | None = None

    def __post_init__(self) -> None:
        if self.velocity_window is not None and (self.velocity_window < 7 or self.velocity_window % 2 == 0):
            raise OptionError("--velocity-window", self.velocity_window, "odd and at least 7 [samples]")
        if self.window is not None and (self.window < 3 or self.window % 2 == 0):
            raise OptionError("--momentum-window", self.window, "odd and at least 3 [samples]")


Method = Literal["rnea", "kkt"]
"""The single-support route: one RNEA pass on the stance-rooted tree, or the KKT system (5.10-5.13)."""
METHODS: tuple[Method, ...] = get_args(Method)


@dataclass(frozen=True)
class EstimateOptions:
    """Options of the estimator (defaults from the thesis).

    Attributes:
        diff: differentiation scheme: ``central``, ``backward``, ``savgol``, ``butterworth``
            (:mod:`~wbfriction.signals.kinematics`, :mod:`~wbfriction.signals.filters`), ``true``,
            or ``auto``: chosen from the log's positions with its window or cutoff
            (:func:`~wbfriction.friction.estimate.resolve_differentiation`; the default, as on the command line), once
            per log.
        compensate_delay: shift the derivatives by their delay (6.1.2).
        torque_alignment: ``zoh`` (mean of tau[k-1], tau[k]), ``sample``, or ``auto``
            (what the log's metadata declares, else ``zoh``).
        lift_off_skip: seconds dropped after a lift-off [s] (6.2.1: 0.10).
        touch_down_skip: seconds dropped before a touch-down [s] (6.2.1: 0.05).
        mask: ``swing`` (a leg joint counts only while its leg swings) or ``single``.
        ds_weight: diagonal of W in (6.1), scalar or (n_tc,): relative weights of the
            joints' acceleration residuals (dimensionless).
        ds_regularization: diagonal of Lambda in (6.1), scalar or (n_tc,)
            [(rad/s^2)^2 / (N·m)^2 with W = 1]; it competes with ``A^T W A``, whose
            entries are of the order of (1 / joint inertia)^2.
        condition_number: report cond(M_mod^{-1}) per sample (one KKT inverse per sample).
        method: single-support route, ``rnea`` (default) or ``kkt``.
        filtering: parameters of the ``savgol`` and ``butterworth`` schemes.
        velocity: ``differentiated`` or ``logged`` (the log's ``qd.<joint>``:
            :func:`~wbfriction.signals.kinematics.measure`).
        acceleration_difference: also give ``Delta qdd`` (5.12) in single support
            (``M_mod^{-1} tau_f``, one ``crba`` per sample on the stance-rooted tree and a
            batched solve); the KKT route always has it.
        base_motion: where the base's motion comes from (:data:`~wbfriction.friction.measured.BaseMotion`):
            ``contact`` (rigid contacts), ``logged`` (the base pose differentiated like the joints),
            ``auto`` (:func:`~wbfriction.friction.measured.resolve_base_motion`).
        wrenches: use the force-torque sensors' wrenches where the log has them: every joint's
            friction in every phase (:func:`~wbfriction.friction.measured.wrench_route`).
        route: ``acceleration``, ``momentum`` or ``auto`` (:data:`RouteOption`; resolved once per log by
            :func:`~wbfriction.friction.route.resolve_route`).
        momentum: the momentum route's windows (:class:`MomentumOptions`).
        check_route: also estimate the other route, whose fit the status compares
            (:attr:`~wbfriction.friction.estimate.FrictionEstimate.route_check`).
        noise_target: the most RMS noise of the positions ``diff="auto"`` and ``route="auto"`` leave in the
            acceleration [rad/s^2] (> 0; :func:`~wbfriction.signals.choice.choose_differentiation`,
            :func:`~wbfriction.friction.route.choose_route`).

    Raises:
        OptionError: a value that is not one of its choices or out of its range, named by its command-line
            option; ``filtering`` set with ``diff="auto"`` (which chooses the filter from the data: it would be
            dropped).
    """

    diff: DiffOption = "auto"
    compensate_delay: bool = True
    torque_alignment: AlignmentOption = "auto"
    lift_off_skip: float = 0.10
    touch_down_skip: float = 0.05
    mask: Mask = "swing"
    ds_weight: float | tuple[float, ...] = 1.0
    ds_regularization: float | tuple[float, ...] = 1e-3
    condition_number: bool = False
    method: Method = "rnea"
    filtering: FilterOptions = FilterOptions()
    acceleration_difference: bool = True
    velocity: Velocity = "differentiated"
    base_motion: BaseMotion = "auto"
    wrenches: bool = True
    route: RouteOption = "auto"
    momentum: MomentumOptions = MomentumOptions()
    check_route: bool = True
    noise_target: float = NOISE_TARGET

    def __post_init__(self) -> None:
        check_choice("diff", self.diff, DIFF_OPTIONS)
        check_choice("torque_alignment", self.torque_alignment, ALIGNMENT_OPTIONS)
        check_choice("mask", self.mask, MASKS)
        check_choice("method", self.method, METHODS)
        check_choice("velocity", self.velocity, VELOCITIES)
        check_choice("base_motion", self.base_motion, BASE_MOTIONS)
        check_choice("route", self.route, ROUTE_OPTIONS)
        check_range("lift_off_skip", self.lift_off_skip, low=0.0)
        check_range("touch_down_skip", self.touch_down_skip, low=0.0)
        check_range("noise_target", self.noise_target, low=0.0, strict=True)
        for name in ("ds_weight", "ds_regularization"):
            value = getattr(self, name)
            for v in value if isinstance(value, tuple) else (value,):
                check_range(name, v, low=0.0, strict=name == "ds_weight")
        given = [f.name for f in fields(FilterOptions) if getattr(self.filtering, f.name) != f.default]
        if self.diff == "auto" and given:
            raise OptionError(flag(given[0]), getattr(self.filtering, given[0]), "given with --diff savgol or "
                              "butterworth (--diff auto chooses the filter from the positions' noise and would "
                              "drop it)")


Term = Literal["load", "direction", "ripple", "temperature"]
"""A term beyond velocity (module docstring)."""
TERMS: tuple[Term, ...] = get_args(Term)
TemperatureLaw = Literal["auto", "linear", "exponential"]
"""How a temperature term's levels follow the temperature (:mod:`~wbfriction.fit.terms`): ``linear``,
``exponential`` (Bittencourt's decrease), or ``auto``: the exponential where held-out samples say it predicts better."""
TEMPERATURE_LAWS: tuple[TemperatureLaw, ...] = get_args(TemperatureLaw)
"""Every term, in the order they are reported."""


