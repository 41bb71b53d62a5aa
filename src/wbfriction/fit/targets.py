"""Friction parameters per joint: the thesis's targets by joint group, and the user's TOML files.

The simulators inject these (:mod:`wbfriction.sim`); the studies compare the fits with them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import cast

from wbfriction.config import read_toml, toml_table
from wbfriction.exceptions import InputError
from wbfriction.fit.terms import TermFit
from wbfriction.friction.models import FrictionParams, ModelParams, target_from_dict
from wbfriction.friction.options import TERMS

THESIS_TARGETS: dict[str, FrictionParams] = {
    "hip_pitch": FrictionParams(F_v=0.2, F_c=0.8, S=0.2, v_s=0.2, tau_os=0.8, a=40.0),
    "hip_yaw": FrictionParams(F_v=0.2, F_c=0.8, S=0.2, v_s=0.2, tau_os=0.8, a=40.0),
    "hip_roll": FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=1.0, a=40.0),
    "knee": FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=1.0, a=40.0),
    "ankle_roll": FrictionParams(F_v=0.2, F_c=0.1, S=0.2, v_s=0.2, tau_os=0.1, a=40.0),
    "ankle_pitch": FrictionParams(F_v=0.2, F_c=0.2, S=0.2, v_s=0.2, tau_os=0.2, a=40.0),
}
"""The thesis's target friction per joint group (Table 6.1), injected in simulation."""


def friction_by_group(groups: dict[str, tuple[str, ...]],
                      targets: dict[str, FrictionParams] = THESIS_TARGETS) -> dict[str, FrictionParams]:
    """Per-joint friction parameters from per-group ones (joints of groups not in ``targets``: none)."""
    return {joint: targets[g] for g, joints in groups.items() if g in targets for joint in joints}


@dataclass(frozen=True)
class FrictionSpec:
    """What a friction TOML asks a simulator to inject (:func:`load_friction_spec`).

    Attributes:
        params: the velocity model per joint.
        terms: per joint with a ``terms`` table, its model and terms beyond velocity
            (:class:`~wbfriction.fit.terms.TermFit`; its ``params`` are ``params``' of the joint).
        temperature: the joints' temperature at the log's start and end [°C] (a linear warm-up, logged as
            ``temperature.<joint>``), or None: not simulated.
    """

    params: dict[str, ModelParams]
    terms: dict[str, TermFit]
    temperature: tuple[float, float] | None = None


TERM_KEYS = ("F_L", "dF_v", "F_cT", "F_vT", "rate_T", "reference_temperature", "ripple")
"""The keys of a ``terms`` table (:func:`load_friction_spec`)."""


def terms_from_dict(params: ModelParams, d: Mapping[str, object]) -> TermFit:
    """A joint's terms beyond velocity from a ``terms`` table: ``F_L`` (load), ``dF_v`` (direction), ``F_cT`` and
    ``F_vT`` with ``reference_temperature`` and optionally ``rate_T`` (temperature: linear, or exponential with that
    rate [1/°C]), ``ripple`` a list of ``[sin, cos]`` amplitudes per harmonic (:mod:`wbfriction.fit.terms` for
    what each means).

    Raises:
        InputError: an unknown key, a value that is not a number, a ripple that is not pairs, temperature
            coefficients without a reference temperature.
    """
    unknown = [k for k in d if k not in TERM_KEYS]
    if unknown:
        raise InputError(f"unknown term key '{unknown[0]}': choose among {', '.join(TERM_KEYS)}")
    try:
        c = {k: float(cast(float, d[k])) for k in ("F_L", "dF_v", "F_cT", "F_vT", "rate_T") if k in d}
        ripple = [(float(s), float(co)) for s, co in cast(list, d.get("ripple", []))]
        t_ref = None if d.get("reference_temperature") is None else float(cast(float, d["reference_temperature"]))
    except (TypeError, ValueError) as exc:
        raise InputError(f"terms: {exc} (numbers, and ripple as [[sin, cos], ...] per harmonic)") from None
    present = {"load": "F_L" in c, "direction": "dF_v" in c, "ripple": bool(ripple),
               "temperature": "F_cT" in c or "F_vT" in c or "rate_T" in c}
    c.update({f"ripple_{f}{h}": x for h, pair in enumerate(ripple, 1) for f, x in zip(("sin", "cos"), pair)})
    if present["temperature"]:
        if t_ref is None:
            raise InputError("terms: F_cT and F_vT need a reference_temperature [°C]")
        c.setdefault("F_cT", 0.0)
        c.setdefault("F_vT", 0.0)
    return TermFit(params, tuple(t for t in TERMS if present[t]), len(ripple), c, reference_temperature=t_ref)


def load_friction_spec(path: str | Path, groups: dict[str, tuple[str, ...]],
                       joints: tuple[str, ...]) -> FrictionSpec:
    """Friction per joint from a TOML file, with terms beyond velocity and a warm-up.

    Each table under ``[friction]`` is named after a joint group or a joint and gives the
    parameters of (3.5), or of the model its ``model`` key names (``coulomb-viscous``: F_v, F_c, tau_os;
    ``stribeck``: F_v, F_c, F_s, v_s, tau_os); missing ones take the model's defaults. A joint's
    own table overrides its group's. A ``terms`` table under it adds friction beyond velocity
    (:func:`terms_from_dict`); a top-level ``[temperature]`` table (``start``, ``end`` [°C]) warms the joints over
    the log and logs it::

        [friction.knee]
        F_v = 0.2
        F_c = 1.0
        [friction.knee.terms]
        F_L = 0.02
        F_cT = -0.008
        F_vT = -0.004
        reference_temperature = 40.0
        ripple = [[0.1, 0.05]]
        [friction.leg_right_4_joint]
        model = "coulomb-viscous"
        F_c = 1.5
        [temperature]
        start = 25.0
        end = 55.0

    Raises:
        InputError: unreadable file, an unknown group, joint, model, parameter or term key; a temperature term
            without the ``[temperature]`` table.
    """
    document = read_toml(path)
    table = toml_table(path, "friction", document)
    params: dict[str, ModelParams] = {}
    terms: dict[str, TermFit] = {}
    for is_group in (True, False):  # groups first, joints override
        for name, values in table.items():
            if (name in groups) != is_group:
                continue
            if not is_group and name not in joints:
                raise InputError(f"{path}: [friction.{name}] names neither a joint group nor a joint")
            values = dict(values) if isinstance(values, dict) else values
            extra = values.pop("terms", None) if isinstance(values, dict) else None
            try:
                p = target_from_dict(values) if isinstance(values, dict) else FrictionParams.from_dict(values)
                t = None if extra is None else terms_from_dict(p, extra if isinstance(extra, dict) else {})
            except InputError as exc:
                raise InputError(f"{path}: [friction.{name}]: {exc}") from exc
            for joint in (groups[name] if is_group else (name,)):
                params[joint] = p
                if t is not None:
                    terms[joint] = t
                else:
                    terms.pop(joint, None)
    temperature = document.get("temperature")
    warm = None
    if temperature is not None:
        try:
            warm = (float(temperature["start"]), float(temperature["end"]))
        except (TypeError, KeyError, ValueError):
            raise InputError(f"{path}: [temperature] needs start and end [°C] as numbers") from None
    if warm is None and any("temperature" in t.kept for t in terms.values()):
        raise InputError(f"{path}: a temperature term needs a [temperature] table (start, end [°C])")
    return FrictionSpec(params, terms, warm)

