"""A toy contact model, one file: a point foot whose constraint is written in the contact frame's own axes (three
LOCAL linear rows) rather than the world's, with no foot radius: the same constraint as the built-in ``point``
with ``foot_radius = 0``, its force in another basis."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.model.contacts import ContactFrames, ContactModel

NAME = "local-point"
"""The toy's name, as a robot TOML's ``contact_model`` gives it."""


class LocalPoint(ContactModel):
    """Three constraints, the frame's origin does not move, written in the frame's own axes: its force is in them too
    (the foot sensors' world-axes columns are not read); no single one fixes the base."""

    name = NAME
    what = "a point in the frame's own axes (three constraints: its origin does not move)"
    plural = "local points"
    dims = 3

    def jacobian(self, robot: ContactFrames, data: pin.Data, frame_id: int) -> np.ndarray:
        return pin.getFrameJacobian(robot.model, data, frame_id, pin.LOCAL)[:3]
