"""Every real dataset through the route a user is given, scored against its published reference (issue 52).

For each dataset of :mod:`wbfriction.datasets`, :func:`run_dataset` does what a user does: ``wbfriction dataset NAME``
writes the logs, then the commands it prints run one after the other, each as its own process (``python -m
wbfriction ...``), timed, in a folder of their own. The route is the one those commands give for that kind of robot:
identify the inertia model (and, for motor currents, the armature) from the torques, estimate the friction with it,
fit, and predict the held-out log where the dataset has one.

:func:`score` reads what the commands wrote (the parameters JSON of the last ``fit``, its friction table, the held-out
friction table of ``predict``) and scores every joint (:class:`JointScore`):

* against a published curve (UR10e, Panda: :mod:`wbfriction.datasets.reference`), the odd part's relative RMS
  error ``|odd_fit - odd_ref| / |odd_ref|`` over the fitted log's valid samples with ``|qd| >= min_speed`` (0.1
  rad/s), and that deviation in the fit's own standard errors (the RMS over the same samples of the deviation over
  the curve's standard error, :meth:`~wbfriction.fit.result.FitResult.dissipative`): a fit whose standard errors
  are honest about what the data determine lies within 3 (:func:`curve_scores`: a fit with terms beyond velocity at
  each sample's load and temperature);
* on the held-out log, the torque RMS of the model fitted (:func:`~wbfriction.pipeline.predict_step.predict_file`)
  against the peer's where it is known (KUKA: FloBaRoID's method; the hung Aliengo and Go2: the iit-DLSLab's PACE
  parameters through the same estimate, and MuJoCo rollouts of the held-out set-points, :func:`peer_scores`).
"""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.datasets import reference, write_dataset
from wbfriction.datasets.reference import HeldOutRms, PeerParameters, Reference
from wbfriction.exceptions import WbfrictionError
from wbfriction.fit.params_file import read_params
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import MIN_SPEED, joint_speed
from wbfriction.fit.terms import term_signals
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.io import read_friction_file
from wbfriction.pipeline.predict_step import predict_file


@dataclass(frozen=True)
class Timed:
    """One command of a route and the wall time it took [s]."""

    command: str
    seconds: float


@dataclass(frozen=True)
class JointScore:
    """One joint of a dataset, as the route left it (NaN where a figure does not apply).

    Attributes:
        joint: its name.
        status: the fit's status (:mod:`~wbfriction.fit.status`) and ``reason`` why, when not ``ok``.
        model: the model family chosen.
        curve_error: the odd part's relative RMS error against the published curve (a share, 0.05 = 5 %).
        curve_sigmas: that deviation in the fit's standard errors (RMS over the samples of deviation / error).
        held_out: the torque RMS on the held-out log [N·m].
        peer: the peer's held-out torque RMS [N·m].
        held_out_moved: whether the joint moved in the held-out log (a joint at rest there predicts static
            friction, which no velocity model holds).
        rollout, peer_rollout: a PD-driven robot's held-out set-points replayed in MuJoCo with the route's
            identification and with the peer's: the tracking error's RMS [rad] (:mod:`wbfriction.studies.pd_peer`).
        refined_rollout: the same with the route's MJCF refined on the training log (``wbfriction refine``) [rad].
        whole_rollout: the same with the route's MJCF refined on the whole log, the peer's training data (the peer's
            footing: :func:`~wbfriction.studies.pd_peer.refine_on_whole_log`) [rad].
        given_held_out: a PD-driven robot's held-out torque RMS [N·m] through the same route with the robot TOML as
            the dataset gave it, no identification (what ``identify --config-output`` must beat).
        whole_held_out: its held-out torque RMS [N·m] with the route run on the whole log (identified and fitted on
            the training and held-out logs together, as the peer was fitted), the held-out log predicted.
    """

    joint: str
    status: str
    reason: str
    model: str
    curve_error: float = float("nan")
    curve_sigmas: float = float("nan")
    held_out: float = float("nan")
    peer: float = float("nan")
    held_out_moved: bool = False
    rollout: float = float("nan")
    peer_rollout: float = float("nan")
    refined_rollout: float = float("nan")
    whole_rollout: float = float("nan")
    given_held_out: float = float("nan")
    whole_held_out: float = float("nan")


@dataclass(frozen=True)
class DatasetRun:
    """A dataset through its route: the commands timed and each joint's score."""

    name: str
    commands: tuple[Timed, ...]
    joints: tuple[JointScore, ...] = ()
    failed: str = ""

    @property
    def seconds(self) -> float:
        """The route's wall time, the dataset's conversion included [s]."""
        return sum(c.seconds for c in self.commands)

    def ok(self) -> tuple[JointScore, ...]:
        """The joints whose fit is ``ok``."""
        return tuple(j for j in self.joints if j.status == "ok")


@dataclass(frozen=True)
class Outputs:
    """Where a route's commands wrote what :func:`score` reads."""

    params: Path
    friction: Path
    held_out: Path | None = None
    identified: Path | None = None
    mjcf: Path | None = None
    refined: Path | None = None


def outputs(commands: Sequence[str], folder: Path) -> Outputs:
    """The parameters JSON and friction table of the last ``fit`` of ``commands``, the friction table of the
    last ``predict``, the TOML ``identify --config-output`` wrote, the MJCF the last ``export`` wrote and the one the
    last ``refine`` wrote (each None without one), as paths in ``folder`` (the commands' working folder)."""
    fit = predict = identified = mjcf = refined = None
    for line in commands:
        words = shlex.split(line)
        if words[1:2] == ["fit"]:
            fit = words
        elif words[1:2] == ["predict"]:
            predict = words
        elif words[1:2] == ["identify"] and "--config-output" in words:
            identified = folder / words[words.index("--config-output") + 1]
        elif words[1:2] == ["export"]:
            written = [words[i + 1] for i, w in enumerate(words[:-1]) if w in ("-o", "--output")]
            mjcf = next((folder / w for w in written if w.endswith((".xml", ".mjcf"))), mjcf)
        elif words[1:2] == ["refine"]:
            refined = folder / words[words.index("-o") + 1]
    if fit is None:
        raise ValueError("the route has no fit")
    return Outputs(folder / fit[fit.index("-o") + 1], folder / fit[2],
                   None if predict is None else folder / predict[2], identified, mjcf, refined)


SPEED_BIN = 0.05
"""Width of the speed bins [rad/s] a fit with terms is averaged over (:func:`curve_scores`)."""


def odd_friction(fit: FitResult, est: FrictionEstimate, k: int, use: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The friction of ``fit`` (with parameters) at the samples ``use`` of joint column ``k`` of ``est`` [N·m], and
    its standard errors: its model's odd part ``(f(qd) - f(-qd)) / 2``, or, where it kept terms beyond velocity,
    what its model gives at each sample less its offset (the load, direction and temperature of that sample; the
    ripple, no friction, left out) averaged over the samples of each speed (bins of :data:`SPEED_BIN`, each way): a
    published model of the velocity alone is such an average over its log's loads; no standard error then (NaN)."""
    v = est.qd[use, k]
    terms = fit.kept_terms
    if terms is None:
        return fit.dissipative(v)
    at_samples = (terms.friction(est.qd[:, k], term_signals(est, k)) - terms.params.tau_os)[use]
    bins = np.floor(v / SPEED_BIN).astype(int)
    _, index = np.unique(bins, return_inverse=True)
    mine = (np.bincount(index, at_samples) / np.bincount(index))[index]  # each speed's mean over its loads
    return mine, np.full(v.shape, np.nan)


def curve_scores(fit: FitResult, est: FrictionEstimate, k: int, ref: Reference) -> tuple[float, float]:
    """The fit's friction against the published curve's odd part over the samples of joint column ``k`` of ``est``
    it was fitted on, with ``|qd| >= ref.min_speed``: (relative RMS error, RMS deviation in the fit's standard
    errors). The fit's friction is :func:`odd_friction`'s; no standard error where it kept terms (NaN)."""
    use = est.valid[:, k] & (np.abs(est.qd[:, k]) >= ref.min_speed)
    v = est.qd[use, k]
    if fit.params is None or v.size == 0:
        return float("nan"), float("nan")
    mine, se = odd_friction(fit, est, k, use)
    published = ref.odd(fit.joint, v)
    error = float(np.sqrt(np.mean((mine - published) ** 2) / np.mean(published**2)))
    sigmas = float(np.sqrt(np.mean(((mine - published) / se) ** 2))) if np.all(se > 0) else float("nan")
    return error, sigmas


def score(name: str, outs: Outputs, config: Path | None = None) -> tuple[JointScore, ...]:
    """Every joint of the dataset ``name`` from the outputs of its route (module docstring); ``config``: the
    robot's TOML ``wbfriction dataset`` wrote (a peer whose parameters lie beside it is scored on its held-out
    log)."""
    ref = reference(name)
    peers: dict[str, float] = {}
    rollouts: dict[str, tuple[float, ...]] = {}
    footings: dict[str, tuple[float, float]] = {}
    if isinstance(ref, PeerParameters) and config is not None:
        peers, rollouts = peer_scores(name, config, outs)
        footings = pd_footings(config, outs)
    fits = read_params(outs.params)
    est = read_friction_file(outs.friction)
    prediction = held = None
    if outs.held_out is not None:
        prediction = predict_file(outs.held_out, outs.params)
        held = read_friction_file(outs.held_out)
    out = []
    for k, joint in enumerate(est.joints):
        fit = fits[joint]
        verdict = fit.verdict()
        error = sigmas = float("nan")
        if ref.has_curve:
            error, sigmas = curve_scores(fit, est, k, ref)
        held_out = peer = float("nan")
        moved = False
        if prediction is not None and held is not None:
            i = prediction.joints.index(joint)
            held_out = float(prediction.rms[i])
            moved = joint_speed(held.qd[held.valid[:, i], i]) >= MIN_SPEED
        if isinstance(ref, HeldOutRms):
            peer = ref.held_out(joint)
        peer = peers.get(joint, peer)
        ours, theirs, refined, whole = rollouts.get(joint, (float("nan"),) * 4)
        given, whole_log = footings.get(joint, (float("nan"), float("nan")))
        out.append(JointScore(joint, verdict.status, verdict.reason, fit.model, error, sigmas, held_out, peer, moved,
                              ours, theirs, refined, whole, given, whole_log))
    return tuple(out)


def run_route(commands: Sequence[str], folder: Path, python: str = sys.executable,
              env: dict[str, str] | None = None, echo: Callable[[str], None] | None = None) -> tuple[Timed, ...]:
    """Run ``commands`` (``wbfriction ...`` lines) one after the other in ``folder``, each as ``python -m
    wbfriction ...``, timed.

    Raises:
        WbfrictionError: a command that failed, with its last line of standard error.
    """
    timed = []
    for line in commands:
        words = shlex.split(line)
        if echo is not None:
            echo(line)
        start = time.perf_counter()
        done = subprocess.run([python, "-m", "wbfriction", *words[1:]], cwd=folder, capture_output=True, text=True,
                              env=env)
        timed.append(Timed(line, time.perf_counter() - start))
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
            raise WbfrictionError(f"{line}: exit status {done.returncode}: {last}")
    return tuple(timed)


def run_dataset(name: str, folder: str | Path, python: str = sys.executable,
                echo: Callable[[str], None] | None = None) -> DatasetRun:
    """The dataset ``name`` through its route in ``folder`` (made if missing): written by ``wbfriction dataset``
    (:func:`~wbfriction.datasets.write_dataset`, timed), its printed commands run (:func:`run_route`), scored
    (:func:`score`). A route that fails is a run with its message in :attr:`DatasetRun.failed`."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    written = write_dataset(name, folder / "data")
    convert = Timed(f"wbfriction dataset {name} -o data", time.perf_counter() - start)
    commands = [c.replace(str(folder) + os.sep, "") for c in written.commands]
    try:
        timed = run_route(commands, folder, python, echo=echo)
    except WbfrictionError as exc:
        return DatasetRun(name, (convert,), failed=str(exc))
    return DatasetRun(name, (convert, *timed), score(name, outputs(commands, folder), written.config))


def peer_scores(name: str, config: Path, outs: Outputs) -> tuple[dict[str, float], dict[str, tuple[float, ...]]]:
    """The held-out torque RMS per joint [N·m] of the peer of the dataset ``name`` (a
    :class:`~wbfriction.datasets.hung_quadruped.HungQuadrupedDataset`: the Aliengo, the Go2), whose parameters lie
    beside the robot's TOML ``config`` (``peer.toml``, the held-out log ``held_out.parquet``; its friction read from the
    dataset's fetched file, :meth:`~wbfriction.datasets.hung_quadruped.HungQuadrupedDataset.peer`), and per joint the
    held-out rollouts' tracking error [rad] of the MJCF the route exported, the peer's, the route's refined MJCF and the
    export refined on the whole log as the peer was fitted (the last two NaN without a route that refines)
    (:mod:`wbfriction.studies.pd_peer`; none without the route's identified TOML and MJCF).

    Raises:
        InputError: a dataset without such a peer (not a hung quadruped's); what reading the peer raises.
    """
    import tempfile

    from wbfriction.datasets import dataset
    from wbfriction.datasets.hung_quadruped import HungQuadrupedDataset
    from wbfriction.exceptions import InputError
    from wbfriction.studies.pd_peer import peer_held_out, peer_rollouts, refine_on_whole_log

    source = dataset(name)
    if not isinstance(source, HungQuadrupedDataset):
        raise InputError(f"dataset '{name}': its reference is a peer's parameters, but it has no peer's file to read")
    folder, peer = config.parent, source.peer()
    held = peer_held_out(config, folder / "peer.toml", peer, folder / "held_out.parquet")
    if outs.identified is None or outs.mjcf is None:
        return held, {}
    with tempfile.TemporaryDirectory(prefix="wbfriction-whole-") as tmp:
        others = {}
        if outs.refined is not None:
            whole = refine_on_whole_log(outs.identified, outs.mjcf, [folder / "train.parquet",
                                                                     folder / "held_out.parquet"],
                                        Path(tmp) / "refined_whole.xml")
            others = {"refined": outs.refined, "whole": whole}
        table = peer_rollouts(config, folder / "peer.toml", peer, outs.identified, outs.mjcf,
                              folder / "held_out.parquet", others=others).to_pydict()
    nan = [float("nan")] * len(table["joint"])
    columns = [table[k] for k in ("rms.ours", "rms.peer")] + [table.get(f"rms.{k}", nan) for k in ("refined", "whole")]
    return held, {j: tuple(values) for j, *values in zip(table["joint"], *columns)}


FOOTING_ROUTE = ("wbfriction estimate {train} --config {config} --route momentum -o {tag}_train_friction.parquet",
                 "wbfriction fit {tag}_train_friction.parquet -o {tag}_params.json",
                 "wbfriction estimate {held_out} --config {config} --route momentum -o {tag}_held_out_friction.parquet")
"""The PD datasets' route after ``identify`` (the commands ``wbfriction dataset`` prints), for :func:`pd_footings`."""


def pd_footings(config: Path, outs: Outputs) -> dict[str, tuple[float, float]]:
    """Per joint of a hung PD-driven robot's dataset (its robot TOML ``config``, the logs ``train.parquet`` and
    ``held_out.parquet`` beside it), the held-out torque RMS [N·m] through the dataset's route (:data:`FOOTING_ROUTE`,
    each command its own process, in the folder of ``outs``' parameters) two more ways: with ``config`` as given (no
    identification), and with the identification and the fit made on the whole log (``train`` then ``held_out``, one
    log: the peer's footing) (:attr:`JointScore.given_held_out`, :attr:`JointScore.whole_held_out`).

    Raises:
        WbfrictionError: a command that failed.
    """
    import pyarrow.parquet as pq

    from wbfriction.logs.tables import write_table

    folder, data = outs.params.parent, config.parent
    train, held_out = data / "train.parquet", data / "held_out.parquet"
    whole = folder / "whole_log.parquet"
    write_table(pa.concat_tables([pq.read_table(train), pq.read_table(held_out)]), whole)
    identify = (f"wbfriction identify {whole.name} --config {shlex.quote(str(config))} --actuator pd "
                "--config-output whole_identified.toml")
    runs = {"given": (str(config), str(train), ()), "whole": ("whole_identified.toml", whole.name, (identify,))}
    out: dict[str, dict[str, float]] = {}
    for tag, (toml, fitted, first) in runs.items():
        lines = [*first, *(c.format(train=shlex.quote(fitted), config=shlex.quote(toml), tag=tag,
                                     held_out=shlex.quote(str(held_out))) for c in FOOTING_ROUTE)]
        run_route(lines, folder)
        prediction = predict_file(folder / f"{tag}_held_out_friction.parquet", folder / f"{tag}_params.json")
        out[tag] = {j: float(r) for j, r in zip(prediction.joints, prediction.rms)}
    return {j: (out["given"].get(j, float("nan")), out["whole"].get(j, float("nan"))) for j in out["given"]}


@dataclass(frozen=True)
class Summary:
    """What the issue asks of each dataset, counted: how many fits are ``ok`` and, of those, how many lie within
    ``max_error`` of the published curve and within 3 standard errors of it; how many joints predict the held-out
    log better than the peer."""

    name: str
    joints: int
    ok: int
    ok_within_error: int = 0
    ok_within_3_sigmas: int = 0
    worst_error: float = float("nan")
    better_than_peer: int = 0
    peers: int = 0
    seconds: float = float("nan")
    notes: tuple[str, ...] = field(default_factory=tuple)


def summarise(run: DatasetRun, max_error: float) -> Summary:
    """The counts of :class:`Summary` for one run; ``max_error`` the share a curve must be within (0.05, 0.15)."""
    ok = run.ok()
    errors = [j.curve_error for j in run.joints if np.isfinite(j.curve_error)]
    peers = [j for j in run.joints if np.isfinite(j.peer) and np.isfinite(j.held_out)]
    return Summary(run.name, len(run.joints), len(ok),
                   sum(1 for j in ok if j.curve_error <= max_error),
                   sum(1 for j in ok if j.curve_sigmas <= 3.0),
                   max(errors, default=float("nan")),
                   sum(1 for j in peers if j.held_out < j.peer), len(peers), run.seconds)


__all__ = ["DatasetRun", "JointScore", "Outputs", "Summary", "Timed", "curve_scores", "odd_friction", "outputs",
           "run_dataset", "run_route", "score", "summarise"]
