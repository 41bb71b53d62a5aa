"""The identification document's bodies: which written bodies are no plausible link (issue 40)."""

from __future__ import annotations

import pytest

from wbfriction.inertia.document import COLLAPSED, MASS_CHANGE, BodyWritten


def body(mass_change: float | None = 0.0, moments_change: tuple[float | None, ...] = (0.0, 0.0, 0.0)) -> BodyWritten:
    return BodyWritten("j", 2.0, 2.0 * (1 + (mass_change or 0.0)), mass_change, 0.01, (0.01, 0.02, 0.02),
                       (0.01, 0.02, 0.02), moments_change)


@pytest.mark.parametrize(("mass_change", "moments", "expected"), [
    (0.0, (0.0, 0.0, 0.0), ""),
    (0.3, (-0.5, 0.2, None), ""),  # changes, but a link still
    (0.0, (-1.0, -0.2, -0.95), "principal moments collapsed (I1 -100 %, I3 -95 %)"),  # the KUKA's lwr_1..lwr_6
    (-0.6, (0.0, 0.0, 0.0), "mass -60 %"),
    (None, (-0.91, 0.0, 0.0), "principal moments collapsed (I1 -91 %)"),
])
def test_a_body_that_collapsed_or_lost_its_mass_is_implausible(mass_change, moments, expected):
    assert body(mass_change, moments).implausible() == expected


def test_the_thresholds_are_the_stated_ones():
    assert body(0.0, (-COLLAPSED + 1e-9, 0.0, 0.0)).implausible() == ""
    assert body(0.0, (-COLLAPSED - 1e-9, 0.0, 0.0)).implausible() != ""
    assert body(MASS_CHANGE - 1e-9).implausible() == "" and body(MASS_CHANGE + 1e-9).implausible() != ""
