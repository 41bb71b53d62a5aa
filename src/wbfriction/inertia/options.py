"""The choices a user makes about the inertia identification, in a module that imports nothing heavy: the
command line shows their defaults in its help without loading NumPy, SciPy or Pinocchio."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

from wbfriction.choices import check_choice, check_range, flag
from wbfriction.exceptions import InputError, OptionError

ArmatureMode = Literal["known", "identify", "none"]
"""How the identification treats the drives' reflected rotor inertia (:mod:`wbfriction.inertia.identification`)."""
ARMATURE_MODES: tuple[ArmatureMode, ...] = get_args(ArmatureMode)
InertiaPart = Literal["all", "mass", "rotational"]
"""What of a body's inertia ``sensitivity`` scales (:mod:`~wbfriction.inertia.sensitivity`)."""
PARTS: tuple[InertiaPart, ...] = get_args(InertiaPart)


@dataclass(frozen=True)
class PriorUncertainty:
    """Standard deviations of the prior toward the given model (:mod:`wbfriction.inertia.consistency`).

    Attributes:
        mass: of each body's mass, relative to it.
        com: of each coordinate of each body's centre of mass [m].
        inertia: of each entry of each body's rotational inertia about its centre of mass,
            relative to its largest principal moment (at least that of a 1 cm sphere of its mass).
        armature: of each joint's armature, relative to the larger of its given armature and the
            largest diagonal entry of the given model's joint-space inertia at the reference
            configuration (:func:`wbfriction.inertia.prior.armature_scale`).
        friction: of each joint's Coulomb, Stribeck and offset friction, relative to the RMS of its
            torque in the log [N·m]; of its viscous friction, that over its velocity limit [rad/s].
    """

    mass: float = 0.1
    com: float = 0.05
    inertia: float = 0.5
    armature: float = 1.0
    friction: float = 1.0

    def __post_init__(self) -> None:
        if min(self.mass, self.com, self.inertia, self.armature, self.friction) <= 0:
            raise InputError(f"prior uncertainties must be > 0, got {self}")


@dataclass(frozen=True)
class InertialOptions:
    """Options of :func:`~wbfriction.inertia.identification.identify_inertia`.

    Attributes:
        tanh_slope: ``a`` of the Coulomb term ``F_c tanh(a qd)`` [s/rad].
        stribeck_velocity: ``v_s`` [rad/s] of a Stribeck term ``(F_s - F_c) tanh(a qd) exp(-(qd/v_s)^2)``
            identified with the others (3.5 with ``delta_s = 2``; ``F_s - F_c = S F_c``), for
            example the one the acceleration route's fit found; None: no Stribeck term.
        stribeck_joints: the joints given the Stribeck term (None: every torque-controlled
            one). A joint that never moves faster than ``v_s`` cannot tell it from Coulomb
            friction: their columns would cancel with huge opposite values.
        one_way_joints: the joints whose regression rows moved one way (the other on fewer than
            :data:`~wbfriction.fit.status.MIN_REVERSE` of them): their Coulomb and offset columns are then one, and
            would cancel as well; their offset is held at zero (no column) and ``F_c`` carries their friction's level
            (a walking quadruped's thighs, seen while their legs swing forwards). Set by
            :func:`~wbfriction.inertia.identification.identify_inertia` from the samples.
        stride: every ``stride``-th single-support sample enters the regression (1 kHz
            logs are far denser than the dynamics need).
        holdout: share of the log's recorded time (gaps left out), at its end, kept out of the
            regression to compare the models' torque predictions.
        prior: weight of the prior toward the given model, in units of the data's residual
            variance (:mod:`wbfriction.inertia.identification`); None: chosen from
            :data:`~wbfriction.inertia.prior.PRIOR_GRID` by validation.
        uncertainty: the prior's standard deviations
            (:class:`PriorUncertainty`).
        armature: ``"known"`` (the model's, the robot's ``[armature]``), ``"identify"`` (one
            parameter per torque-controlled joint, >= 0, prior toward the model's) or ``"none"``
            (torques that do not see the rotors: link-side sensors).
        validation: share of the training samples' time span, at its end, that scores
            the priors of the grid.
        rank_tolerance: relative pivot below which a parameter is not identifiable
            (:func:`~wbfriction.inertia.least_squares.base_parameters`).
        min_mass: the mass [kg] of the sphere at which a massless or flat body's prior is measured
            (:func:`~wbfriction.inertia.consistency.body_prior`).
        block: samples per block of the compressed regression.
        link_margin: the share of each given body's pseudo-inertia an identified body keeps, in [0, 1) (its mass
            and its mass's second moment along every direction, ``J(pi) - link_margin J(pi_0)`` positive
            semidefinite: :func:`~wbfriction.inertia.consistency.fit_consistent`). A joint's torques determine
            combinations of the bodies beyond it (base parameters), and with 0 the fit may move a link's inertia
            into its neighbours' until it is a rod or a point, physical yet no link: on the KUKA LWR4+ logs of
            ``../shared/real-data`` five of seven bodies collapsed so (principal moments -97 to -100 %), and
            those bodies predicted another run's torques worse than links kept at a quarter (the held-out run's
            friction fit: 0.344 -> 0.32 N·m mean RMS; 0.1 to 0.3 give the same within 0.002).
        prior_tolerance: with the prior's weight chosen by validation, the strongest weight whose validation score
            is within this share of the best is taken (>= 0).
    """

    tanh_slope: float = 40.0
    stribeck_velocity: float | None = None
    stribeck_joints: tuple[str, ...] | None = None
    one_way_joints: tuple[str, ...] = ()
    stride: int = 5
    holdout: float = 0.2
    prior: float | None = None
    uncertainty: PriorUncertainty = PriorUncertainty()
    armature: ArmatureMode = "known"
    validation: float = 0.25
    rank_tolerance: float = 1e-8
    min_mass: float = 1e-3
    block: int = 200
    link_margin: float = 0.25
    prior_tolerance: float = 0.02

    def __post_init__(self) -> None:
        check_choice("armature", self.armature, ARMATURE_MODES)
        if not 0.0 <= self.link_margin < 1.0:
            raise OptionError(flag("link_margin"), self.link_margin, "at least 0 and below 1")
        check_range("prior_tolerance", self.prior_tolerance, low=0.0)
        if self.prior is not None and not self.prior > 0:
            raise InputError(f"the prior's weight must be > 0, got {self.prior}")
