"""Where a log's torques come from: the torque sources the package knows, in a registry new ones join with one call,
and the one a log's columns choose (:attr:`Log.torque_source <wbfriction.logs.log.Log.torque_source>`, said the same
way in every output: :func:`torque_record`).

Four are built in, tried in this order, one source for every joint, the first that a log's columns choose: joint
torque sensors (``tau.<joint>``), the drivers' own estimates (``tau_est.<joint>``), motor currents times the torque
constants (``current.<joint>``, the robot TOML's ``[torque_constants]``), the drivers' PD law on the set-points
(``q_des.<joint>``, :mod:`wbfriction.logs.pd`). Another is one call away::

    from wbfriction.logs import TorqueKind, register_torque_source

    class Effort(TorqueKind):
        name, what, prefix, precedence = "effort", "the drives' effort in mN·m (effort.<joint>)", "effort", 25
        def torque(self, given):
            return 1e-3 * given.columns("effort")

    register_torque_source(Effort())

after which every log whose columns it claims (by default: ``effort.<joint>`` of every torque-controlled joint) has
its torque from it, in every function and command that reads a log.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError
from wbfriction.logs.pd import PdSetpoints, driver_estimate, pd_columns_named, pd_law_torque, setpoint_columns
from wbfriction.logs.tables import numeric_columns
from wbfriction.model.robot import Robot
from wbfriction.registry import Registry

TorqueSource = str
"""Where a log's torques come from: the name of a registered :class:`TorqueKind` (``"sensor"``, ``"driver"``,
``"current"``, ``"pd"`` built in; :attr:`Log.torque_source <wbfriction.logs.log.Log.torque_source>`)."""


@dataclass(frozen=True, eq=False)
class TorqueColumns:
    """What a torque source reads a log's torque from: its table, its robot, where its rows start and what the
    messages name it (``source``, ``first_row``), its times ``time`` (N,) [s], its logged angles ``q`` (N, n_act)
    [rad] (the encoder's) and its PD set-points (None: none logged)."""

    table: pa.Table
    robot: Robot
    source: str
    first_row: int
    time: np.ndarray
    q: np.ndarray
    setpoints: PdSetpoints | None

    @property
    def names(self) -> set[str]:
        """The table's column names."""
        return set(self.table.column_names)

    def has(self, prefix: str) -> list[bool]:
        """Whether each torque-controlled joint has a ``<prefix>.<joint>`` column, in :attr:`Robot.torque_controlled`
        order."""
        names = self.names
        return [f"{prefix}.{n}" in names for n in self.robot.torque_controlled]

    def columns(self, prefix: str) -> np.ndarray:
        """The ``<prefix>.<joint>`` columns of the torque-controlled joints (N, n_tc), read as numbers.

        Raises:
            ColumnError: a column missing or not numbers, naming it.
        """
        cols = [f"{prefix}.{n}" for n in self.robot.torque_controlled]
        return numeric_columns(self.table, cols, self.source, self.first_row)


class TorqueKind:
    """A torque source: where a log's torque of the torque-controlled joints comes from.

    A subclass names itself (:attr:`name`, the string every output's metadata records; :attr:`what`, what the text
    outputs print), says which columns make a log its own (:attr:`prefix`, and where the default does not say it,
    :meth:`claims`), its place among the sources (:attr:`precedence`: the lowest that claims a log wins) and reads the
    torque (:meth:`torque`). What it does not define has a default built on :attr:`prefix`: the columns the schema
    checks (:meth:`named`), the schema's check of one joint (:meth:`gives`), the log written back (:meth:`columns`).
    """

    name: ClassVar[str]
    """The source's name, recorded in every output's metadata (``torque_source.source``)."""
    what: ClassVar[str]
    """What the source is, as the outputs say it (``torque_source.what``)."""
    prefix: ClassVar[str]
    """The prefix of its columns, one per torque-controlled joint (``<prefix>.<joint>``)."""
    precedence: ClassVar[float]
    """Its place among the sources: the one of lowest precedence that claims a log is its source."""
    alignment: ClassVar[str | None] = None
    """What each sample's torque stands for, where not the instant's: ``"sample"``, its period's mean (the PD law's:
    :mod:`wbfriction.model.pd`); recorded as the log's ``torque_alignment`` metadata unless the log says it."""
    printed: ClassVar[bool] = True
    """Whether the text outputs say where the torque comes from (not for the default, the torque sensors)."""
    pd_law: ClassVar[bool] = False
    """Whether its torque is the drivers' PD law on the set-points (what the actuator identification needs)."""
    motor_side: ClassVar[bool] = False
    """Whether its torque is the motor's, read from its current (the drivers' estimates, the currents times the torque
    constants): the rotor's inertia torque (armature x qdd) is in it, which the model holds only through the robot
    TOML's ``[armature]`` (:func:`rotor_inertia_warnings`)."""

    def claims(self, given: TorqueColumns) -> bool:
        """Whether a log is this source's: by default, it has ``<prefix>.<joint>`` for every torque-controlled
        joint."""
        return all(given.has(self.prefix))

    def torque(self, given: TorqueColumns) -> np.ndarray:
        """The torque of the torque-controlled joints (N, n_tc) [N·m] of a log it claims; by default its
        ``<prefix>.<joint>`` columns as they are.

        Raises:
            ColumnError: a column missing or not numbers, naming it.
        """
        return given.columns(self.prefix)

    def named(self, robot: Robot) -> dict[str, set[str] | None]:
        """The prefixes of the columns this source reads, each to the names its ``<prefix>.<name>`` columns may give
        (None: any, refused where they are read, with the reason): what the log's schema checks before a row is read
        (:func:`~wbfriction.logs.log.check_schema`: a column of another name is refused, naming it; every such column
        must hold numbers). By default ``{prefix: the robot's actuated joints}`` (a column of a joint that is not
        torque-controlled is allowed and not read, as ``tau.<joint>``)."""
        return {self.prefix: set(robot.actuated)}

    def gives(self, robot: Robot, joint: str, seen: set[str]) -> bool:
        """Whether a log with the columns ``seen`` has ``joint``'s torque from this source (the schema's check, before
        a row is read); by default, it has ``<prefix>.<joint>``."""
        return f"{self.prefix}.{joint}" in seen

    def refuse(self, robot: Robot, joint: str, seen: set[str], source: str) -> None:
        """Raise what is wrong with ``joint``'s columns that no source :meth:`gives` its torque from, where it is
        this source's to say (by default nothing).

        Raises:
            ColumnError: this source's column of ``joint`` without what it needs.
        """

    def hint(self, joint: str) -> str | None:
        """What the message for a joint without a torque names as this source's alternative (None: nothing)."""
        return f"'{self.prefix}.{joint}'"

    def columns(self, tau: np.ndarray, robot: Robot, setpoints: PdSetpoints | None) -> dict[str, np.ndarray]:
        """The columns a log of this source is written as, from its torque ``tau`` (N, n_tc) [N·m]: by default
        ``<prefix>.<joint>`` as they are."""
        return {f"{self.prefix}.{n}": tau[:, i] for i, n in enumerate(robot.torque_controlled)}

    def record(self, robot: Robot, setpoints: PdSetpoints | None) -> dict[str, object]:
        """What every output's metadata says of the source beyond its name and :attr:`what`: for a measured torque of
        a log that also holds set-points, ``setpoints`` "not used" (the measured torque is taken, the PD law is
        not)."""
        return {} if setpoints is None else {"setpoints": "not used"}

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


ENTRY_POINT_GROUP = "wbfriction.torque_sources"
"""The entry-point group under which an installed package advertises its torque sources: each entry's name is the
source's and its object a :class:`TorqueKind` (an instance, or a class called without arguments)."""

SOURCES: Registry[TorqueKind] = Registry("torque source", precedence=lambda k: k.precedence,
                                         entry_points=ENTRY_POINT_GROUP)
"""The registered torque sources, in precedence order: the built-in ones, those registered, those installed packages
advertise (read, and each loaded, the first time a log's source is chosen, since one may come first; one that does
not load is left out with one :class:`~wbfriction.registry.PluginWarning` line, the others used)."""


register_torque_source = SOURCES.register
"""Add a torque source (a :class:`TorqueKind`) to those every log is asked of, at its
:attr:`~TorqueKind.precedence`; returns it (:meth:`Registry.register <wbfriction.registry.Registry.register>`:
ValueError for a name, or a precedence, registered already, naming it)."""
unregister_torque_source = SOURCES.unregister
"""Remove the torque source of a name; returns it (ValueError: none of that name)."""
torque_sources = SOURCES.kinds
"""The registered torque sources, in precedence order."""


def torque_kind(name: TorqueSource) -> TorqueKind:
    """The registered torque source named ``name``.

    Raises:
        ValueError: no source of that name.
    """
    return SOURCES.get(name)


def torque_source_of(given: TorqueColumns) -> TorqueKind:
    """The source of a log's torque: the registered one of lowest precedence that :meth:`~TorqueKind.claims` it.

    Raises:
        ColumnError: none claims it, naming the first torque-controlled joint's ``tau`` column.
    """
    found = next((k for k in SOURCES if k.claims(given)), None)
    if found is None:
        n = given.robot.torque_controlled[0]
        raise ColumnError(given.source, f"tau.{n}", None, f"missing column 'tau.{n}': no torque source "
                          f"({SOURCES.listed()}) has the torque of every torque-controlled joint")
    return found


def torque_columns_named(robot: Robot) -> dict[str, set[str] | None]:
    """The column prefixes every registered torque source reads (:meth:`TorqueKind.named`), each to the names its
    columns may give (None: any, refused where read); a prefix two sources read gives the names of either (None if
    either says any)."""
    named: dict[str, set[str] | None] = {}
    for kind in SOURCES.kinds():
        for prefix, names in kind.named(robot).items():
            if prefix not in named:
                named[prefix] = None if names is None else set(names)
            else:
                held = named[prefix]
                named[prefix] = None if held is None or names is None else held | names
    return named


def rotor_inertia_warnings(robot: Robot, seen: set[str], source: str) -> tuple[str, ...]:
    """One line when a log whose columns are ``seen`` has its torques from the motors' currents
    (:attr:`TorqueKind.motor_side`: the first registered source that gives every torque-controlled joint's) and the
    robot's model has no rotor inertia (``[armature]``, ``model.armature``) for some torque-controlled joint: the
    rotor's inertia torque (armature x qdd) is then in what is estimated, nothing refused; () otherwise. Said before
    any row is read (:func:`~wbfriction.logs.log.check_schema`)."""
    tc = robot.torque_controlled
    kind = next((k for k in SOURCES if all(k.gives(robot, j, seen) for j in tc)), None)
    if kind is None or not kind.motor_side:
        return ()
    armature = robot.model.armature[robot.act_v_index[robot.tc_index]]
    bare = [j for j, a in zip(tc, armature) if not a > 0]
    if not bare:
        return ()
    shown = ", ".join(bare[:3]) + (f" and {len(bare) - 3} more" if len(bare) > 3 else "")
    return (f"{source}: the torques are {kind.what}: each motor's rotor inertia torque (armature x qdd) is in them, "
            f"and robot '{robot.name}' gives no [armature] for {len(bare)} of its {len(tc)} torque-controlled joints "
            f"({shown}): it stays in the friction estimated; give [armature] in its TOML (or find it: wbfriction "
            "identify --armature identify)",)


def check_torque_columns(robot: Robot, seen: set[str], source: str) -> None:
    """Every torque-controlled joint has a torque from some registered source (:meth:`TorqueKind.gives`: ``tau``,
    ``tau_est``, ``current`` with a torque constant, ``q_des`` of a PD-driven joint built in), checked on a log's
    column names ``seen`` alone.

    Raises:
        ColumnError: a joint without, naming what its columns lack (:meth:`TorqueKind.refuse`), else its ``tau``
            column and the alternatives (:meth:`TorqueKind.hint`).
    """
    kinds = SOURCES.kinds()
    for n in robot.torque_controlled:
        if any(k.gives(robot, n, seen) for k in kinds):
            continue
        for k in kinds:
            k.refuse(robot, n, seen, source)
        hints = [h for k in kinds if k.name != "sensor" and (h := k.hint(n)) is not None]
        raise ColumnError(source, f"tau.{n}", None, f"missing column 'tau.{n}' (or {', or '.join(hints)})")


def torque_record(robot: Robot, source: TorqueSource, setpoints: PdSetpoints | None) -> dict[str, object]:
    """Where a log's torques come from, for every output's metadata: ``source`` (its name), ``what``
    (:attr:`TorqueKind.what`), and what the source adds (:meth:`TorqueKind.record`): for the PD law its delay [s],
    what the delay holds back (``delayed``: :mod:`wbfriction.model.pd`) and where its gains come from; where the log
    ``identify`` found the delay on did not tell what it holds back (:attr:`~wbfriction.model.pd.PdDriver.delayed_known`
    false), ``delayed_known`` false and per joint the viscous coefficient the two differ by (``viscous_equivalent``
    [N·m·s/rad], ``kp delay``), which the friction's F_v carries (:func:`~wbfriction.fit.joints.fit_estimate`); a log
    of measured torques that also holds set-points, ``setpoints`` "not used"; where the robot TOML states it, per
    joint the torque's relative scale error (``scale_sd``, :mod:`wbfriction.fit.torque_scale`), which F_c and F_v
    carry.

    Raises:
        ValueError: no source of that name registered.
    """
    kind = torque_kind(source)
    record = {"source": source, "what": kind.what, **kind.record(robot, setpoints)}
    scale_sd = {j: robot.torque_scale_sd[j] for j in robot.torque_controlled if j in robot.torque_scale_sd}
    return {**record, "scale_sd": scale_sd} if scale_sd else record


class SensorTorque(TorqueKind):
    """Link-side joint torque sensors, ``tau.<joint>`` [N·m] of every torque-controlled joint: only the friction
    after the sensor is in it."""

    name, what, prefix, precedence, printed = "sensor", "joint torque sensors (tau.<joint>)", "tau", 10, False

    def hint(self, joint: str) -> str | None:
        """None: the message names ``tau.<joint>`` itself."""
        return None


class DriverTorque(TorqueKind):
    """The motor drivers' own estimates, ``tau_est.<joint>`` [N·m] (from their currents): any such column makes a log
    this source's (:func:`~wbfriction.logs.pd.driver_estimate` refuses it for some joints only)."""

    name, what, prefix, precedence = "driver", "the motor drivers' own estimates (tau_est.<joint>)", "tau_est", 20
    motor_side = True

    def claims(self, given: TorqueColumns) -> bool:
        """Any ``tau_est`` column."""
        return any(given.has(self.prefix))

    def torque(self, given: TorqueColumns) -> np.ndarray:
        """``tau_est.<joint>`` (N, n_tc) [N·m].

        Raises:
            ColumnError: ``tau_est`` logged for some torque-controlled joints only.
        """
        estimated = driver_estimate(given.table, given.robot, given.source, given.first_row)
        assert estimated is not None  # claimed: some tau_est column
        return estimated

    def named(self, robot: Robot) -> dict[str, set[str] | None]:
        """``tau_est`` of the torque-controlled joints."""
        return {self.prefix: set(robot.torque_controlled)}

    def hint(self, joint: str) -> str | None:
        """None (the message does not name it)."""
        return None


class CurrentTorque(TorqueKind):
    """Motor currents ``current.<joint>`` [A] times the joints' torque constants [N·m/A] (the robot TOML's
    ``[torque_constants]``, :attr:`Robot.torque_constants <wbfriction.model.robot.Robot.torque_constants>`): any
    ``current`` column makes a log this source's, and so does a ``tau`` column of some joints only (refused)."""

    name, what, prefix, precedence = "current", "motor currents times the torque constants (current.<joint>)", \
        "current", 30
    motor_side = True

    def claims(self, given: TorqueColumns) -> bool:
        """Any ``current`` column, or ``tau`` of some joints only (not every one: the sensors'), which is refused."""
        return any(given.has(self.prefix)) or any(given.has("tau"))

    def torque(self, given: TorqueColumns) -> np.ndarray:
        """``current.<joint>`` times the joint's torque constant (N, n_tc) [N·m].

        Raises:
            ColumnError: ``tau`` columns of some joints (mixed with currents), a ``current`` column missing.
        """
        from_sensor = given.has("tau")
        if any(from_sensor):
            n = given.robot.torque_controlled[from_sensor.index(False)]
            raise ColumnError(given.source, f"tau.{n}", None, f"missing column 'tau.{n}': torques come from tau.* "
                              "columns for some joints and current.* for others; log one kind for every joint")
        k = np.array([given.robot.torque_constants[n] for n in given.robot.torque_controlled])
        return given.columns(self.prefix) * k

    def gives(self, robot: Robot, joint: str, seen: set[str]) -> bool:
        """``current.<joint>`` and the joint's torque constant."""
        return f"current.{joint}" in seen and joint in robot.torque_constants

    def refuse(self, robot: Robot, joint: str, seen: set[str], source: str) -> None:
        """A current without a torque constant.

        Raises:
            ColumnError: ``current.<joint>`` without the joint's torque constant.
        """
        if f"current.{joint}" in seen:
            raise ColumnError(source, f"current.{joint}", None, f"column 'current.{joint}' needs a torque constant: "
                              f"add '{joint}' [N·m/A] to the robot's [torque_constants]")

    def hint(self, joint: str) -> str | None:
        """``current.<joint>`` with a torque constant."""
        return f"'current.{joint}' with a torque constant for '{joint}' in the robot's [torque_constants]"

    def columns(self, tau: np.ndarray, robot: Robot, setpoints: PdSetpoints | None) -> dict[str, np.ndarray]:
        """``current.<joint>``: the torque divided by the joint's torque constant [A]."""
        return {f"current.{n}": tau[:, i] / robot.torque_constants[n] for i, n in enumerate(robot.torque_controlled)}


class PdLawTorque(TorqueKind):
    """The drivers' PD law on the set-points ``q_des.<joint>`` (:mod:`wbfriction.logs.pd`): a log with set-points and
    no ``tau`` (nor ``tau_est``, ``current``) column. Each sample's torque stands for its period's mean
    (:mod:`wbfriction.model.pd`)."""

    name, what, prefix, precedence = "pd", "the drivers' PD law on q_des.<joint>", "q_des", 40
    alignment, pd_law = "sample", True

    def claims(self, given: TorqueColumns) -> bool:
        """Set-points read and no ``tau`` column."""
        return given.setpoints is not None and not any(given.has("tau"))

    def torque(self, given: TorqueColumns) -> np.ndarray:
        """The PD law's torque (N, n_tc) [N·m] (:func:`~wbfriction.logs.pd.pd_law_torque`).

        Raises:
            ColumnError: a torque-controlled joint that is not PD-driven.
        """
        assert given.setpoints is not None  # claimed
        return pd_law_torque(given.robot, given.setpoints, given.time, given.q, given.source)

    def named(self, robot: Robot) -> dict[str, set[str] | None]:
        """The set-points' and gains' prefixes (``q_des``, ``qd_des``, ``tau_ff``, ``kp``, ``kd``) of the PD-driven
        joints (None without ``[pd]``: :func:`~wbfriction.logs.pd.read_setpoints` refuses them with the reason;
        :func:`~wbfriction.logs.pd.pd_columns_named`)."""
        return {p: names for p, names in pd_columns_named(robot).items() if p != DriverTorque.prefix}

    def gives(self, robot: Robot, joint: str, seen: set[str]) -> bool:
        """``q_des.<joint>`` of a PD-driven joint."""
        return robot.pd is not None and joint in robot.pd.joints and f"q_des.{joint}" in seen

    def refuse(self, robot: Robot, joint: str, seen: set[str], source: str) -> None:
        """A set-point of a joint the TOML gives no gains.

        Raises:
            ColumnError: ``q_des.<joint>`` (and no ``current``) of a joint not in ``[pd]``.
        """
        if f"q_des.{joint}" in seen and f"current.{joint}" not in seen:
            raise ColumnError(source, f"q_des.{joint}", None, f"column 'q_des.{joint}' is a PD set-point, but robot "
                              f"'{robot.name}' has no [pd] gains for '{joint}' in its TOML (kp, kd: "
                              "wbfriction.model.pd)")

    def hint(self, joint: str) -> str | None:
        """``q_des.<joint>`` with gains."""
        return f"'q_des.{joint}' with [pd] gains"

    def columns(self, tau: np.ndarray, robot: Robot, setpoints: PdSetpoints | None) -> dict[str, np.ndarray]:
        """The set-points' columns (:func:`~wbfriction.logs.pd.setpoint_columns`); without set-points, ``tau``."""
        if setpoints is not None and robot.pd is not None:
            return setpoint_columns(setpoints, robot.pd.joints)
        return {f"tau.{n}": tau[:, i] for i, n in enumerate(robot.torque_controlled)}

    def record(self, robot: Robot, setpoints: PdSetpoints | None) -> dict[str, object]:
        """The law's delay [s], what it holds back (``delayed``), where its gains come from (``gains``) and, where
        the delay's identification did not tell what it holds back, ``delayed_known`` false and per joint
        ``viscous_equivalent`` [N·m·s/rad]."""
        if robot.pd is None or setpoints is None:
            return {}
        logged = setpoints.kp is not None or setpoints.kd is not None
        record: dict[str, object] = {"delay": robot.pd.delay, "delayed": robot.pd.delayed,
                                     "gains": "kp/kd columns" if logged else "the robot's [pd]"}
        if not robot.pd.delayed_known:
            record |= {"delayed_known": False, "viscous_equivalent": robot.pd.viscous_equivalent()}
        return record


for _builtin in (SensorTorque(), DriverTorque(), CurrentTorque(), PdLawTorque()):
    register_torque_source(_builtin)
