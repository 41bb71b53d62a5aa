"""The friction laws the generalisation benchmark simulates (:mod:`wbfriction.studies.generalise`), and the truth a
fit of the tool is judged against.

Sign convention: ``tau_f`` is the torque friction exerts on the joint [N·m]; the law gives ``f`` and the simulator
applies ``tau_f = -f`` (dissipative: ``qd · tau_f <= 0`` but for the position ripple, which is conservative-like
cogging, and the LuGre bristle's pre-sliding spring).

Every law is one parametrisation, per joint (:class:`JointLaw`), evaluated on all joints at once at every physics
step (:class:`LawState`):

.. math::

    f = m_T(t)\\,\\Big[c(\\dot q)\\,(1 + k_L |L|) + F_v^{\\pm} \\dot q\\Big] + A \\sin(n q + \\varphi),
    \\qquad m_T(t) = 1 + k_T (T(t) - T_0)

with the Coulomb part ``c`` either ``tanh(a qd) F_c^± (1 + S exp(-(qd / v_s)^2))`` (Coulomb-viscous: ``S = 0``;
the project's (3.5) Stribeck; asymmetric: ``F_c^+ != F_c^-``, ``F_v^+ != F_v^-``), or a LuGre-like bristle
``sigma_0 z`` with ``dz/dt = qd - sigma_0 |qd| z / g(qd)``, ``g = F_c (1 + S exp(-(qd / v_s)^2))``, integrated
exactly over each physics step at constant ``qd`` (Canudas de Wit, Olsson, Åström & Lischinsky, *A new model for
control of systems with friction*, IEEE TAC 40(3), 1995; no bristle damping). ``L`` is the joint's load (the
rigid-body torque of the last step, [N·m]), ``T`` a linear warm-up of the joint from ``T_0`` [°C] that the log does
not carry.

**The truth** (:func:`truth_from_log`): the tool fits F_c and F_v. For the Coulomb-viscous and Stribeck laws these
are the law's own (its ``tanh`` and Stribeck factor known: a least-squares fit of the log's injected ``-tau_f`` on
that basis returns them exactly). For every other law (asymmetric, load-dependent, ripple, LuGre, temperature) the
tool's F_c and F_v have no exact counterpart, and the truth is the **Coulomb-viscous best approximation over the
velocities the log visits**: the least-squares fit of ``-tau_f`` on ``[sgn(qd), qd]`` (and a constant for the
asymmetric law, which the tool's offset ``tau_os`` takes) over the samples at which ``|qd| >=`` :data:`V_MIN`. A
joint that visited too few speeds (:data:`MIN_MOVING` samples, or a spread of ``|qd|`` under :data:`MIN_SPREAD`)
gets the law's nominal values (the mean of either direction's, at the log's mean temperature).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Literal, get_args

import numpy as np

Law = Literal["coulomb-viscous", "stribeck", "asymmetric", "load", "ripple", "lugre", "temperature"]
"""The laws drawn (module docstring)."""
LAWS: tuple[Law, ...] = get_args(Law)
EXACT_LAWS: tuple[Law, ...] = ("coulomb-viscous", "stribeck")
"""The laws whose F_c and F_v are the tool's own (the truth is the law's parameters)."""
VELOCITY_LAWS: tuple[Law, ...] = ("coulomb-viscous", "stribeck", "asymmetric")
"""The laws of the velocity alone (what the hung PD-driven simulator's friction takes)."""
V_MIN = 0.02
"""Samples slower than this [rad/s] are left out of the truth's fit."""
MIN_MOVING = 50
"""A joint with fewer moving samples gets its law's nominal values as the truth."""
MIN_SPREAD = 0.01
"""... and so does one whose moving samples' ``|qd|`` spread (standard deviation) is below this [rad/s]."""


@dataclass(frozen=True)
class JointLaw:
    """One joint's friction law (module docstring); units N·m, N·m·s/rad, rad/s, s/rad, 1/(N·m), rad, 1/°C.

    Attributes:
        law: which of :data:`LAWS`.
        F_c, F_v: the Coulomb and viscous levels for positive velocities; F_c_neg, F_v_neg: for negative ones
            (equal but for the asymmetric law).
        S, v_s: the Stribeck factor and velocity (S = 0: none); a: the ``tanh`` slope: 1000 s/rad but for the
            Stribeck law (drawn, 40-200: (3.5) has it), as steep as the tool's Coulomb–viscous family's sign
            function (with 100 s/rad, the band below 0.03 rad/s of a noise-free 3-joint chain's log took F_v 55 %
            off in ``fit``'s Coulomb–viscous fit, where a least-squares fit of the estimate on the law's own basis
            gave it exactly).
        k_load: the load dependence of the Coulomb part.
        ripple, ripple_n, ripple_phase: the position ripple's amplitude [N·m], its periods per radian and phase.
        sigma0: the LuGre bristle stiffness [N·m/rad] (0: no bristle, the ``tanh``).
        k_temp: the relative change of F_c and F_v per °C of warm-up.
    """

    law: Law
    F_c: float
    F_v: float
    F_c_neg: float
    F_v_neg: float
    S: float = 0.0
    v_s: float = 0.1
    a: float = 1000.0
    k_load: float = 0.0
    ripple: float = 0.0
    ripple_n: float = 1.0
    ripple_phase: float = 0.0
    sigma0: float = 0.0
    k_temp: float = 0.0

    def nominal(self, temperature_factor: float = 1.0) -> dict[str, float]:
        """The law's own F_c and F_v: the mean of either direction's, times the mean temperature factor."""
        return {"F_c": 0.5 * (self.F_c + self.F_c_neg) * temperature_factor,
                "F_v": 0.5 * (self.F_v + self.F_v_neg) * temperature_factor}

    def to_dict(self) -> dict:
        """The law as JSON (the log's ``friction_law`` metadata)."""
        return asdict(self)


def _column(laws: Sequence[JointLaw], name: str) -> np.ndarray:
    return np.array([float(getattr(law, name)) for law in laws])


class LawState:
    """The friction of every joint at each physics step, its LuGre bristles' state kept between steps.

    Args:
        laws: per joint (n,).
        warm_up: the joints' temperature rise over the log, ``(T_0, T_1)`` [°C], reached linearly over ``duration``
            [s].
    """

    def __init__(self, laws: Sequence[JointLaw], warm_up: tuple[float, float] = (25.0, 25.0),
                 duration: float = 1.0) -> None:
        self.laws = tuple(laws)
        c = {k: _column(laws, k) for k in ("F_c", "F_v", "F_c_neg", "F_v_neg", "S", "v_s", "a", "k_load", "ripple",
                                           "ripple_n", "ripple_phase", "sigma0", "k_temp")}
        self.c = c
        self.bristle = c["sigma0"] > 0
        self.z = np.zeros(len(laws))
        self.warm_up, self.duration = warm_up, duration
        # the parts every joint lacks are skipped (the same numbers: each would add zero or multiply by one)
        self._asymmetric = bool(np.any(c["F_c"] != c["F_c_neg"]) or np.any(c["F_v"] != c["F_v_neg"]))
        self._stribeck, self._load = bool(np.any(c["S"] != 0)), bool(np.any(c["k_load"] != 0))
        self._ripple = bool(np.any(c["ripple"] != 0))
        self._warm = bool(np.any(c["k_temp"] != 0)) and warm_up[1] != warm_up[0]

    def temperature_factor(self, t: float | np.ndarray) -> np.ndarray:
        """``m_T`` per joint at time ``t`` [s] (module docstring): (n,), or (N, n) for times (N,)."""
        t0, t1 = self.warm_up
        rise = (t1 - t0) * np.clip(np.asarray(t, dtype=float) / self.duration, 0.0, 1.0)
        return 1.0 + np.multiply.outer(rise, self.c["k_temp"])

    def f(self, qd: np.ndarray, q: np.ndarray, load: np.ndarray, t: float, h: float) -> np.ndarray:
        """The law's ``f`` (n,) [N·m] over the physics step ``[t, t + h)`` from the step's velocities [rad/s],
        angles [rad] and loads [N·m]; advances the bristles by ``h`` [s]."""
        c = self.c
        if self._asymmetric:
            positive = qd > 0
            F_c = np.where(positive, c["F_c"], c["F_c_neg"])
            F_v = np.where(positive, c["F_v"], c["F_v_neg"])
        else:
            F_c, F_v = c["F_c"], c["F_v"]
        if self._stribeck:
            F_c = F_c * (1.0 + c["S"] * np.exp(-np.square(qd / c["v_s"])))
        coulomb = np.tanh(c["a"] * qd) * F_c
        if self.bristle.any():
            b = self.bristle
            g, z, sigma0 = F_c[b], self.z[b], c["sigma0"][b]
            coulomb[b] = sigma0 * z
            z_ss = np.sign(qd[b]) * g / sigma0
            self.z[b] = z_ss + (z - z_ss) * np.exp(-sigma0 * np.abs(qd[b]) * h / g)
        if self._load:
            coulomb = coulomb * (1.0 + c["k_load"] * np.abs(load))
        out = coulomb + F_v * qd
        if self._warm:
            out = self.temperature_factor(t) * out
        if self._ripple:
            out = out + c["ripple"] * np.sin(c["ripple_n"] * q + c["ripple_phase"])
        return out


def truth_from_log(laws: Sequence[JointLaw], qd: np.ndarray, tau_f: np.ndarray,
                   temperature_factor: np.ndarray | None = None) -> list[dict[str, float]]:
    """The truth per joint (module docstring) from the true velocities ``qd`` [rad/s] and the injected friction
    ``tau_f`` [N·m] at the log's samples, each (N, n); ``temperature_factor`` (N, n): ``m_T`` at the samples (for
    the nominal fallback).

    Returns:
        per joint ``{"F_c": ..., "F_v": ...}`` (and ``"tau_os"`` for the asymmetric law) [N·m, N·m·s/rad].
    """
    out = []
    for j, law in enumerate(laws):
        v, f = qd[:, j], -tau_f[:, j]
        moving = np.abs(v) >= V_MIN
        m_t = 1.0 if temperature_factor is None else float(np.mean(temperature_factor[:, j]))
        if moving.sum() < MIN_MOVING or np.std(np.abs(v[moving])) < MIN_SPREAD:
            out.append(law.nominal(m_t))
            continue
        v, f = v[moving], f[moving]
        if law.law in EXACT_LAWS:
            basis = [np.tanh(law.a * v) * (1.0 + law.S * np.exp(-np.square(v / law.v_s))), v]
        else:
            basis = [np.sign(v), v] + ([np.ones_like(v)] if law.law == "asymmetric" else [])
        x = np.linalg.lstsq(np.column_stack(basis), f, rcond=None)[0]
        d = {"F_c": float(x[0]), "F_v": float(x[1])}
        if law.law == "asymmetric":
            d["tau_os"] = float(x[2])
        out.append(d)
    return out


def draw_law(rng: np.random.Generator, law: Law, F_c: float, F_v: float) -> JointLaw:
    """One joint's law of kind ``law`` about the levels ``F_c`` [N·m] and ``F_v`` [N·m·s/rad], its other
    parameters drawn from ``rng`` (ranges in the code: a Stribeck factor 0.2-0.8 at 0.02-0.2 rad/s, asymmetry
    ±15-40 %, a load dependence giving 2-20 % more Coulomb friction per 10 N·m, a ripple of 10-30 % of F_c with 2-8
    periods per radian, a bristle stiffness putting the pre-sliding at 1-10 mrad, -0.3 to -1 % per °C)."""
    kw: dict = {}
    F_c_neg, F_v_neg = F_c, F_v
    if law == "stribeck":
        kw.update(S=rng.uniform(0.2, 0.8), v_s=rng.uniform(0.02, 0.2), a=rng.uniform(40.0, 200.0))
    elif law == "asymmetric":
        F_c_neg = F_c * (1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(0.15, 0.4))
        F_v_neg = F_v * (1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(0.15, 0.4))
    elif law == "load":
        kw.update(k_load=rng.uniform(0.002, 0.02))
    elif law == "ripple":
        kw.update(ripple=F_c * rng.uniform(0.1, 0.3), ripple_n=float(rng.integers(2, 9)),
                  ripple_phase=rng.uniform(0.0, 2 * np.pi))
    elif law == "lugre":
        kw.update(sigma0=F_c / rng.uniform(1e-3, 1e-2), S=rng.uniform(0.0, 0.5), v_s=rng.uniform(0.02, 0.1))
    elif law == "temperature":
        kw.update(k_temp=-rng.uniform(0.003, 0.01))
    return JointLaw(law, float(F_c), float(F_v), float(F_c_neg), float(F_v_neg),
                    **{k: float(v) for k, v in kw.items()})
