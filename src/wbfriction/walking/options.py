"""The choices a user makes about a walk (thesis 6.2.2), in a module that imports nothing heavy: the command
line shows their defaults in its help without loading NumPy or Pinocchio."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

from wbfriction.choices import check_choice
from wbfriction.exceptions import InputError

Gait = Literal["forward", "sideways", "turning", "both", "combined"]
"""A walk of the footstep planner (:class:`GaitOptions`)."""
GAITS: tuple[Gait, ...] = get_args(Gait)


@dataclass(frozen=True)
class GaitOptions:
    """Parameters of a walk (defaults: thesis 6.2.2, TALOS-sized lift height).

    Attributes:
        gait: one of :data:`GAITS`.
        steps: number of steps (per direction for ``both``).
        step_length: forward distance between consecutive footprints [m].
        step_width: lateral displacement of each sideways step [m] (> 0: to the left).
        turn_length: distance between consecutive footprints when turning [m].
        turn_angle: change of heading per turning step [rad] (> 0: to the left).
        single_support: swing duration [s].
        double_support: double-support duration between steps [s].
        initial: double support before the first step [s].
        final: double support after the last step [s].
        lift_height: apex of the swing foot above the ground [m].
        com_height: height of the centre of mass above the ground [m]; None: the
            reference posture's, lowered by ``com_lowering``.
        com_lowering: lowering of the centre of mass from the reference posture [m].
        pc_amplitude: amplitude of a slow sine on the position-controlled joints [rad].
    """

    gait: Gait = "forward"
    steps: int = 10
    step_length: float = 0.3
    step_width: float = 0.25
    turn_length: float = 0.15
    turn_angle: float = 0.35
    single_support: float = 0.8
    double_support: float = 0.2
    initial: float = 1.0
    final: float = 1.0
    lift_height: float = 0.05
    com_height: float | None = None
    com_lowering: float = 0.04
    pc_amplitude: float = 0.2

    def __post_init__(self) -> None:
        check_choice("gait", self.gait, GAITS)
        if self.steps < 1:
            raise InputError(f"steps must be at least 1, got {self.steps}")
        for name in ("single_support", "double_support", "initial", "final"):
            if getattr(self, name) <= 0:
                raise InputError(f"{name} must be positive, got {getattr(self, name)}")
