"""Human labels of joints ("right knee" for ``leg_right_4_joint``): the ``[labels]`` table of a robot TOML.

What a person reads in the report and the tables; the joint names stay the keys everywhere else.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from wbfriction.exceptions import InputError


def default_label(joint: str) -> str:
    """A joint's label when the robot TOML gives none: its name without a ``_joint`` suffix, underscores as
    spaces (``left_knee`` -> "left knee")."""
    name = joint[: -len("_joint")] if joint.endswith("_joint") else joint
    return name.replace("_", " ").strip() or joint


def parse_labels(value: object, joints: Sequence[str], source: str) -> dict[str, str]:
    """The label of every joint of ``joints``: ``value`` (the TOML's ``[labels]``, joint name -> text) over
    :func:`default_label`.

    Raises:
        InputError: ``[labels]`` not a table, a joint not in ``joints``, a label not a non-empty string, or
            two joints with the same label.
    """
    given: Mapping = {} if value is None else value  # type: ignore[assignment]
    if not isinstance(given, Mapping):
        raise InputError(f"{source}: [labels] must be a table of joint = \"label\"")
    for joint, text in given.items():
        if joint not in joints:
            raise InputError(f"{source}: [labels] names {joint!r}, which is not a joint of the model")
        if not isinstance(text, str) or not text.strip():
            raise InputError(f"{source}: [labels] {joint} must be a non-empty string")
    labels = {j: str(given[j]).strip() if j in given else default_label(j) for j in joints}
    seen: dict[str, str] = {}
    for joint, text in labels.items():
        if text in seen:
            raise InputError(f"{source}: [labels] gives {seen[text]!r} and {joint!r} the same label {text!r}")
        seen[text] = joint
    return labels
