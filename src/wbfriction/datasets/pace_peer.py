"""A PD-driven robot's peer identification by the iit-DLSLab (PACE), read as data, and written as a robot-TOML fragment.

The iit-DLSLab identified their hung quadrupeds (:mod:`~wbfriction.datasets.hung_quadruped`: the Aliengo, the Go2)
with PACE (Bjelonic et al. 2025, https://github.com/leggedrobotics/pace-sim2real: CMA-ES over Isaac Lab rollouts of
the whole log) and published the result as ``robot_model/<robot>/isaaclab_identified_parameters.py`` in
https://github.com/iit-DLSLab/simple-robot-identification-isaaclab: Python source of ``name = [...]`` lists, one
value per joint (armature, viscous friction, a Coulomb friction, encoder bias) and scalars (``delay``, ``Kp``,
``Kd``). :func:`read_peer` reads it without executing it (:func:`ast.literal_eval`); :func:`peer_config` writes it
as the tables of a robot TOML (``peer.toml``, beside the dataset's logs); :class:`PeerActuator` holds it.

The files name their Coulomb friction after the Isaac Lab attribute it set: ``static_friction`` (the Aliengo's) or
``dynamic_friction`` (the Go2's). PACE searches one friction value per joint (``bounds_params[24:36]`` of
``sysid_isaaclab/tasks/{aliengo,go2}_pace_env_cfg.py``, "friction between 0.0 - 1.0") and its actuator
configuration notes "modeling coulomb friction if friction = dynamic_friction": either name is the same Coulomb
level, :attr:`PeerActuator.coulomb_friction`.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

from wbfriction.datasets.store import RemoteFile
from wbfriction.exceptions import InputError

PEER_STEP = 0.005
"""The peer's simulation step [s]: ``sim.dt = 0.005`` with ``decimation = 1`` (its
``sysid_isaaclab/tasks/aliengo_pace_env_cfg.py`` and ``go2_pace_env_cfg.py``, lines 150-151): one physics step = one
control step = one log sample (``my_fit.py`` steps the simulation once per sample); its delay counts these steps."""

FRICTION_KEYS = ("static_friction", "dynamic_friction")
"""The names a peer's file may give its Coulomb friction (module docstring); it must give exactly one."""


@dataclass(frozen=True)
class PeerActuator:
    """The iit-DLSLab identification of a hung PD-driven robot (PACE: CMA-ES over Isaac Lab rollouts of the log),
    as its file gives it, per joint name (the log's joints,
    :data:`~wbfriction.datasets.hung_quadruped.QUADRUPED_JOINTS`).

    Attributes:
        armature: reflected rotor inertia [kg·m²] (Isaac Lab's joint armature: added to the mass matrix's diagonal,
            as ``[armature]``).
        viscous_friction: [N·m·s/rad] (Isaac Lab's ``viscous_friction``).
        coulomb_friction: [N·m] (Isaac Lab's joint ``friction``, which their assets set equal to
            ``dynamic_friction``: a Coulomb friction; the file's ``static_friction`` or ``dynamic_friction``,
            :data:`FRICTION_KEYS`).
        bias: the peer's encoder bias [rad], in its sign convention: the simulated (model's) angle minus the
            logged one, ``q_logged = q_model - bias``. In PACE (leggedrobotics/pace-sim2real at f8ec8b8,
            ``source/pace_sim2real/pace_sim2real/``; the same in every version from 2025-11-21 on) the driver's PD
            runs on ``joint_pos - self.encoder_bias`` (``utils/pace_actuator.py`` line 64: the bias is subtracted
            from the simulated joint position to give the encoder's reading, not added to the set-point), the score
            is ``sim_dof_pos - real_dof_pos - bias`` (``optim/cma_es.py`` line 73) and a rollout starts at
            ``initial_position + bias`` (line 119). The lab's own deployed actuator reads it the same way
            (iit-DLSLab/basic-locomotion-isaaclab, ``actuators/pace_actuator.py``: ``joint_pos -
            self.encoder_bias``). wbfriction's offset is therefore ``-bias`` (:attr:`encoder_offset`). The search
            was bounded to ±0.1 rad (``sysid_isaaclab/tasks/<robot>_pace_env_cfg.py`` lines 129-130).
        delay_steps: the peer's delay as published [steps of :data:`PEER_STEP`: physics steps, which with
            ``decimation = 1`` are also its control steps and the log's samples]. PACE delays the PD's torque
            output (``pace_actuator.py`` line 65, Isaac Lab's ``DelayBuffer``, one entry a physics step: the
            feedback as well as the set-point) by ``int(delay)`` steps (``cma_es.py`` line 129, ``.to(torch.int)``:
            truncated, so any value in [2, 3) simulates the same 2 steps).
        kp, kd: the gains it was identified with [N·m/rad, N·m·s/rad].
        friction_key: the name the file gave :attr:`coulomb_friction` (one of :data:`FRICTION_KEYS`).
    """

    armature: dict[str, float]
    viscous_friction: dict[str, float]
    coulomb_friction: dict[str, float]
    bias: dict[str, float]
    delay_steps: float
    kp: float
    kd: float
    friction_key: str = "static_friction"

    @property
    def static_friction(self) -> dict[str, float]:
        """:attr:`coulomb_friction` under the Aliengo file's name [N·m]."""
        return self.coulomb_friction

    @property
    def encoder_offset(self) -> dict[str, float]:
        """wbfriction's encoder offset [rad] (the logged angle minus the model's, ``[encoder_offset]``):
        ``-bias``."""
        return {j: -b for j, b in self.bias.items()}

    @property
    def delay(self) -> float:
        """The published delay in seconds: ``delay_steps`` × :data:`PEER_STEP` [s]."""
        return self.delay_steps * PEER_STEP

    @property
    def applied_delay_steps(self) -> int:
        """The steps its simulation delayed the torque by: ``int(delay_steps)`` (PACE truncates)."""
        return int(self.delay_steps)

    @property
    def applied_delay(self) -> float:
        """:attr:`applied_delay_steps` × :data:`PEER_STEP` [s]."""
        return self.applied_delay_steps * PEER_STEP


_PEER_LISTS = ("armature", "viscous_friction", "bias")
"""The per-joint lists every peer's file holds under these names (the Coulomb friction: :data:`FRICTION_KEYS`)."""


def read_peer(path: str | Path, joints: tuple[str, ...]) -> PeerActuator:
    """A peer's ``isaaclab_identified_parameters.py``: Python source of ``name = [...]`` lists (one value per joint,
    in the joint order its ``# Order:`` comment gives, else ``joints``' order) and scalars (``delay``, ``Kp``,
    ``Kd``). Each assignment's value is read with :func:`ast.literal_eval`; nothing is executed.

    Args:
        path: the file.
        joints: the log's joints (URDF names, ``<name>_joint``); the file's ``# Order:`` names them without
            ``_joint``.

    Raises:
        InputError: a file that does not parse as Python, a statement that is not ``name = literal``, a value
            missing, not a number or of another length, both or neither of :data:`FRICTION_KEYS`, an order naming
            other joints, naming the file and key.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        tree = ast.parse(text, filename=str(path))
    except SyntaxError as exc:
        raise InputError(f"{path}: not Python source (line {exc.lineno}: {exc.msg})") from None
    values: dict[str, object] = {}
    for node in tree.body:
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)):
            raise InputError(f"{path}: line {node.lineno} is not 'name = value'")
        try:
            values[node.targets[0].id] = ast.literal_eval(node.value)
        except ValueError:
            raise InputError(f"{path}: line {node.lineno}: {node.targets[0].id} is not a literal") from None
    order = _peer_order(path, text, joints)
    friction = [key for key in FRICTION_KEYS if key in values]
    if len(friction) != 1:
        raise InputError(f"{path}: needs one Coulomb friction list, '{FRICTION_KEYS[0]}' or '{FRICTION_KEYS[1]}'; "
                         f"found {' and '.join(repr(k) for k in friction) or 'neither'}")

    def number(key: str) -> float:
        v = values.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(f"{path}: '{key}' must be a number, got {v!r}")
        return float(v)

    def per_joint(key: str) -> dict[str, float]:
        v = values.get(key)
        if not isinstance(v, list) or len(v) != len(order) or any(isinstance(x, bool) or not isinstance(
                x, (int, float)) for x in v):
            raise InputError(f"{path}: '{key}' must be a list of {len(order)} numbers")
        return {j: float(x) for j, x in zip(order, v)}

    lists = {key: per_joint(key) for key in _PEER_LISTS}
    return PeerActuator(**lists, coulomb_friction=per_joint(friction[0]), delay_steps=number("delay"),
                        kp=number("Kp"), kd=number("Kd"), friction_key=friction[0])


def _peer_order(path: Path, text: str, joints: tuple[str, ...]) -> tuple[str, ...]:
    found = re.search(r"^#\s*Order:\s*(.+)$", text, re.M)
    if found is None:
        return joints
    order = tuple(f"{name.strip()}_joint" for name in found.group(1).split(","))
    if sorted(order) != sorted(joints):
        raise InputError(f"{path}: its '# Order:' names {', '.join(order)}, not the log's {len(joints)} joints "
                         f"({', '.join(joints)})")
    return order


def peer_config(peer: PeerActuator, robot: str, config: str, source: RemoteFile) -> str:
    """The peer's identification as a robot-TOML fragment: ``[armature]``, ``[encoder_offset]`` (``-bias``) and a
    ``[pd]`` with its gains and the delay its simulation applied (:attr:`PeerActuator.applied_delay`), to the whole
    torque (``delayed = "torque"``, as PACE's actuator holds it); its friction in comments.

    Args:
        peer: the identification.
        robot: the robot as the header names it (``"Aliengo"``).
        config: the robot TOML whose tables it replaces (``"aliengo.toml"``).
        source: the peer's file (its repository, commit and path go in the header).
    """
    lines = [f"# The iit-DLSLab identification of this {robot} (PACE: CMA-ES over Isaac Lab rollouts), as a robot-TOML",
             f"# fragment: its tables replace {config}'s. From {source.repository} at {source.commit[:7]},",
             f"# {source.path}. A peer's result, not ground truth.",
             "[armature]   # [kg·m²]"]
    lines += [f"{j} = {v!r}" for j, v in peer.armature.items()]
    lines += ["", "# The logged angle minus the model's [rad]: their 'bias' with its sign changed (PACE's encoder",
              "# reads the simulated angle minus the bias)."]
    lines += ["[encoder_offset]"] + [f"{j} = {v!r}" for j, v in peer.encoder_offset.items()]
    lines += ["", f"# Their delay: {peer.delay_steps!r} steps of {PEER_STEP} s ({peer.delay:.5f} s), which PACE",
              f"# truncates to {peer.applied_delay_steps} steps and applies to the PD's torque (set-point and feedback "
              "alike): [pd] delayed = \"torque\" (wbfriction.model.pd).",
              "[pd]", f"kp = {peer.kp!r}", f"kd = {peer.kd!r}", f"delay = {peer.applied_delay!r}   # [s]",
              'delayed = "torque"', "",
              "# Their friction (not a robot-TOML table; PeerActuator holds it), per joint: viscous [N·m·s/rad],",
              f"# {peer.friction_key.removesuffix('_friction')} (Coulomb) [N·m]:"]
    lines += [f"#   {j}: {peer.viscous_friction[j]!r}, {peer.coulomb_friction[j]!r}" for j in peer.armature]
    return "\n".join(lines) + "\n"
