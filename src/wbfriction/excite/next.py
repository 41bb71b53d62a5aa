"""What to record next: from the fits of a log already recorded, the motion that determines what it left undetermined,
without recording again what it determined (``wbfriction excite --after PARAMS.json``).

The joints whose fit is not ``ok`` (:meth:`~wbfriction.fit.result.FitResult.verdict`: ``weak``, ``at bound``, ``not
excited``, ``failed``; and any joint the file has no fit of) move; the others are held at their posture. The design
(:func:`~wbfriction.excite.pd_design.design_pd`) takes as its prior the robot's TOML (a hung PD-driven robot's
drivers, delay, armature and offsets: what ``identify --actuator pd --config-output`` wrote) and each joint's fitted
friction where it can be one (:func:`physical`: a fit at F_v 0 is what is in question, not a prior), else the
simulator's default (:func:`~wbfriction.sim.hung.default_hung_friction`). A joint without armature (the log left it
at zero, so ``--config-output`` wrote none: a rotor always has some) takes the median of those the TOML gives, else
:data:`ARMATURE_PRIOR`. Beside each moving joint's predicted standard errors it keeps what the log gave (the fit's
value and the standard error a user reads, its status), so that the two can be read side by side.

A fixed-base arm's (:func:`record_next_arm`) is the same choice of joints, prior and log's values on the arm's
design (:func:`~wbfriction.excite.arm_design.design_arm` with ``moving``): the held joints at the middle of their
range (the parameters file records no posture), the torque limits checked with their gravity, each moving joint's
prior its fitted friction where :func:`physical`, else the arm simulator's default
(:func:`~wbfriction.sim.arm.default_arm_friction`), and the prediction (what ``estimate`` and ``fit`` will report)
the moving joints'.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Generic, TypeVar

import numpy as np

from wbfriction.actuator.options import ActuatorOptions
from wbfriction.exceptions import InputError
from wbfriction.excite.arm_design import ArmDesign, design_arm
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.options import PdExciteOptions
from wbfriction.excite.pd_design import PdDesign, design_pd
from wbfriction.excite.predict_arm import REAL_ARM
from wbfriction.fit.result import FitResult
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.sim.arm import ArmOptions, default_arm_friction
from wbfriction.sim.hung import default_hung_friction

ARMATURE_PRIOR = 0.01
"""The armature prior [kg·m^2] of a robot whose TOML gives none (a quadruped's knee drive's order of size)."""
COMPARED = ("F_v", "F_c")
"""The parameters a log's fit and the design's identification both give, compared."""
Design = TypeVar("Design", PdDesign, ArmDesign)


@dataclass(frozen=True)
class Logged:
    """What the log's fit gave of one joint: its status and reason, and per compared parameter (value, standard
    error a user reads) in its unit (NaN where the family has none)."""

    status: str
    reason: str
    values: dict[str, tuple[float, float]]


@dataclass(frozen=True)
class NextRecording(Generic[Design]):
    """The motion to record next (module docstring).

    Attributes:
        design: the design (a hung PD-driven robot's or an arm's), moving its ``moving`` joints.
        logged: per moving joint, what the log gave.
        prior_from_fit: the joints whose prior is their fitted friction (the others: the simulator's default).
    """

    design: Design
    logged: dict[str, Logged]
    prior_from_fit: tuple[str, ...]


def physical(fit: FitResult) -> bool:
    """Whether a fit's friction can be a design's prior: ``ok`` or ``weak`` (not a fit at a bound, of a joint the
    log did not excite, or failed), every value finite, each magnitude a user reads (F_c, F_v) larger than its
    standard error (a value the data do not tell from zero is what is in question, not a prior)."""
    params = fit.params
    if fit.verdict().status not in ("ok", "weak") or params is None or not np.all(np.isfinite(params.as_vector())):
        return False
    read = fit.read_stderr()
    return all(getattr(params, n) > read.get(n, np.inf) and not fit.at_bound.get(n, False)
               for n in COMPARED if n in params.names)


def with_armature(robot: Robot) -> Robot:
    """``robot`` with an armature on every actuated joint (module docstring): those without take the median of the
    others', else :data:`ARMATURE_PRIOR`."""
    iv = robot.act_v_index
    armature = np.array(robot.model.armature[iv], dtype=float)
    if np.all(armature > 0):
        return robot
    known = armature[armature > 0]
    model = robot.model.copy()
    full = model.armature.copy()
    full[iv] = np.where(armature > 0, armature, float(np.median(known)) if known.size else ARMATURE_PRIOR)
    model.armature = full
    return replace(robot, model=model, cache={})


def logged_of(fit: FitResult) -> Logged:
    """:class:`Logged` of one joint's fit."""
    verdict = fit.verdict()
    read = fit.read_stderr()
    values = {n: (float(getattr(fit.params, n, np.nan)) if fit.params is not None else np.nan,
                  float(read.get(n, np.nan))) for n in COMPARED}
    return Logged(verdict.status, verdict.reason, values)


def undetermined(robot: Robot, fits: Mapping[str, FitResult], source: str) -> tuple[str, ...]:
    """The joints of ``robot`` whose fit in ``fits`` is not ``ok`` or missing (module docstring), in its actuated
    order; ``source``: the parameters file, for errors.

    Raises:
        InputError: every joint's fit ``ok`` (nothing left to determine).
    """
    moving = tuple(j for j in robot.actuated if j not in fits or not fits[j].verdict().ok)
    if not moving:
        raise InputError(f"{source}: every joint's fit is ok: the log determined them all, nothing to record next")
    return moving


def prior_of(robot: Robot, fits: Mapping[str, FitResult], default: Mapping[str, ModelParamsBase]
             ) -> tuple[dict[str, ModelParamsBase], tuple[str, ...]]:
    """Each actuated joint's prior: its fitted friction where :func:`physical`, else ``default``'s (none where
    neither has one: the design refuses it); and the joints whose prior is their fit."""
    from_fit = tuple(j for j in robot.actuated if j in fits and physical(fits[j]))
    prior = {j: fits[j].params if j in from_fit else default[j] for j in robot.actuated
             if j in from_fit or j in default}
    return prior, from_fit  # type: ignore[return-value]


def logged_all(fits: Mapping[str, FitResult], moving: tuple[str, ...]) -> dict[str, Logged]:
    """:class:`Logged` of each moving joint (``not fitted`` where the file has no fit of it)."""
    return {j: logged_of(fits[j]) if j in fits else Logged("not fitted", "", {}) for j in moving}


def record_next(robot: Robot, fits: Mapping[str, FitResult], source: str,
                options: PdExciteOptions = PdExciteOptions(),
                identification: ActuatorOptions = ActuatorOptions(),
                progress: Progress | None = None) -> NextRecording[PdDesign]:
    """The motion to record next on a hung PD-driven ``robot`` after a log whose fits are ``fits`` (module
    docstring); ``source``: the parameters file, for errors.

    Raises:
        InputError: every joint's fit ``ok`` (nothing left to determine); what
            :func:`~wbfriction.excite.pd_design.design_pd` raises.
    """
    moving = undetermined(robot, fits, source)
    prior, from_fit = prior_of(robot, fits, default_hung_friction(robot))
    design = design_pd(with_armature(robot), options, prior, identification, progress,  # type: ignore[arg-type]
                       moving=moving)
    return NextRecording[PdDesign](design, logged_all(fits, moving), from_fit)


def record_next_arm(robot: Robot, fits: Mapping[str, FitResult], source: str,
                    options: ExciteOptions = ExciteOptions(), recording: ArmOptions = REAL_ARM,
                    progress: Progress | None = None) -> NextRecording[ArmDesign]:
    """The motion to record next on a fixed-base arm ``robot`` (torque-measured joints) after a log whose fits are
    ``fits`` (module docstring); ``source``: the parameters file, for errors. ``options`` and ``recording``: as
    :func:`~wbfriction.excite.arm_design.design_arm` takes them.

    Raises:
        InputError: every joint's fit ``ok`` (nothing left to determine); what
            :func:`~wbfriction.excite.arm_design.design_arm` raises (a torque limit passed, the held joints'
            gravity included).
    """
    moving = undetermined(robot, fits, source)
    prior, from_fit = prior_of(robot, fits, default_arm_friction(robot))
    design = design_arm(robot, options, prior, recording, progress, moving=moving)
    return NextRecording[ArmDesign](design, logged_all(fits, moving), from_fit)


def fits_after(robot: Robot, after: Path | None) -> dict[str, FitResult] | None:
    """The fits of the parameters file ``after`` (``excite --after``: what ``fit`` wrote of the log recorded) for
    ``robot``; None without one.

    Raises:
        InputError: what :func:`~wbfriction.fit.params_file.read_robot_params` raises.
    """
    if after is None:
        return None
    from wbfriction.fit.params_file import read_robot_params

    return read_robot_params(after, robot.name, robot.actuated, robot.urdf)
