"""What a standing design shares (a biped on one foot, a quadruped on three): its options, the feet it needs, and its
figure (the swing joints' set-points within their bands and the shares of their Cramér-Rao bounds)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from wbfriction.exceptions import InputError
from wbfriction.excite.options import ARM_RATE, PD_EXCITE
from wbfriction.options import option

if TYPE_CHECKING:
    import pyarrow as pa

    from wbfriction.excite.design import ExciteOptions
    from wbfriction.model.robot import Robot

STANDING_DURATION, STANDING_PERIOD = 8.0, 4.0
"""A standing design's default time on one foot (or three) and its swing joints' Fourier period [s]
(:class:`~wbfriction.excite.one_foot.OneFootOptions`' and :class:`~wbfriction.excite.tripod.TripodOptions`' own)."""


@dataclass(frozen=True)
class StandingDesignOptions:
    """What ``excite`` reads of a robot standing on some feet while one leg swings: the recording [s] on them
    (``duration``), the set-points' rate [Hz], the swing joints' Fourier period [s], the seed of the design's
    starts."""

    duration: float = option(STANDING_DURATION, quantity="duration")
    rate: float = option(ARM_RATE, quantity="rate")
    period: float = option(STANDING_PERIOD, quantity="period")
    seed: int = option(PD_EXCITE.seed, quantity="seed")

    def excite(self, harmonics: int) -> ExciteOptions:
        """Each swing joint's design: these, ``harmonics`` per joint, the whole range (its band is the design's)."""
        from wbfriction.excite.design import ExciteOptions

        return ExciteOptions(duration=self.duration, rate=self.rate, period=self.period, harmonics=harmonics,
                             range_share=1.0, seed=self.seed)


def require_feet(robot: Robot, feet: int, what: str, model: str | None = None) -> None:
    """Refuse a robot not on ``feet`` contacts, or (``model``: a contact model's name, ``"point"``) one whose
    contacts are not all of that model (``what``: the stance the design makes): the contact model is asked, not the
    feet counted (issue 81: four feet of any model that does not fix the base were taken for a quadruped's).

    Raises:
        InputError: naming the robot, its contacts (the first of another model, and what it is) and the stance.
    """
    if len(robot.contact_frames) != feet:
        raise InputError(f"robot '{robot.name}' has a floating base on {len(robot.contact_frames)} "
                         f"{robot.stands_on}: excite designs {what}")
    other = next(((f, m) for f, m in zip(robot.contact_frames, robot.contact_models) if m.name != model), None)
    if model is not None and other is not None:
        frame, kind = other
        raise InputError(f"robot '{robot.name}' stands on contact model '{kind.name}' at '{frame}' ({kind.what}), "
                         f"not '{model}': excite designs {what}")


def standing_figure(robot: Robot, excitation: Any, table: pa.Table, doc: dict, title: str) -> Callable[[Path], None]:
    """What writes the figure of a standing design's set-points ``table`` (its swing joints', the encoders'
    coordinates) within their bands, with the shares of their bounds from ``doc``, titled ``title``."""

    def figure(path: Path) -> None:
        import numpy as np

        from wbfriction.report.excite import excite_figure

        joints = excitation.joints
        offset = robot.offset_vector[[robot.actuated.index(j) for j in joints]]
        q_des = np.column_stack([table.column(f"q_des.{j}").to_numpy() for j in joints])
        excite_figure(path, joints, table.column("time").to_numpy(), q_des, excitation.lower + offset,
                      excitation.upper + offset, {j: s["share"] for j, s in doc["swing"].items()}, title)

    return figure
