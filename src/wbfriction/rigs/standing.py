"""The figure of a standing design (a biped on one foot, a quadruped on three): the swing joints' set-points within
their bands and the shares of their Cramér-Rao bounds."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pyarrow as pa

    from wbfriction.model.robot import Robot


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
