"""Friction families as objects (issue 54): a family defined here, registered with one call, is fitted by the
library (``fit_friction``, ``fit_estimate``, ``--model auto`` among the others) and by the command line (in this
process, and in another one through an installed package's entry point), its parameters recovered from synthetic
data; every family's Jacobians match finite differences, its fit coordinates round-trip, its design columns sum to
its characteristic; the registry's errors carry the name and the families known."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, cast

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import ArrayLike

from helpers import run_cli_printed
from wbfriction.exceptions import OptionError
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions, ModelChoice, TermOptions, model_choices
from wbfriction.fit.projection import factor_positions
from wbfriction.fit.selection import fit_friction
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.families import (
    BUILTIN_NAMES,
    FrictionFamily,
    InvalidFamily,
    ModelParamsBase,
    UnknownFamilyError,
    families,
    family,
    family_names,
    register_family,
    unregister_family,
)
from wbfriction.logs.tables import write_table

TOY = "viscous-only"


@dataclass(frozen=True)
class ViscousOnlyParams(ModelParamsBase):
    """Viscous friction (3.2) with the offset of (3.4): ``f = F_v qd + tau_os``."""

    model: ClassVar[str] = TOY
    names: ClassVar[tuple[str, ...]] = ("F_v", "tau_os")

    F_v: float = 0.0
    tau_os: float = 0.0

    def f(self, qd: ArrayLike) -> np.ndarray:
        return self.F_v * np.asarray(qd, dtype=float) + self.tau_os

    def quantities(self) -> dict[str, float]:
        return {"F_v": self.F_v, "F_c": 0.0, "F_s": 0.0, "S": 0.0, "v_s": float("nan"), "tau_os": self.tau_os,
                "a": float("inf")}


class ViscousOnly(FrictionFamily):
    """The toy family: linear in both parameters, no jump; its expectation under a velocity noise is the base class's
    Gauss-Hermite rule (exact for a line)."""

    name, equation, params_class = TOY, "3.2", ViscousOnlyParams
    units = {"F_v": "N·m·s/rad", "tau_os": "N·m"}
    lower, upper = np.array([0.0, -np.inf]), np.array([np.inf, np.inf])
    constant_columns = ("F_v", "tau_os")
    column_factors = (("F_v",), ("tau_os",))

    def values(self, x, qd, delta_s):
        return x[0] * np.asarray(qd, dtype=float) + x[1]

    def jacobian(self, x, qd, delta_s):
        return np.column_stack([qd, np.ones_like(qd)])

    def columns(self, qd, delta_s, z, jump=None):
        return np.column_stack([qd, np.ones_like(qd)])


TRUTH = ViscousOnlyParams(F_v=0.4, tau_os=0.15)
"""The toy's parameters the synthetic data are made of."""

T = np.arange(4000) * 2e-3
QD = 1.2 * np.sin(2 * np.pi * 0.31 * T) + 0.4 * np.sin(2 * np.pi * 1.7 * T + 0.5)
"""A joint's velocity over 8 s [rad/s]."""

NOISE = 0.03
"""The torque noise of the synthetic data [N·m]."""


def noisy_torque(seed: int = 0) -> np.ndarray:
    """``tau_f = -f(qd)`` of :data:`TRUTH` at :data:`QD`, with a white noise of :data:`NOISE` [N·m]."""
    return TRUTH.torque(QD) + np.random.default_rng(seed).normal(0.0, NOISE, QD.size)


@pytest.fixture
def toy():
    """The toy family, registered for one test (one call), then forgotten."""
    fam = register_family(ViscousOnly())
    yield fam
    unregister_family(TOY)


def assert_recovered(fit, truth: ModelParamsBase = TRUTH) -> None:
    """Each parameter of ``fit`` within 4 standard errors of ``truth`` and within 2 % (the offset 0.01 N·m)."""
    assert fit.model == TOY and fit.success and isinstance(fit.params, ViscousOnlyParams)
    for name in truth.names:
        value, true, se = getattr(fit.params, name), getattr(truth, name), fit.stderr[name]
        assert 0 < se < 0.01 and abs(value - true) < 4 * se, (name, value, true, se)
        assert abs(value - true) < max(0.02 * abs(true), 0.01), (name, value, true)


# the registry

def test_one_call_registers_a_family_and_its_name_becomes_a_model_choice(toy):
    assert family(TOY) is toy and TOY in family_names() and TOY in model_choices()
    assert FitOptions(model=cast(ModelChoice, TOY)).model == TOY
    assert [f.name for f in families()] == [TOY, *BUILTIN_NAMES]  # simplest (fewest parameters) first
    unregister_family(TOY)
    with pytest.raises(UnknownFamilyError):
        FitOptions(model=cast(ModelChoice, TOY))
    register_family(toy)


def test_an_unknown_name_is_one_error_naming_it_and_the_families_known():
    with pytest.raises(UnknownFamilyError) as info:
        family("lugre")
    assert info.value.name == "lugre" and info.value.known == BUILTIN_NAMES
    assert str(info.value) == "model must be one of coulomb-viscous, stribeck, thesis, got 'lugre'"
    with pytest.raises(OptionError) as option:  # where the options are made, with auto
        FitOptions(model=cast(ModelChoice, "lugre"))
    assert str(option.value) == "--model must be one of auto, coulomb-viscous, stribeck, thesis, got 'lugre'"
    assert option.value.option == "--model" and option.value.value == "lugre"
    import pickle
    again = pickle.loads(pickle.dumps(info.value))
    assert (again.name, again.known, str(again)) == ("lugre", BUILTIN_NAMES, str(info.value))


def test_a_definition_that_does_not_hold_together_is_refused_before_it_is_registered():
    class Broken(ViscousOnly):
        upper = np.array([np.inf])

    with pytest.raises(InvalidFamily, match="upper has 1 bounds for 2 parameters") as info:
        register_family(Broken())
    assert info.value.family == TOY and TOY not in family_names()

    class Stranger(ViscousOnly):
        column_factors = (("F_v",), ("F_x",))

    with pytest.raises(InvalidFamily, match="not parameters of its: F_x"):
        register_family(Stranger())
    with pytest.raises(ValueError, match="built-in"):
        unregister_family("thesis")


def test_the_names_are_checked_without_numpy():
    """The command line's help lists the families and ``FitOptions`` checks a name without loading NumPy or a
    family."""
    code = ("import sys\nfrom wbfriction.fit.options import FitOptions, model_choices\n"
            "from wbfriction.friction.families.registry import family_names\n"
            "FitOptions(model='stribeck'); print(model_choices(), family_names())\n"
            "try:\n    FitOptions(model='lugre')\nexcept Exception as exc:\n    print(type(exc).__name__)\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('numpy', 'scipy')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[-2:] == ["UnknownFamilyError", "[]"]


# the toy family fitted: the library

def test_the_library_fits_the_registered_family_and_recovers_its_parameters(toy):
    fit = fit_friction(QD, noisy_torque(), model=TOY)
    assert_recovered(fit)
    assert fit.rms_residual == pytest.approx(NOISE, rel=0.05) and fit.bounded() == ()
    # with a velocity noise (the base class's expectation) and held parameters
    noisy = fit_friction(QD, noisy_torque(), model=TOY, velocity_noise=0.01)
    assert_recovered(noisy)
    held = fit_friction(QD, noisy_torque(), model=TOY, fixed={"tau_os": 0.15})
    assert held.stderr["tau_os"] == 0.0 and held.params.tau_os == 0.15 and abs(held.params.F_v - 0.4) < 0.01


def test_fit_estimate_fits_every_joint_with_the_registered_family_on_worker_processes(toy):
    n = QD.size
    qd = np.column_stack([QD, 0.5 * QD])
    truths = [TRUTH, ViscousOnlyParams(F_v=1.1, tau_os=-0.3)]
    rng = np.random.default_rng(3)
    tau_f = np.column_stack([p.torque(qd[:, j]) for j, p in enumerate(truths)]) + rng.normal(0, NOISE, qd.shape)
    est = FrictionEstimate(("a", "b"), T, qd, tau_f, np.ones(qd.shape, dtype=bool), np.zeros(n, dtype=int),
                           np.ones(n, dtype=bool), np.ones((n, 1), dtype=bool), ("sole",))
    fits = fit_estimate(est, FitOptions(model=cast(ModelChoice, TOY), terms=TermOptions(terms=())), workers=2)
    for fit, truth in zip(fits, truths):
        assert_recovered(fit, truth)


def test_auto_chooses_among_every_family_the_registered_one_first(toy):
    auto = fit_friction(QD, noisy_torque(), model="auto")
    assert [s.model for s in auto.selection.scores] == [TOY, *BUILTIN_NAMES]
    assert auto.model == TOY and auto.selection.chosen == TOY
    assert_recovered(auto)


# the toy family fitted: the command line

@pytest.fixture(scope="module")
def table(tmp_path_factory) -> Path:
    """A friction table of one joint made by :data:`TRUTH`, with noise."""
    path = tmp_path_factory.mktemp("toy") / "friction.parquet"
    write_table(pa.table({"time": T, "qd.j": QD, "tau_f.j": noisy_torque(), "valid.j": np.ones(QD.size, dtype=bool)}),
                path)
    return path


def read_fit(path: Path) -> dict:
    return json.loads(path.read_text())["joints"]["j"]


def test_the_command_line_fits_a_family_registered_in_its_process(toy, table, tmp_path, capsys):
    """``wbfriction fit --model viscous-only``, in this process after the registration (what a program that defines
    a family and runs the command line does)."""
    out = tmp_path / "p.json"
    code, printed, err = run_cli_printed(capsys, "fit", table, "--model", TOY, "--terms", "none", "-o", out)
    assert code == 0, err
    entry = read_fit(out)
    assert entry["model"] == TOY and set(entry["params"]) == {"F_v", "tau_os"}
    for name in TRUTH.names:
        assert abs(entry["params"][name] - getattr(TRUTH, name)) < 4 * entry["stderr"][name]
    code, _, err = run_cli_printed(capsys, "fit", table, "--model", "lugre", "-o", tmp_path / "q.json")
    assert code == 2 and "--model must be one of auto, coulomb-viscous, stribeck, thesis, viscous-only, got 'lugre'" \
        in err and not (tmp_path / "q.json").exists()


def test_an_installed_package_adds_a_family_to_the_command_line(table, tmp_path):
    """A package advertising the toy under the entry-point group ``wbfriction.families`` (a ``dist-info`` folder on
    the path) makes it a choice of ``wbfriction fit --model`` in another process."""
    site = tmp_path / "site"
    dist = site / "toy_family-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-family\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(f"[wbfriction.families]\n{TOY} = test_families:ViscousOnly\n")
    here = Path(__file__).resolve().parent
    path = os.pathsep.join([str(site), str(here), str(here.parent), os.environ.get("PYTHONPATH", "")])
    out = tmp_path / "p.json"
    res = subprocess.run([sys.executable, "-m", "wbfriction", "fit", str(table), "--model", TOY, "--terms", "none",
                          "-o", str(out)], capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=path))
    assert res.returncode == 0, res.stderr
    entry = read_fit(out)
    assert entry["model"] == TOY and abs(entry["params"]["F_v"] - TRUTH.F_v) < 4 * entry["stderr"]["F_v"]


# every family's properties

NAMES = (*BUILTIN_NAMES, TOY)
RANGES = {"F_v": (0.05, 2.0), "F_c": (0.1, 2.0), "F_s": (0.1, 3.0), "S": (0.0, 3.0), "v_s": (0.05, 1.0),
          "tau_os": (-1.0, 1.0), "a": (2.0, 100.0)}
"""Where each parameter is drawn (within every built-in family's bounds)."""


def family_of(name: str) -> FrictionFamily:
    """The family ``name`` (the toy's class, unregistered)."""
    return ViscousOnly() if name == TOY else family(name)


def draw(fam: FrictionFamily, unit: list[float]) -> np.ndarray:
    """Parameters of ``fam`` from ``unit`` (numbers in [0, 1], one per parameter) over :data:`RANGES`."""
    return np.array([RANGES[n][0] + u * (RANGES[n][1] - RANGES[n][0]) for n, u in zip(fam.names, unit)])


units = st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6)
speeds = st.lists(st.floats(-2.0, 2.0), min_size=5, max_size=40).map(np.array)


def numeric_jacobian(fn, x: np.ndarray) -> np.ndarray:
    """Central differences of ``fn`` (P,) -> (N,) at ``x``."""
    columns = []
    for i in range(x.size):
        h = 1e-6 * max(1.0, abs(x[i]))
        up, down = x.copy(), x.copy()
        up[i] += h
        down[i] -= h
        columns.append((fn(up) - fn(down)) / (2 * h))
    return np.column_stack(columns)


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=25, deadline=None)
@given(unit=units, qd=speeds, delta_s=st.sampled_from([2.0, 1.5]))
def test_every_familys_jacobian_is_its_finite_differences(name, unit, qd, delta_s):
    fam = family_of(name)
    x = draw(fam, unit)
    J = fam.jacobian(x, qd, delta_s)
    assert J.shape == (qd.size, x.size)
    np.testing.assert_allclose(J, numeric_jacobian(lambda p: fam.values(p, qd, delta_s), x), rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(fam.values(x, qd, delta_s), fam.params(x, delta_s).f(qd))


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=15, deadline=None)
@given(unit=units, qd=speeds, sigma=st.floats(0.005, 0.1), delta_s=st.sampled_from([2.0, 1.5]))
def test_every_familys_expectation_has_its_jacobian(name, unit, qd, sigma, delta_s):
    """Under a velocity noise: the analytic Jacobian (``delta_s = 2``) or its own central differences (another
    exponent, looser) against central differences of the expectation."""
    fam = family_of(name)
    x = draw(fam, unit)
    numeric = numeric_jacobian(lambda p: fam.expected_values(p, qd, sigma, delta_s), x)
    tol = 1e-5 if delta_s == 2.0 else 1e-3
    np.testing.assert_allclose(fam.expected_jacobian(x, qd, sigma, delta_s), numeric, rtol=tol, atol=tol)


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=25, deadline=None)
@given(unit=units, qd=speeds, sigma=st.sampled_from([0.0, 0.02]), delta_s=st.sampled_from([2.0, 1.5]))
def test_every_familys_fit_coordinates_round_trip_and_its_columns_sum_to_it(name, unit, qd, sigma, delta_s):
    """``from_fit(to_fit(x)) = x``; the Jacobian in the fit's coordinates is the chain rule's (central differences
    through ``from_fit``); the design columns times their factors' products are the characteristic (its expectation
    under the noise ``sigma``)."""
    fam = family_of(name)
    x = draw(fam, unit)
    z = fam.to_fit(x)
    np.testing.assert_allclose(fam.from_fit(z), x, rtol=1e-14, atol=1e-15)
    chain = fam.fit_jacobian(fam.jacobian(x, qd, delta_s))
    numeric = numeric_jacobian(lambda p: fam.values(fam.from_fit(p), qd, delta_s), z)
    np.testing.assert_allclose(chain, numeric, rtol=1e-5, atol=1e-6)
    products = np.array([np.prod(z[list(f)]) for f in factor_positions(fam)])
    np.testing.assert_allclose(fam.expected_columns(qd, sigma, delta_s, z) @ products,
                               fam.expected_values(x, qd, sigma, delta_s), rtol=1e-9, atol=1e-9)
    lower, upper = fam.bounds(qd if qd.any() else np.ones(1))
    assert lower.shape == upper.shape == x.shape and np.all(lower <= upper)
