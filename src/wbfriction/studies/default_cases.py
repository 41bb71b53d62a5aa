"""The datasets the defaults are chosen on (:mod:`wbfriction.studies.defaults`, issue 52). Each :class:`Case` runs
the route a user is given for it (:mod:`~wbfriction.studies.real_data`) under a :class:`Setting` (every stage's
options) and scores it (:class:`CaseScore`: its loss, lower is better, and each fit judged *good* or not):

* ``kuka-lwr4`` (real): the mean over joints of run 3's torque RMS over the peer's (FloBaRoID's method), the route
  identifying on runs 1 and 2; a fit is *good* where it predicts run 3 as its noise and standard errors allow
  (:func:`~wbfriction.fit.predict.other_log_checks`);
* ``kuka-repeat`` (real): runs 1 and 2 of the same robot (one trajectory run twice) fitted apart, the model
  identified on both: the mean relative RMS difference of their friction curves (:class:`KukaRepeatCase`); it
  judges no status;
* ``ur10e``, ``panda`` (real): the mean of the odd part's relative RMS error against the published curve; a fit
  is *good* within the issue's targets, 5 % and 15 %;
* ``panda-terms`` (the arm simulator's Panda with a load term and a position ripple on every joint, the studies'
  sensor noise): fitted on one log, its torques predicted on another that moves otherwise, over the true model's
  RMS there (the floor); a fit is *good* within 1.5 times the floor;
* ``panda-sim`` (the arm simulator: motor currents, armature, 1e-4 rad of position noise, 0.05 N·m of torque
  noise), identified from a model with principal moments x1.1 and masses x1.05 and no armature; ``talos-ideal``
  (the ideal simulator's combined walk, exact model, no noise); ``talos-mujoco`` (MuJoCo's combined walk with the
  studies' sensor noise, the ankle wrenches and the IMU): the mean relative error of F_c and F_v against the
  injected friction; a fit is *good* with F_c within 5 % and F_v within 10 %.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import numpy as np

from wbfriction.datasets import reference, write_dataset
from wbfriction.datasets.reference import HeldOutRms
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.fit.predict import other_log_checks, predict_torques
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import DEFAULT_THRESHOLDS, StatusThresholds, fit_verdict
from wbfriction.friction.estimate import FrictionEstimate, estimate_log
from wbfriction.friction.models import ModelParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.closed_loop import identify
from wbfriction.inertia.options import ArmatureMode, InertialOptions
from wbfriction.logs.log import Log
from wbfriction.logs.source import read_log
from wbfriction.model.loading import load_robot
from wbfriction.model.robot import Robot
from wbfriction.studies.real_data import curve_scores, odd_friction


@dataclass(frozen=True)
class Setting:
    """The options of every stage of a route (the case sets the armature)."""

    inertial: InertialOptions = InertialOptions()
    estimate: EstimateOptions = EstimateOptions()
    fit: FitOptions = FitOptions()
    thresholds: StatusThresholds = DEFAULT_THRESHOLDS


@dataclass(frozen=True)
class Judged:
    """One fit of a case: its status (at the setting's thresholds) and whether it is good (module docstring)."""

    joint: str
    status: str
    good: bool
    error: float


@dataclass(frozen=True)
class CaseScore:
    """A case's loss (lower is better; module docstring) and each fit judged."""

    loss: float
    judged: tuple[Judged, ...]

    def misjudged(self) -> float:
        """The statuses' loss: (2 x ok but not good + good but not ok) / fits."""
        n = len(self.judged)
        false_ok = sum(1 for j in self.judged if j.status == "ok" and not j.good)
        false_not = sum(1 for j in self.judged if j.status != "ok" and j.good)
        return (2 * false_ok + false_not) / n if n else math.nan


@dataclass
class Fitted:
    """What a route left for scoring: the estimate fitted, its fits, the robot model, and the held-out estimate."""

    estimate: FrictionEstimate
    fits: list[FitResult]
    robot: Robot
    held_out: FrictionEstimate | None = None
    held_out_fits: list[FitResult] | None = None
    """The held-out estimate fitted alone (the cases that compare two fits), else None."""


class Case(ABC):
    """A dataset the defaults are chosen on (module docstring); stages cached by the options they depend on."""

    name: str
    kind: Literal["real", "sim"]
    identifies: bool = False
    armature: ArmatureMode = "none"
    judges_statuses: bool = True
    """Whether its fits, judged good or not, score the statuses' thresholds (a case that compares two fits has no
    truth to judge one by)."""

    def __init__(self, folder: Path):
        self.folder = folder / self.name
        self._models: dict[Any, Robot] = {}
        self._fitted: dict[Any, Fitted] = {}

    @abstractmethod
    def prepare(self) -> None:
        """Write or simulate the case's logs (once)."""

    @abstractmethod
    def given(self) -> Robot:
        """The model a user starts from."""

    @abstractmethod
    def logs(self) -> tuple[Log, Log | None]:
        """The log the route fits on, and the held-out log (None: none)."""

    def model(self, setting: Setting) -> Robot:
        """The model the route estimates with: identified from the fitted log where the route identifies."""
        if not self.identifies:
            return self.given()
        key = (setting.inertial, setting.estimate)
        if key not in self._models:
            inertial = replace(setting.inertial, armature=self.armature)
            loop = identify(self.given(), self.logs()[0], setting.estimate, inertial, workers=2)
            self._models[key] = loop.final.identification.robot
        return self._models[key]

    def fitted(self, setting: Setting) -> Fitted:
        key = (setting.inertial if self.identifies else None, setting.estimate, setting.fit)
        if key not in self._fitted:
            robot = self.model(setting)
            train, held = self.logs()
            est = estimate_log(robot, train, setting.estimate)
            fits = fit_estimate(est, setting.fit, workers=2, targets=self.targets())
            held_est = None if held is None else estimate_log(robot, held, setting.estimate)
            self._fitted[key] = Fitted(est, fits, robot, held_est)
        return self._fitted[key]

    def targets(self) -> Mapping[str, ModelParams] | None:
        """The injected friction (simulators), None for real data."""
        return None

    @abstractmethod
    def score(self, fitted: Fitted, thresholds: StatusThresholds) -> CaseScore:
        """The case's loss and its fits judged."""


def _status(fit: FitResult, thresholds: StatusThresholds) -> str:
    return fit_verdict(fit, thresholds).status


class RealCase(Case):
    """A real dataset (:mod:`wbfriction.datasets`) through its route."""

    kind = "real"
    identifies = True
    _given: Robot
    _logs: tuple[Log, Log | None]

    @property
    def dataset(self) -> str:
        """The dataset's name (:func:`~wbfriction.datasets.write_dataset`)."""
        return self.name

    def prepare(self) -> None:
        self.written = write_dataset(self.dataset, self.folder)
        self._given = load_robot(config=self.written.config)
        held = self.written.logs.get("held_out")
        self._logs = (read_log(self.written.logs["train"], self._given),
                      None if held is None else read_log(held, self._given))

    def given(self) -> Robot:
        return self._given

    def logs(self) -> tuple[Log, Log | None]:
        return self._logs


class KukaCase(RealCase):
    """FloBaRoID's KUKA LWR4+: run 3's torques against the peer's method."""

    name = "kuka-lwr4"
    armature = "none"

    def score(self, fitted: Fitted, thresholds: StatusThresholds) -> CaseScore:
        assert fitted.held_out is not None
        ref = reference(self.name)
        fits = {f.joint: f for f in fitted.fits}
        models = {j: f.kept_terms or f.params for j, f in fits.items() if f.params is not None}
        rms = predict_torques(fitted.held_out, models).rms
        checks = other_log_checks(fitted.held_out, fits, "run 3", workers=2)
        assert isinstance(ref, HeldOutRms)
        peer = np.array([ref.held_out(j) for j in fitted.held_out.joints])
        judged = tuple(Judged(j, _status(fits[j], thresholds), c is not None and c.predicts, float(r / p))
                       for j, r, p, c in zip(fitted.held_out.joints, rms, peer, checks))
        return CaseScore(float(np.mean(rms / peer)), judged)


class KukaRepeatCase(KukaCase):
    """FloBaRoID's KUKA LWR4+ runs 1 and 2 (one trajectory run twice, half an hour apart), each fitted alone with
    the model identified on both: the loss is the mean over joints of the two fits' friction curves' relative RMS
    difference over run 2's samples moving faster than :data:`REPEAT_SPEED`
    (:func:`~wbfriction.studies.real_data.odd_friction`): a default that makes a fit follow one log's accidents
    shows as two runs that disagree. No truth judges one fit: the statuses' thresholds are not scored on it."""

    name = "kuka-repeat"
    judges_statuses = False

    @property
    def dataset(self) -> str:
        return KukaCase.name

    def prepare(self) -> None:
        super().prepare()
        runs = self._logs[0]  # runs 1 and 2, the half hour between them its longest step
        cut = int(np.argmax(np.diff(runs.time))) + 1
        self._runs = (runs.rows(0, cut), runs.rows(cut, len(runs)))

    def fitted(self, setting: Setting) -> Fitted:
        key = (setting.inertial, setting.estimate, setting.fit)
        if key not in self._fitted:
            robot = self.model(setting)
            est = [estimate_log(robot, run, setting.estimate) for run in self._runs]
            fits = [fit_estimate(e, setting.fit, workers=2) for e in est]
            self._fitted[key] = Fitted(est[0], fits[0], robot, est[1], fits[1])
        return self._fitted[key]

    def score(self, fitted: Fitted, thresholds: StatusThresholds) -> CaseScore:
        assert fitted.held_out is not None and fitted.held_out_fits is not None
        est = fitted.held_out
        judged = []
        for k, (one, two) in enumerate(zip(fitted.fits, fitted.held_out_fits)):
            use = est.valid[:, k] & (np.abs(est.qd[:, k]) >= REPEAT_SPEED)
            if one.params is None or two.params is None or not use.any():
                continue
            a, b = odd_friction(one, est, k, use)[0], odd_friction(two, est, k, use)[0]
            error = float(np.sqrt(np.mean((a - b) ** 2) / np.mean((0.5 * (a + b)) ** 2)))
            judged.append(Judged(two.joint, _status(two, thresholds), bool(error <= 0.15), error))
        return CaseScore(float(np.mean([j.error for j in judged])), tuple(judged))


REPEAT_SPEED = 0.05
"""The speed [rad/s] above which two runs' friction curves are compared (:class:`KukaRepeatCase`): below it a
joint may stick."""


class CurveCase(RealCase):
    """A real dataset with a published curve: the odd part's error against it."""

    target: float

    def score(self, fitted: Fitted, thresholds: StatusThresholds) -> CaseScore:
        ref = reference(self.name)
        est = fitted.estimate
        judged = []
        for k, fit in enumerate(fitted.fits):
            error, _ = curve_scores(fit, est, k, ref)
            judged.append(Judged(fit.joint, _status(fit, thresholds), bool(error <= self.target), error))
        return CaseScore(float(np.nanmean([j.error for j in judged])), tuple(judged))


class Ur10eCase(CurveCase):
    name = "ur10e"
    armature = "identify"
    target = 0.05


class PandaCase(CurveCase):
    name = "panda"
    armature = "none"
    target = 0.15


class SimCase(Case):
    """A simulated log with known friction: the relative errors of F_c and F_v."""

    kind = "sim"
    _robot: Robot
    _log: Log
    _truth: dict[str, ModelParams]

    def targets(self) -> Mapping[str, ModelParams] | None:
        return self._truth

    def score(self, fitted: Fitted, thresholds: StatusThresholds) -> CaseScore:
        judged, errors = [], []
        for fit in fitted.fits:
            if fit.joint not in self._truth or fit.params is None or (fit.speed or 0.0) < 0.02:
                continue
            err = fit.reported().error_percent()  # with terms kept: the velocity model refitted with them
            if err is None:
                continue
            e_c, e_v = err.get("F_c", math.nan) / 100, err.get("F_v", math.nan) / 100
            errors.append(0.5 * (e_c + e_v))
            judged.append(Judged(fit.joint, _status(fit, thresholds), bool(e_c <= 0.05 and e_v <= 0.10),
                                 max(e_c, e_v)))
        return CaseScore(float(np.nanmean(errors)), tuple(judged))

    def given(self) -> Robot:
        return self._robot

    def logs(self) -> tuple[Log, Log | None]:
        return self._log, None


class PandaSimCase(SimCase):
    """The arm simulator's Panda (motor currents, armature, sensor noise) through a wrong model, identified."""

    name = "panda-sim"
    identifies = True
    armature = "identify"

    def prepare(self) -> None:
        from wbfriction.inertia.sensitivity import scaled_robot
        from wbfriction.studies.noise import family_friction, simulate_family

        robot = load_robot("panda")
        self._truth = family_friction(robot, "thesis")
        self._log = simulate_family(robot, "thesis", 1e-4, 0, duration=20.0, steps=0, cache={})
        wrong = scaled_robot(scaled_robot(robot, 1.1, "rotational"), 1.05, "mass")
        wrong.model.armature = np.zeros(wrong.model.nv)
        self._robot = wrong


class TalosIdealCase(SimCase):
    """The ideal simulator's combined walk (3 steps of each gait), Table 6.1 friction, the exact model."""

    name = "talos-ideal"

    def prepare(self) -> None:
        from wbfriction.fit.targets import friction_by_group
        from wbfriction.sim import simulate_ideal
        from wbfriction.studies.common import SIMULATOR
        from wbfriction.walking import walking_reference
        from wbfriction.walking.options import GaitOptions

        self._robot = load_robot("talos")
        self._truth = dict(friction_by_group(self._robot.groups))
        reference_walk = walking_reference(self._robot, GaitOptions(gait="combined", steps=3))
        self._log = simulate_ideal(self._robot, reference_walk, self._truth, SIMULATOR).log


class TalosMujocoCase(SimCase):
    """MuJoCo's combined walk (3 steps of each gait) with the studies' sensor noise, the exact model."""

    name = "talos-mujoco"

    def prepare(self) -> None:
        from wbfriction.studies.noise import family_friction, simulate_family

        self._robot = load_robot("talos")
        self._truth = family_friction(self._robot, "thesis")
        self._log = simulate_family(self._robot, "thesis", 1e-4, 0, duration=0.0, steps=3, cache={})


class PandaTermsCase(SimCase):
    """The arm simulator's Panda whose friction grows with load and carries a position ripple on every joint
    (``wbfriction/data/friction_load_ripple.toml``), the studies' sensor noise: fitted on one
    log, scored on another that moves otherwise, by its torque RMS over the floor (the true model's RMS there)."""

    name = "panda-terms"

    def prepare(self) -> None:
        from wbfriction.fit.targets import load_friction_spec
        from wbfriction.logs.log import log_from_table
        from wbfriction.sim.arm import ArmOptions, ExcitationOptions, simulate_arm

        self._robot = load_robot("panda")
        spec_file = Path(str(resources.files("wbfriction").joinpath("data").joinpath("friction_load_ripple.toml")))
        self._spec = load_friction_spec(spec_file, self._robot.groups, self._robot.torque_controlled)
        self._truth = dict(self._spec.params)
        logs = []
        for seed in (0, 1):
            sim = simulate_arm(self._robot, self._spec.params, terms=self._spec.terms, options=ArmOptions(
                duration=20.0, seed=seed, excitation=ExcitationOptions(seed=seed), position_std=1e-4,
                encoder_bits=19, torque_std=0.05))
            logs.append(log_from_table(sim.table, self._robot, f"panda-terms-{seed}"))
        self._log, self._held = logs

    def logs(self) -> tuple[Log, Log | None]:
        return self._log, self._held

    def score(self, fitted: Fitted, thresholds: StatusThresholds) -> CaseScore:
        assert fitted.held_out is not None
        floor = predict_torques(fitted.held_out, {**self._spec.params, **self._spec.terms}).rms
        fits = {f.joint: f for f in fitted.fits}
        rms = predict_torques(fitted.held_out, {j: f.kept_terms or f.params for j, f in fits.items()
                                                if f.params is not None}).rms
        ratio = rms / floor
        judged = tuple(Judged(j, _status(fits[j], thresholds), bool(r <= 1.5), float(r))
                       for j, r in zip(fitted.held_out.joints, ratio))
        return CaseScore(float(np.mean(ratio)), judged)


CASES: tuple[type[Case], ...] = (KukaCase, KukaRepeatCase, Ur10eCase, PandaCase, PandaSimCase, PandaTermsCase,
                                 TalosIdealCase, TalosMujocoCase)
"""Every case, real first."""


__all__ = ["CASES", "Case", "CaseScore", "Judged", "KukaRepeatCase", "Setting"]
