"""A long ROS 2 bag in bounded memory: messages per second and peak memory of ``convert``.

Writes an MCAP bag of ``--minutes`` for TALOS by repeating a simulated combined walk:
``sensor_msgs/JointState`` at 1 kHz (32 joints), the left sole's ``WrenchStamped`` at 1 kHz,
the right sole's contact as a ``Bool`` on change, ``nav_msgs/Odometry`` at 200 Hz arriving
10 ms after its stamp. Then runs ``wbfriction convert`` on it (streamed,
:func:`wbfriction.logs.bags.iter_bag`, then checked in chunks) and, with ``--estimate``,
``wbfriction estimate`` on the bag, and prints rows per second and the peak resident memory
of each command's process tree. Run it for two lengths to see that memory does not grow
with the bag:

    python benchmarks/bench_long_bag.py --minutes 5
    python benchmarks/bench_long_bag.py --minutes 20 --estimate
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

import numpy as np
from bench_long_log import measure, walk_log, work_folder

from wbfriction.model.loading import load_robot

T0 = 1_700_000_000_000_000_000
MAP = """[joint_states]
topic = "/joint_states"
[[contacts]]
frame = "left_sole_link"
topic = "/left_ft"
threshold = 50.0
[[contacts]]
frame = "right_sole_link"
topic = "/right_contact"
[base]
topic = "/odom"
"""


def build_bag(path: Path, minutes: float) -> int:
    """The bag, written message by message (never held whole); returns its joint-state samples."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    robot = load_robot("talos")
    log = walk_log(robot)
    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    names = list(robot.actuated)
    tau = np.zeros((len(log), len(names)))
    tau[:, robot.tc_index] = log.tau
    period_ns = 1_000_000
    total = int(minutes * 60_000)
    vec = lambda x, y, z: T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)  # noqa: E731
    stamp = lambda ns: T["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)  # noqa: E731
    header = lambda ns: T["std_msgs/msg/Header"](stamp=stamp(ns), frame_id="")  # noqa: E731
    late: list[tuple[int, bytes]] = []  # odometry waiting for its receive time
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        c_js = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        c_lf = w.add_connection("/left_ft", "geometry_msgs/msg/WrenchStamped", typestore=ts)
        c_rf = w.add_connection("/right_contact", "std_msgs/msg/Bool", typestore=ts)
        c_od = w.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for n in range(total):
            k = n % len(log)
            ns = T0 + n * period_ns
            while late and late[0][0] <= ns:
                w.write(c_od, *late.pop(0))
            js = T["sensor_msgs/msg/JointState"](header=header(ns), name=names, position=np.ascontiguousarray(log.q[k]),
                                                 velocity=np.zeros(0), effort=tau[k])
            w.write(c_js, ns, ts.serialize_cdr(js, "sensor_msgs/msg/JointState"))
            force = 400.0 if log.contact[k, 0] else 3.0
            wr = T["geometry_msgs/msg/WrenchStamped"](header=header(ns), wrench=T["geometry_msgs/msg/Wrench"](
                force=vec(0.0, 0.0, -force), torque=vec(0.0, 0.0, 0.0)))
            w.write(c_lf, ns, ts.serialize_cdr(wr, "geometry_msgs/msg/WrenchStamped"))
            if n == 0 or log.contact[k, 1] != log.contact[(n - 1) % len(log), 1]:
                w.write(c_rf, ns, ts.serialize_cdr(T["std_msgs/msg/Bool"](data=bool(log.contact[k, 1])),
                                                   "std_msgs/msg/Bool"))
            if n % 5 == 0:
                b = log.base[k]
                pose = T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=b[0], y=b[1], z=b[2]),
                                                   orientation=T["geometry_msgs/msg/Quaternion"](
                                                       x=b[3], y=b[4], z=b[5], w=b[6]))
                odom = T["nav_msgs/msg/Odometry"](
                    header=header(ns), child_frame_id="base_link",
                    pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
                    twist=T["geometry_msgs/msg/TwistWithCovariance"](
                        twist=T["geometry_msgs/msg/Twist"](linear=vec(0.0, 0.0, 0.0), angular=vec(0.0, 0.0, 0.0)),
                        covariance=np.zeros(36)))
                late.append((ns + 10 * period_ns, ts.serialize_cdr(odom, "nav_msgs/msg/Odometry")))
        for item in late:
            w.write(c_od, *item)
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=5.0)
    parser.add_argument("--estimate", action="store_true", help="Also run 'wbfriction estimate' on the bag.")
    parser.add_argument("--keep", type=Path, default=None, help="Folder to keep the bag and the outputs in.")
    args = parser.parse_args()
    with work_folder(args.keep, "wbf-bag-") as folder:
        bag = folder / "bag"
        shutil.rmtree(bag, ignore_errors=True)
        t0 = time.perf_counter()
        rows = build_bag(bag, args.minutes)
        size = sum(p.stat().st_size for p in bag.iterdir())
        print(f"bag: {rows} joint-state samples ({rows / 60_000:.1f} min at 1 kHz) and "
              f"{rows * 1.2:.0f} other messages, {size / 2**30:.2f} GiB, written in {time.perf_counter() - t0:.0f} s")
        (folder / "map.toml").write_text(MAP)
        base = [sys.executable, "-m", "wbfriction"]
        seconds, peak = measure([*base, "convert", str(bag), "--map", str(folder / "map.toml"),
                                 "-o", str(folder / "log.parquet")])
        print(f"wbfriction convert: {seconds:.0f} s, {rows / seconds:.0f} samples/s, peak {peak / 2**20:.0f} MiB "
              f"resident (sampled every 0.2 s)")
        if args.estimate:
            seconds, peak = measure([*base, "estimate", str(bag), "--map", str(folder / "map.toml"),
                                     "-o", str(folder / "friction.parquet")])
            print(f"wbfriction estimate (bag): {seconds:.0f} s, {rows / seconds:.0f} samples/s, peak "
                  f"{peak / 2**20:.0f} MiB resident in all (the command and its 2 workers)")


if __name__ == "__main__":
    main()
