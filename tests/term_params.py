"""Small synthetic parameters files and friction tables of one joint with terms beyond velocity (issue 53's tests):
a fit whose status is ``ok``, written as ``wbfriction fit`` writes it, and tables whose friction is written from the
physical law itself, not through :mod:`wbfriction.fit.terms`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.fit.params_file import write_params
from wbfriction.fit.ranges import FittedRanges
from wbfriction.fit.result import FitResult
from wbfriction.fit.terms import TermFit
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.io import friction_table
from wbfriction.friction.models import CoulombViscousParams
from wbfriction.logs.tables import write_table

JOINT = "panda_joint1"
VELOCITY = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.0)
T_REF = 40.0
COEFFICIENTS = {"F_L": 0.02, "F_cT": -0.008, "F_vT": -0.002, "ripple_sin1": 0.10, "ripple_cos1": 0.05,
                "ripple_sin2": 0.03, "ripple_cos2": -0.02}
"""A load term (k_L 0.02 /(N·m)), a linear temperature law (k_Tc -0.8 %/°C) and a two-harmonic ripple of 0.1 N·m."""
Q_RANGE = (0.5, 2.5)
RANGES = FittedRanges(angle=Q_RANGE, load=(0.0, 30.0), temperature=(25.0, 55.0))


def term_fit(kept: tuple[str, ...] = ("load", "ripple", "temperature"), ranges: FittedRanges | None = RANGES,
             **coefficients: float) -> TermFit:
    """The terms ``kept`` with :data:`COEFFICIENTS` (``coefficients`` added or changed), standard errors of 1 %."""
    c = {n: v for n, v in COEFFICIENTS.items()
         if ("load" in kept and n == "F_L") or ("temperature" in kept and n in ("F_cT", "F_vT"))
         or ("ripple" in kept and n.startswith("ripple"))}
    c.update(coefficients)
    derived = {name: value for name, value in (
        ("k_L", c.get("F_L", np.nan) / VELOCITY.F_c), ("k_Tc", c.get("F_cT", np.nan) / VELOCITY.F_c),
        ("k_Tv", c.get("F_vT", np.nan) / VELOCITY.F_v),
        ("ripple_rms", np.sqrt(sum(v**2 for n, v in c.items() if n.startswith("ripple")) / 2))) if np.isfinite(value)
        and (name != "ripple_rms" or "ripple" in kept)}  # the ripple's size: its RMS over a whole turn
    stderr = {n: 0.01 * abs(v) + 1e-6 for n, v in {**c, **derived, **VELOCITY.to_dict()}.items()}
    return TermFit(VELOCITY, kept, 2 if "ripple" in kept else 0, c, stderr, derived,
                   reference_temperature=T_REF if "temperature" in kept else None,
                   q_range=Q_RANGE if "ripple" in kept else None, held_out_rms=(0.05, 0.04), ranges=ranges)


def ok_fit(terms: TermFit | None = None, joint: str = JOINT) -> FitResult:
    """A converged coulomb-viscous fit of a joint that moved (1 rad/s), standard errors of 1 %, with ``terms``."""
    fit = FitResult(joint, 2000, params=VELOCITY, stderr={"F_v": 0.002, "F_c": 0.01, "tau_os": 0.001}, success=True,
                    message="converged", speed=1.0, at_bound={n: False for n in VELOCITY.names},
                    model="coulomb-viscous", terms=terms)
    assert fit.verdict().status == "ok", fit.verdict()
    return fit


def params_file(path: Path, terms: TermFit | None = None) -> Path:
    """The parameters JSON of :func:`ok_fit` (``provenance.robot``: panda), as ``fit`` writes it."""
    write_params(path, [ok_fit(terms)], {"provenance": {"robot": "panda"}})
    return path


def edited(path: Path, edit, out: Path | None = None) -> Path:
    """The parameters file at ``path`` with ``edit(joint_entry)`` applied to its joint's entry (in place, or to
    ``out``)."""
    doc: dict[str, Any] = json.loads(path.read_text())
    edit(doc["joints"][JOINT])
    out = out or path
    out.write_text(json.dumps(doc))
    return out


def physical_friction(qd: np.ndarray, q: np.ndarray, load: np.ndarray, temperature: np.ndarray,
                      c: dict[str, float] = COEFFICIENTS) -> np.ndarray:
    """``f`` of the joint written in its physical terms: ``(F_c + F_L |load| + F_cT (T - T_ref)) sgn(qd)
    + (F_v + F_vT (T - T_ref)) qd + sum_h s_h sin(h q) + c_h cos(h q)``."""
    dT = temperature - T_REF
    return ((VELOCITY.F_c + c["F_L"] * np.abs(load) + c["F_cT"] * dT) * np.sign(qd)
            + (VELOCITY.F_v + c["F_vT"] * dT) * qd
            + sum(c[f"ripple_sin{h}"] * np.sin(h * q) + c[f"ripple_cos{h}"] * np.cos(h * q) for h in (1, 2)))


def motion(n: int = 2000, seed: int = 0, swing: float = 0.9) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(time, qd, q, load)``: a joint swinging over the angles 0.6-2.4 rad (inside :data:`Q_RANGE`; ``1.5 ± swing``
    [rad]) at up to about 1.6 rad/s, under a load of 0-25 N·m, sampled at 100 Hz."""
    t = np.arange(n) * 0.01
    q = 1.5 + swing * np.sin(1.7 * t)
    qd = swing * 1.7 * np.cos(1.7 * t)
    load = 12.5 + 12.5 * np.sin(0.6 * t + 0.3)
    return t, qd, q, load


def motion_estimate(temperature: np.ndarray, q_logged: np.ndarray | None = None, noise: float = 0.01, seed: int = 0,
                    c: dict[str, float] = COEFFICIENTS, swing: float = 0.9) -> FrictionEstimate:
    """The friction estimate of :data:`JOINT` (as ``estimate`` makes it) of :func:`motion` (``swing``) at
    ``temperature`` (N,) [°C], its friction :func:`physical_friction` of the true angle plus ``noise`` [N·m] of white
    noise, its angle logged as ``q_logged`` (N,) [rad] (default the true one: another branch is the logger's)."""
    t, qd, q, load = motion(len(temperature), seed, swing)
    tau_f = -physical_friction(qd, q, load, temperature, c) + np.random.default_rng(seed).normal(0, noise, len(t))
    col = lambda x: np.asarray(x, dtype=float)[:, None]  # noqa: E731
    return FrictionEstimate(joints=(JOINT,), time=t, qd=col(qd), tau_f=col(tau_f), valid=np.ones((len(t), 1), bool),
                            phase=np.full(len(t), "single"), unique=np.ones(len(t), bool),
                            contact=np.zeros((len(t), 0), bool), contact_frames=(),
                            q=col(q if q_logged is None else q_logged), tau=col(load - tau_f),
                            temperature=col(temperature), metadata={"provenance": {"robot": "panda"}})


def table_file(path: Path, temperature: np.ndarray, q_shift: float = 0.0, noise: float = 0.01, seed: int = 0,
               c: dict[str, float] = COEFFICIENTS) -> Path:
    """A friction table of :data:`JOINT` (as ``estimate`` writes it) of :func:`motion` at ``temperature`` (N,) [°C],
    its angle logged ``q_shift`` [rad] away (another branch: 2π k), its friction :func:`physical_friction` of the
    true angle plus ``noise`` [N·m] of white noise (:func:`motion_estimate`)."""
    q = motion(len(temperature), seed)[2]
    write_table(friction_table(motion_estimate(temperature, q + q_shift, noise, seed, c)), path)
    return path
