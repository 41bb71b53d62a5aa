"""Helpers shared by several test modules: running the command line, writing ROS 2 bags, the real logs."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from wbfriction import cli
from wbfriction.logs.bags import BagMap, ContactTopic

T0 = 1_700_000_000_000_000_000  # an absolute stamp [ns], as robots write them

REPO = Path(__file__).resolve().parents[1]
REAL_DATA = Path(os.environ.get("WBFRICTION_DATA") or os.environ.get("WBFRICTION_REAL_DATA")
                 or REPO / ".." / "shared" / "real-data")
"""Logs recorded on real robots: env ``WBFRICTION_DATA`` (what :mod:`wbfriction.datasets` reads), else
``WBFRICTION_REAL_DATA`` (its former name), else ``../shared/real-data`` beside the checkout."""
KUKA = REAL_DATA / "kuka_lwr4"
KUKA_URDF = KUKA / "kuka_lwr4.urdf"
KUKA_CONFIG = REPO / "examples" / "kuka_lwr4.toml"
needs_kuka = pytest.mark.skipif(not KUKA.is_dir(), reason=f"the real KUKA LWR4+ logs are not at {KUKA} "
                                                         "(set WBFRICTION_DATA)")


def needs_data(folder: str):
    """Skip a test without the real dataset's folder ``REAL_DATA/<folder>`` (e.g. ``ur10e``, ``panda``)."""
    return pytest.mark.skipif(not (REAL_DATA / folder).is_dir(),
                              reason=f"the real {folder} logs are not at {REAL_DATA / folder} (set WBFRICTION_DATA)")


def kuka_table(*runs: int) -> pa.Table:
    """Runs ``measurements_<i>.npz`` of the KUKA LWR4+ in the log format (stamps untouched), one after the
    other: :func:`wbfriction.logs.read_npz_recordings`, as ``examples/kuka_lwr4_convert.py`` and
    ``wbfriction dataset kuka-lwr4`` convert them."""
    from wbfriction.datasets import KUKA_LWR4_JOINTS
    from wbfriction.logs import read_npz_recordings

    return read_npz_recordings([KUKA / f"measurements_{i}.npz" for i in runs], KUKA_LWR4_JOINTS)


def strict_json(path):
    """The JSON document at ``path``, refused (the test fails) where it holds ``NaN``, ``Infinity`` or
    ``-Infinity``: no file the package writes may (issue 63; a number that is not finite is ``null``)."""
    import json

    text = Path(path).read_text(encoding="utf-8")

    def refuse(constant: str):
        pytest.fail(f"{path}: holds {constant}, which JSON does not have (null expected)")

    return json.loads(text, parse_constant=refuse)


def run(*args, cwd=None, columns: int = 200):
    """``python -m wbfriction ARGS`` in a terminal ``columns`` wide."""
    return subprocess.run([sys.executable, "-m", "wbfriction", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=dict(os.environ, COLUMNS=str(columns)))


STAGE_LINE = re.compile(r"(?P<label>.+): (?:(?P<items>\d+) (?P<unit>\S+) in )?(?P<seconds>\d+\.\d) s")
"""A stage's line on standard error off a terminal (:mod:`wbfriction.cli.stages`): ``fit: 12 joints in 81.2 s``,
``reading friction.parquet: 0.4 s``."""


def said(stderr: str) -> list[str]:
    """The non-empty lines of a command's standard error but its stages' (:data:`STAGE_LINE`, printed as each ends
    when standard error is not a terminal): its messages, e.g. an error's one line."""
    return [line for line in stderr.strip().splitlines()
            if line.strip() and (line.startswith(("error:", "warning:")) or not STAGE_LINE.fullmatch(line))]


def stage_lines(stderr: str) -> list[re.Match]:
    """The stage lines of a command's standard error (piped, not a terminal), in order; each checked to be one plain
    line of at most 100 characters (no carriage return, no ANSI escape)."""
    assert "\r" not in stderr and "\x1b" not in stderr, repr(stderr[:300])
    found = [m for m in map(STAGE_LINE.fullmatch, stderr.splitlines()) if m is not None]
    assert all(len(m[0]) <= 100 for m in found), [m[0] for m in found]
    return found


def assert_stages(stderr: str, *labels: str) -> dict[str, re.Match]:
    """Assert that a command's standard error holds a stage line starting with each of ``labels``, in this order;
    the lines by label (the first of each)."""
    found = stage_lines(stderr)
    names = [m["label"] for m in found]
    at = -1
    for label in labels:
        hits = [k for k, name in enumerate(names) if name.startswith(label) and k > at]
        assert hits, f"no stage line '{label}...' after {names[:at + 1]} in:\n{stderr}"
        at = hits[0]
    return {name: m for name, m in reversed(list(zip(names, found)))}


def widest_line(text: str) -> int:
    """The longest line of ``text`` in characters, trailing spaces left out (what a terminal shows)."""
    return max((len(line.rstrip()) for line in text.splitlines()), default=0)


def assert_one_line_error(res, needle):
    assert res.returncode == 2
    lines = said(res.stderr)
    assert len(lines) == 1 and needle in lines[0], res.stderr


def run_cli(capsys, *args) -> tuple[int, str]:
    """``wbfriction ARGS`` in this process: (exit status, standard error)."""
    code, _, err = run_cli_printed(capsys, *args)
    return code, err


def run_cli_printed(capsys, *args) -> tuple[int, str, str]:
    """``wbfriction ARGS`` in this process: (exit status, standard output, standard error)."""
    argv = sys.argv
    sys.argv = ["wbfriction", *map(str, args)]
    try:
        cli.main()
        code = 0
    except SystemExit as exc:
        code = exc.code
    finally:
        sys.argv = argv
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def hung_go2_toml(path: Path, robot, delay: float) -> Path:
    """A robot TOML at ``path`` for the hung Go2 ``robot`` (its URDF, drivers' gains, encoder offsets) with the
    drivers' ``delay`` [s]: what ``--config`` takes for a simulated log's own truth."""
    offsets = "\n".join(f"{j} = {v!r}" for j, v in robot.encoder_offset.items())
    pd = robot.pd
    path.write_text(f'name = "go2"\nurdf = "{robot.urdf}"\nfloating_base = false\n'
                    f'[pd]\nkp = {float(pd.kp[0])!r}\nkd = {float(pd.kd[0])!r}\ndelay = {delay!r}\n'
                    f'[encoder_offset]\n{offsets}\n')
    return path


def ros_time(ts, ns: int):
    return ts.types["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def write_bag(path, log, robot, storage: str = "mcap", wrench_every: int = 2, odom_every: int = 5,
              shuffle: bool = True, rename: dict | None = None, delay_ns: dict | None = None, stamp=None,
              force=None):
    """The log as a bag: JointState at every sample (names in a different order in every
    message), the left sole's contact as a 400 N WrenchStamped every ``wrench_every`` samples
    (``force(k, f)``: the force written for sample ``k`` instead of ``f``),
    the right one as a Bool, the base as Odometry every ``odom_every`` samples.

    ``delay_ns``: topic -> how much later than its stamp a message is received [ns] (the
    bag's order is the receive time). ``stamp(topic, k, ns)``: the header stamp written
    for sample ``k`` (default ``ns``)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    rng = np.random.default_rng(0)
    rename = rename or {}
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    names = list(robot.actuated)
    delay_ns = delay_ns or {}
    stamp = stamp or (lambda topic, k, ns: ns)
    messages = []  # (receive time, connection, bytes), written in receive order
    with Writer(path, version=9, storage_plugin=plugin) as w:
        c_js = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        c_lf = w.add_connection("/left_ft", "geometry_msgs/msg/WrenchStamped", typestore=ts)
        c_rf = w.add_connection("/right_contact", "std_msgs/msg/Bool", typestore=ts)
        c_od = w.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        tau_all = np.zeros((len(log), len(names)))
        tau_all[:, robot.tc_index] = log.tau
        for k in range(len(log)):
            ns = T0 + int(round(log.time[k] * 1e9))
            header = lambda topic: T["std_msgs/msg/Header"](stamp=ros_time(ts, stamp(topic, k, ns)), frame_id="")  # noqa: E731, B023
            write = lambda c, data: messages.append((ns + delay_ns.get(c.topic, 0), len(messages), c, data))  # noqa: E731, B023
            order = rng.permutation(len(names)) if shuffle else np.arange(len(names))
            js = T["sensor_msgs/msg/JointState"](
                header=header("/joint_states"), name=[rename.get(names[i], names[i]) for i in order],
                position=log.q[k, order].astype(np.float64), velocity=np.zeros(0),
                effort=tau_all[k, order].astype(np.float64))
            write(c_js, ts.serialize_cdr(js, "sensor_msgs/msg/JointState"))
            if k % wrench_every == 0:
                f = 400.0 if log.contact[k, 0] else 3.0
                f = f if force is None else force(k, f)
                wr = T["geometry_msgs/msg/WrenchStamped"](
                    header=header("/left_ft"), wrench=T["geometry_msgs/msg/Wrench"](
                    force=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=-f),
                    torque=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)))
                write(c_lf, ts.serialize_cdr(wr, "geometry_msgs/msg/WrenchStamped"))
            if k == 0 or log.contact[k, 1] != log.contact[k - 1, 1]:  # a state topic: on change only
                write(c_rf, ts.serialize_cdr(T["std_msgs/msg/Bool"](data=bool(log.contact[k, 1])), "std_msgs/msg/Bool"))
            if k % odom_every == 0:
                b = log.base[k]
                pose = T["geometry_msgs/msg/Pose"](
                    position=T["geometry_msgs/msg/Point"](x=b[0], y=b[1], z=b[2]),
                    orientation=T["geometry_msgs/msg/Quaternion"](x=b[3], y=b[4], z=b[5], w=b[6]))
                odom = T["nav_msgs/msg/Odometry"](
                    header=header("/odom"), child_frame_id="base_link",
                    pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
                    twist=T["geometry_msgs/msg/TwistWithCovariance"](
                        twist=T["geometry_msgs/msg/Twist"](linear=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                                                           angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)),
                        covariance=np.zeros(36)))
                write(c_od, ts.serialize_cdr(odom, "nav_msgs/msg/Odometry"))
        for received, _, c, data in sorted(messages, key=lambda m: m[:2]):
            w.write(c, received, data)


def bag_map(robot, **kw) -> BagMap:
    left, right = robot.contact_frames
    return BagMap("/joint_states", (ContactTopic(left, "/left_ft", 50.0), ContactTopic(right, "/right_contact")),
                  base="/odom", **kw)




def drawn_texts(fig) -> list:
    """Every text a matplotlib figure draws (tick labels, titles, legends...), as (text, window extent [px],
    font size [px]): recorded while the figure is drawn on the Agg canvas, so texts that are not drawn (ticks
    outside the view) are not counted."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    renderer = canvas.get_renderer()
    seen: dict[int, tuple] = {}
    draw_text = renderer.draw_text

    def record(gc, x, y, s, prop, angle, ismath=False, mtext=None):
        if mtext is not None and s.strip() and id(mtext) not in seen:
            seen[id(mtext)] = (mtext.get_text(), mtext.get_window_extent(renderer),
                               mtext.get_fontsize() * fig.dpi / 72)
        return draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)

    renderer.draw_text = record
    fig.draw(renderer)
    return list(seen.values())


def text_overlaps(texts: list, tolerance: float = 1.0) -> list[tuple[str, str]]:
    """Pairs of texts (:func:`drawn_texts`) whose boxes, shrunk by ``tolerance`` px on every side, intersect."""
    pairs = []
    for k, (a, box_a, _) in enumerate(texts):
        for b, box_b, _ in texts[k + 1:]:
            w = min(box_a.x1, box_b.x1) - max(box_a.x0, box_b.x0) - 2 * tolerance
            h = min(box_a.y1, box_b.y1) - max(box_a.y0, box_b.y0) - 2 * tolerance
            if w > 0 and h > 0:
                pairs.append((a, b))
    return pairs


MAP_RENAME = {"leg_left_4_joint": "LLeg_knee", "leg_right_4_joint": "RLeg_knee", "torso_1_joint": "waist_yaw"}


def mapped_copy(table: pa.Table, frames: tuple[str, ...]) -> tuple[pa.Table, str]:
    """``table`` with some joints under other names and each contact flag replaced by a force column
    (300 N in contact, 2 N off it), and the map TOML that undoes it."""
    back = {v: k for k, v in MAP_RENAME.items()}
    names = []
    for name in table.column_names:
        kind, dot, item = name.partition(".")
        names.append(f"{kind}.{MAP_RENAME[item]}" if dot and item in MAP_RENAME else name)
    out = table.rename_columns(names)
    toml = "[joint_states]\nrename = { " + ", ".join(f'{k} = "{v}"' for k, v in back.items()) + " }\n"
    for k, frame in enumerate(frames):
        flags = out.column(f"contact.{frame}").to_numpy()
        out = out.drop_columns([f"contact.{frame}"]).append_column(f"foot{k}.fz", pa.array(-(2.0 + 298.0 * flags)))
        toml += f'[[contacts]]\nframe = "{frame}"\ncolumn = "foot{k}.fz"\nthreshold = 50.0\n'
    return out.replace_schema_metadata(table.schema.metadata), toml


def ended_within(proc: subprocess.Popen, seconds: float, after: str) -> tuple[str, str]:
    """The standard output and error of ``proc`` (started in a session of its own) once it ends; if it is
    still running ``seconds`` later, its group killed and the test failed, saying so ``after`` what."""
    try:
        return proc.communicate(timeout=seconds)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        pytest.fail(f"still running {seconds:g} s after {after}: {err}")


def chain_urdf(rng: np.random.Generator) -> str:
    """A chain of every 1-DoF joint Pinocchio makes of a URDF: revolute, continuous and prismatic joints
    about x, y, z and an axis that is none of them; random placements and bodies; the sole at its end."""
    unaligned = "0.48 0.6 0.64"
    links, joints, parent = ['<link name="base"><inertial><mass value="3"/><inertia ixx="0.1" iyy="0.2" izz="0.3" '
                             'ixy="0" ixz="0" iyz="0"/></inertial></link>'], [], "base"
    kinds = [(t, a) for t in ("revolute", "continuous", "prismatic") for a in ("1 0 0", "0 1 0", "0 0 1", unaligned)]
    for k, (kind, axis) in enumerate(kinds):
        m, c = rng.uniform(0.5, 2.0), rng.uniform(-0.1, 0.1, 3)
        xyz, rpy = rng.uniform(-0.3, 0.3, 3), rng.uniform(-1.0, 1.0, 3)
        links.append(f'<link name="l{k}"><inertial><origin xyz="{" ".join(map(str, c))}"/><mass value="{m}"/>'
                     f'<inertia ixx="{0.02 * m}" iyy="{0.03 * m}" izz="{0.025 * m}" ixy="0.001" ixz="0" iyz="0"/>'
                     f'</inertial></link>')
        limit = '<limit lower="-2" upper="2" effort="100" velocity="10"/>' if kind != "continuous" else ""
        joints.append(f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="l{k}"/>'
                      f'<origin xyz="{" ".join(map(str, xyz))}" rpy="{" ".join(map(str, rpy))}"/>'
                      f'<axis xyz="{axis}"/>{limit}</joint>')
        parent = f"l{k}"
    links.append('<link name="sole"/>')
    joints.append(f'<joint name="sole_joint" type="fixed"><parent link="{parent}"/><child link="sole"/>'
                  '<origin xyz="0.05 0 -0.1" rpy="0.2 0 0"/></joint>')
    return '<robot name="chain">' + "".join(links + joints) + "</robot>"


def load_yaml(text: str, version: tuple[int, int] | None = None):
    """Safe-load YAML (ruamel, pure); ``version`` (1, 1): as a YAML 1.1 reader, where a float without a dot in its
    mantissa (PyYAML would read a string) is an error (its warning raised)."""
    import warnings

    from ruamel.yaml import YAML

    yaml = YAML(typ="safe", pure=True)
    if version is not None:
        yaml.version = version
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return yaml.load(text)


def consistent_motion(robot, q: np.ndarray, v: np.ndarray, a_joint: np.ndarray, contact: np.ndarray,
                      force: np.ndarray, tau_f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact data for a robot on point feet: the base's acceleration that the contact forces ``force`` (N, n_c, 3)
    (world axes, at the feet ``contact`` (N, n_c) down) make with the joints' accelerations ``a_joint`` (N, n_act),
    its six rows solved, and the joint torques ``tau`` (N, n_act) the motion then needs less the friction ``tau_f``
    (the equation of motion ``M a + h = S^T (tau + tau_f) + sum J^T f`` holds to round-off); returns ``(a, tau)``."""
    import pinocchio as pin

    from wbfriction.model.determination import contact_jacobian

    model, data = robot.model, robot.model.createData()
    a = np.zeros((len(q), model.nv))
    tau = np.empty((len(q), robot.n_act))
    for k in range(len(q)):
        a[k, robot.act_v_index] = a_joint[k]
        pin.computeJointJacobians(model, data, q[k])
        pin.updateFramePlacements(model, data)
        ext = sum((contact_jacobian(robot, data, c).T @ force[k, c] for c in np.flatnonzero(contact[k])),
                  np.zeros(model.nv))
        M = pin.crba(model, data, q[k])
        a[k, :6] = -np.linalg.solve(M[:6, :6], (pin.rnea(model, data, q[k], v[k], a[k]) - ext)[:6])
        r = pin.rnea(model, data, q[k], v[k], a[k]) - ext
        assert np.abs(r[:6]).max() < 1e-9
        tau[k] = r[robot.act_v_index] - tau_f[k]
    return a, tau


def assert_same_tables(a: pa.Table, b: pa.Table, what: str, atol: float = 1e-9) -> None:
    """Two tables with the same columns, their floats equal to ``rtol=1e-9`` and ``atol``, the rest exactly (``what``
    names them in a failure)."""
    assert a.column_names == b.column_names, what
    for name in a.column_names:
        x, y = a[name].to_numpy(zero_copy_only=False), b[name].to_numpy(zero_copy_only=False)
        if x.dtype.kind == "f":
            np.testing.assert_allclose(x, y, rtol=1e-9, atol=atol, err_msg=f"{what}: {name}")
        else:
            assert np.array_equal(x, y), (what, name)


def hung_truth_mjcf(go2, mjr, folder: Path, duration: float):
    """``duration`` s of the hung Go2, noise-free, its friction MuJoCo's own (frictionloss, damping; the constraint's
    time constant MuJoCo's default, as an export leaves it), the MJCF of its true parameters and the log, in
    ``folder``: ``(sim, robot, truth.xml, hung.parquet)``, ``robot`` the Go2 with the simulation's encoder offsets."""
    import dataclasses

    import pyarrow.parquet as pq

    from wbfriction.export.mjcf import write_mjcf
    from wbfriction.sim.hung import simulate_hung
    from wbfriction.sim.pd_options import HungOptions

    sim = simulate_hung(go2, HungOptions(duration=duration, friction="mujoco", friction_timeconst=0.02), mjr=mjr)
    robot = dataclasses.replace(go2, encoder_offset=dict(zip(go2.actuated, sim.encoder_offset.tolist())), cache={})
    truth, log = folder / "truth.xml", folder / "hung.parquet"
    write_mjcf(robot, sim.friction, truth, armature=dict(zip(go2.actuated, sim.armature.tolist())))
    pq.write_table(sim.table, log)
    return sim, robot, truth, log


def run_with_toy_format(code: str):
    """Run Python ``code`` in a fresh interpreter with the toy Feather format (``tests/toys``) importable (registered
    before the command line loads, as a plugin's would be), returning the JSON its last printed line holds."""
    import json

    tests = Path(__file__).resolve().parent
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tests), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.splitlines()[-1])


def logger_sampling(drive: float, logger: float, duration: float, hold: float = 0.0, phase: float = 0.3e-3,
                    noise: float = 0.0, seed: int = 0):
    """A drive clock at ``drive`` [s] (each period held with probability ``hold``: no new sample) read by a logger
    at ``logger`` [s]: each row the drives' latest sample. Returns the rows' stamps (N,), their values (N, 3), the
    true times of the samples (K,), which sample each row shows (N,)."""
    rng = np.random.default_rng(seed)
    ticks = np.arange(int(duration / drive))
    held = rng.random(ticks.size) < hold
    held[0] = False
    true = phase + drive * ticks[~held]
    values = np.column_stack([np.sin(true), np.cos(3 * true), true]) + noise * rng.normal(size=(true.size, 3))
    stamps = logger * np.arange(int(true[-1] / logger) + 1)
    shown = np.searchsorted(true, stamps, side="right") - 1  # the latest sample taken at or before the tick
    keep = shown >= 0
    return stamps[keep], values[shown[keep]], true, shown[keep]
