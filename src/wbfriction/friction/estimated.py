"""The friction estimate of a log, sample by sample: what every route produces (:class:`FrictionEstimate`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import cast

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.options import ROUTES, Route
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import Smoother


@dataclass
class FrictionEstimate:
    """Per-sample friction estimate of the torque-controlled joints.

    Attributes:
        joints: torque-controlled joint names (n_tc,).
        time: (N,) [s].
        qd: joint velocities (N, n_tc) [rad/s] (same differentiation as ``qdd_msr``).
        tau_f: estimated friction torque (N, n_tc) [N·m]; NaN where not estimated.
        qdd: measured accelerations ``qdd_msr`` (N, n_tc) [rad/s^2].
        delta_qdd: acceleration difference (5.12) ``qdd_msr - qdd_est`` (N, n_tc)
            [rad/s^2]; NaN where not estimated. ``qdd - delta_qdd`` is the estimated
            acceleration ``qdd_est`` (5.10).
        valid: (N, n_tc) samples to trust (single support, margins, mask).
        phase: (N,) ``single`` / ``double`` / ``flight``.
        unique: (N,) the estimate is the exact unique solution (single support).
        cond: (N,) condition number of ``M_mod^{-1}`` (NaN where not computed), or None.
        contact: (N, n_contacts) flags; ``contact_frames`` their names.
        tau_f_true: (N, n_tc) true friction if the log had it, else None.
        metadata: carried from the log, plus the options used.
        companion_delta_qdd: the single-support acceleration difference through the other
            kind of scheme (N, n_tc) [rad/s^2] (NaN elsewhere), or None: unfiltered
            (central differences) for a filtering scheme, Savitzky-Golay filtered otherwise;
            so that Fig. 7.4 can show the difference with and without filtering.
            ``companion_diff`` names its scheme.
        smoother: the zero-phase smoother the estimate went through (filtering schemes),
            or None; the fit passes the model through it too
            (:func:`~wbfriction.fit.selection.fit_friction`). A table records it as the
            ``estimate_options`` of its metadata.
        disagreement: (N, n_tc) ``tau_f`` of the measured route less the rigid-contact route's where both
            estimated the sample (single support) [N·m], NaN elsewhere; None without a measured route
            (:mod:`wbfriction.friction.cross_check`).
        route: (N,) how each sample was estimated (:data:`~wbfriction.friction.measured.Closure`):
            ``contact`` (rigid contacts), ``base`` (measured base motion), ``wrench`` (measured
            wrenches), ``none``; or None (a table that does not say: rigid contacts).
        q: the joints' positions (N, n_tc) [rad], the model's (the logged ones less the encoder offsets), a
            continuous joint's in (−π, π] (:func:`~wbfriction.model.layout.principal_angle`: the same number on every
            row, whatever the log's convention or the window it was unwrapped in), or None (a table of an earlier
            version): what the position ripple is a function of (:mod:`~wbfriction.fit.terms`).
        tau: the joints' measured torques (N, n_tc) [N·m], or None: the load their transmissions carry (the
            friction beyond the sensor is not in it), what load-dependent friction is a function of.
        temperature: the joints' logged temperatures (N, n_tc) [°C], NaN for a joint without, or None: none logged.
        determined: (N, n_tc) the joint's friction is determined by the sample's equations (point feet: the rank
            decision of :mod:`wbfriction.model.determination`; False where the dynamics were not evaluated, those rows
            with ``cond`` NaN), or None (the thesis's phases decide).
        route_check: the same samples estimated by the other route (issue 38: the momentum route's for the
            acceleration route's, and the other way round; its ``tau_f``, ``qd``, ``valid`` and ``smoother``),
            whose fit :func:`~wbfriction.fit.joints.fit_estimate` compares with this one's; or None.
    """

    joints: tuple[str, ...]
    time: np.ndarray
    qd: np.ndarray
    tau_f: np.ndarray
    valid: np.ndarray
    phase: np.ndarray
    unique: np.ndarray
    contact: np.ndarray
    contact_frames: tuple[str, ...]
    qdd: np.ndarray | None = None
    delta_qdd: np.ndarray | None = None
    cond: np.ndarray | None = None
    tau_f_true: np.ndarray | None = None
    metadata: dict = field(default_factory=dict)
    smoother: Smoother | None = None
    companion_delta_qdd: np.ndarray | None = None
    companion_diff: str | None = None
    route: np.ndarray | None = None
    disagreement: np.ndarray | None = None
    q: np.ndarray | None = None
    tau: np.ndarray | None = None
    temperature: np.ndarray | None = None
    determined: np.ndarray | None = None
    route_check: FrictionEstimate | None = field(default=None, repr=False)

    def keeping(self, rows: np.ndarray) -> FrictionEstimate:
        """A copy whose valid samples are only those of ``rows`` ((N, n_tc) or (N, 1) bool), its other route's too
        (a study's swing or stance samples)."""
        check = None if self.route_check is None else self.route_check.keeping(rows)
        return replace(self, valid=self.valid & rows, route_check=check)

    @property
    def estimation_route(self) -> Route:
        """The route these estimates took (:data:`~wbfriction.friction.options.Route`), from the options in the
        metadata (an older table: ``acceleration``)."""
        options = self.metadata.get("estimate_options")
        route = options.get("route") if isinstance(options, dict) else None
        return cast(Route, route if route in ROUTES else "acceleration")


def no_single_support(robot: Robot, source: str) -> InputError:
    """The error of a log without a single-support sample, naming it and its contact columns; on a fixed base
    (always welded: every sample is one), a log without a sample whose derivatives are defined; on point feet
    (no single support: the rank decides, :mod:`wbfriction.model.determination`), a log without a sample that
    determines a joint's friction."""
    if robot.partial_contacts:
        sensed = [f for f, m in zip(robot.contact_frames, robot.contact_models) if m.world_force]
        forces = ", ".join(f"force.{f}.x|y|z" for f in sensed[:2])
        unknown = f"whose force is not logged in 3-D ({forces}, ...)" if sensed else \
            f"({robot.stands_on}: no force column is read)"
        return InputError(f"{source}: no sample determines any joint's friction: every leg has a foot down {unknown} "
                          "at every sample with defined derivatives outside the switches' margins (--lift-off, "
                          "--touch-down) and the differentiation's window (--window, --cutoff)")
    if not robot.floating_base:
        return InputError(f"{source}: no sample with defined derivatives: every stretch between time gaps is "
                          "shorter than the differentiation's window (--window, --cutoff, --velocity-window, "
                          "--momentum-window)")
    return InputError(f"{source}: no single-support sample (exactly one of the columns "
                      f"{', '.join('contact.' + f for f in robot.contact_frames)} set) with defined derivatives "
                      "outside the lift-off and touch-down margins (--lift-off, --touch-down) and the "
                      "differentiation's window (--window, --cutoff)")
