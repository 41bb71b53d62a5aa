"""ROS 2 bags written with rosbags' own writer (MCAP and sqlite3) and read back as logs."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pytest

from helpers import assert_one_line_error, bag_map, ros_time, run, write_bag
from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.bags import BagMap, ContactTopic, iter_bag, load_bag_map, read_bag
from wbfriction.logs.log import log_from_table
from wbfriction.logs.source import read_log

T0 = 1_700_000_000_000_000_000  # an absolute stamp [ns], as robots write them


@pytest.fixture(scope="module")
def short_log(talos, combined_walk):
    """2.5 s of the combined walk (with two contact changes per foot at least)."""
    log = combined_walk.log
    n = 2500
    return log_from_table(log.to_table(talos).slice(0, n), talos, "walk")


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_bag_reads_back_as_the_log(talos, short_log, tmp_path, storage):
    log = short_log
    write_bag(tmp_path / "bag", log, talos, storage, wrench_every=3)
    back = log_from_table(read_bag(tmp_path / "bag", bag_map(talos)), talos, "bag")
    # the log spans the stamps where every topic has data: from the first sample to the last
    # odometry message (every 5th sample), after which the base cannot be interpolated
    n = (len(log) - 1) // 5 * 5 + 1
    assert len(back) == n
    log = log_from_table(log.to_table(talos).slice(0, n), talos, "walk")
    np.testing.assert_allclose(back.time, log.time - log.time[0], atol=1e-9)
    np.testing.assert_array_equal(back.q, log.q)  # float64 through CDR: bit for bit
    np.testing.assert_array_equal(back.tau, log.tau)
    # right foot (Bool on change): exact; left foot (wrench every 3rd sample, zero-order hold):
    # off only on the (at most 2) samples after a change that fell between two wrench messages
    np.testing.assert_array_equal(back.contact[:, 1], log.contact[:, 1])
    wrong = np.flatnonzero(back.contact[:, 0] != log.contact[:, 0])
    changes = np.flatnonzero(np.diff(log.contact[:, 0].astype(int))) + 1
    assert changes.size >= 1 and wrong.size >= 1
    assert set(wrong) <= set(changes) | set(changes + 1)
    # base: odometry every 5th sample, linear + slerp in between
    # (exact on the messages' stamps; between them the error of a chord over 5 ms)
    np.testing.assert_allclose(back.base[::5, :3], log.base[::5, :3], atol=1e-12)
    assert np.abs(back.base[:, :3] - log.base[:, :3]).max() < 1e-3
    dots = np.abs(np.sum(back.base[:, 3:] * log.base[:, 3:], axis=1))
    assert np.degrees(2 * np.arccos(np.clip(dots, -1, 1))).max() < 0.05


def test_a_bag_is_streamed_in_blocks_with_late_topics(talos, short_log, tmp_path):
    """Read in blocks of 50 samples while the odometry arrives 30 ms and the wrenches 7 ms
    after their stamps: the same table as the on-time bag read whole, bit for bit, and no
    block holds more than the block plus the samples the late topics hold back."""
    write_bag(tmp_path / "on_time", short_log, talos, wrench_every=3)
    write_bag(tmp_path / "late", short_log, talos, wrench_every=3,
              delay_ns={"/odom": 30_000_000, "/left_ft": 7_000_000})
    whole = read_bag(tmp_path / "on_time", bag_map(talos))
    blocks = list(iter_bag(tmp_path / "late", bag_map(talos), block_rows=50))
    assert len(blocks) > len(short_log) // 100
    assert max(b.num_rows for b in blocks) <= 50 + 31 + 5  # + the odometry's lag and its period
    streamed = pa.concat_tables(blocks)
    assert streamed.column_names == whole.column_names
    for name in whole.column_names:
        np.testing.assert_array_equal(streamed.column(name).to_numpy(), whole.column(name).to_numpy(), err_msg=name)
    meta = lambda t: {k: v for k, v in json.loads(t.schema.metadata[b"wbfriction"]).items() if k != "source_bag"}  # noqa: E731
    assert meta(blocks[0]) == meta(whole) and meta(whole)["time_origin_ns"] == T0


def test_bag_stamps_that_go_back_and_joints_that_appear_are_refused(talos, short_log, tmp_path):
    back = lambda topic, k, ns: ns - 6_000_000 if (topic, k) == ("/odom", 100) else ns  # noqa: E731
    write_bag(tmp_path / "a", short_log, talos, stamp=back)
    with pytest.raises(InputError, match="topic '/odom': the stamp of message 21 goes back in time"):
        read_bag(tmp_path / "a", bag_map(talos))
    js_back = lambda topic, k, ns: ns - 2_000_000 if (topic, k) == ("/joint_states", 40) else ns  # noqa: E731
    write_bag(tmp_path / "b", short_log, talos, stamp=js_back)
    with pytest.raises(InputError, match="topic '/joint_states': the stamp of message 41 goes back in time"):
        read_bag(tmp_path / "b", bag_map(talos))
    # a joint-state message naming a joint the first one did not
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Writer(tmp_path / "e", version=9) as w:
        conns = {t: w.add_connection(t, m, typestore=ts) for t, m in (
            ("/joint_states", "sensor_msgs/msg/JointState"), ("/right_contact", "std_msgs/msg/Bool"))}
        for k, names in enumerate((["a", "b"], ["a", "c"])):
            ns = T0 + k * 1_000_000
            js = ts.types["sensor_msgs/msg/JointState"](
                header=ts.types["std_msgs/msg/Header"](stamp=ros_time(ts, ns), frame_id=""), name=names,
                position=np.zeros(2), velocity=np.zeros(0), effort=np.zeros(2))
            w.write(conns["/right_contact"], ns - 1, ts.serialize_cdr(ts.types["std_msgs/msg/Bool"](data=True),
                                                                      "std_msgs/msg/Bool"))
            w.write(conns["/joint_states"], ns, ts.serialize_cdr(js, "sensor_msgs/msg/JointState"))
    two = BagMap("/joint_states", (ContactTopic("right_sole_link", "/right_contact"),))
    with pytest.raises(InputError, match="joint-state message 2 names joint 'c', which the first message did not"):
        read_bag(tmp_path / "e", two)


@pytest.mark.parametrize("which", ["one", "all"])
def test_a_nan_wrench_is_refused_not_read_as_no_contact(talos, short_log, tmp_path, which):
    """A WrenchStamped contact whose force is NaN compared as "no contact" (|NaN| > threshold is False):
    refused, naming the bag, the topic and the message (the wrench messages are every 2nd sample)."""
    nan = (lambda k, f: np.nan if k == 600 else f) if which == "one" else (lambda k, f: np.nan)  # noqa: E731
    write_bag(tmp_path / "bag", short_log, talos, force=nan)
    message = 301 if which == "one" else 1
    with pytest.raises(InputError, match=rf"bag: topic '/left_ft': message {message} has a non-finite force.z "
                                         r"\(nan\): it cannot say whether frame 'left_sole_link' is in contact"):
        read_bag(tmp_path / "bag", bag_map(talos))


def test_estimate_from_a_bag_equals_estimate_from_its_conversion(talos, short_log, tmp_path):
    """'estimate BAG --map' and 'convert' then 'estimate' are one computation."""
    write_bag(tmp_path / "bag", short_log, talos, wrench_every=1, odom_every=1)
    (tmp_path / "map.toml").write_text(
        '[joint_states]\ntopic = "/joint_states"\n'
        f'[[contacts]]\nframe = "{talos.contact_frames[0]}"\ntopic = "/left_ft"\nthreshold = 50\n'
        f'[[contacts]]\nframe = "{talos.contact_frames[1]}"\ntopic = "/right_contact"\n'
        '[base]\ntopic = "/odom"\n')
    m = load_bag_map(tmp_path / "map.toml")
    direct = estimate_log(talos, read_log(tmp_path / "bag", talos, m), EstimateOptions())
    from wbfriction.logs.log import write_log

    write_log(read_log(tmp_path / "bag", talos, m), talos, tmp_path / "log.parquet")
    converted = estimate_log(talos, read_log(tmp_path / "log.parquet", talos), EstimateOptions())
    np.testing.assert_array_equal(direct.tau_f, converted.tau_f)
    ref = estimate_log(talos, short_log, EstimateOptions())
    assert np.nanmax(np.abs(direct.tau_f - ref.tau_f)) < 1e-6


def test_renamed_joints_and_bag_errors(talos, short_log, tmp_path):
    rename = {"leg_left_4_joint": "LLeg_knee"}
    write_bag(tmp_path / "bag", short_log, talos, "sqlite3", rename=rename)
    back = log_from_table(read_bag(tmp_path / "bag", bag_map(talos, rename={"LLeg_knee": "leg_left_4_joint"})),
                          talos, "bag")
    np.testing.assert_array_equal(back.q, short_log.q[:len(back)])
    # without the rename the model's knee is missing and the bag's name is unknown
    with pytest.raises(InputError, match="unknown joint 'LLeg_knee'"):
        log_from_table(read_bag(tmp_path / "bag", bag_map(talos)), talos, "bag")
    missing = BagMap("/joint_states", (ContactTopic(talos.contact_frames[0], "/nope"),))
    with pytest.raises(InputError, match="no topic '/nope' in the bag"):
        read_bag(tmp_path / "bag", missing)
    wrong = BagMap("/odom", bag_map(talos).contacts)
    with pytest.raises(InputError, match="carries nav_msgs/msg/Odometry, expected sensor_msgs/msg/JointState"):
        read_bag(tmp_path / "bag", wrong)
    no_threshold = BagMap("/joint_states", (ContactTopic(talos.contact_frames[0], "/left_ft"),))
    with pytest.raises(InputError, match="give its threshold"):
        read_bag(tmp_path / "bag", no_threshold)
    with pytest.raises(InputError, match="needs a topic map"):
        read_log(tmp_path / "bag", talos)
    (tmp_path / "junk").mkdir()
    (tmp_path / "junk" / "metadata.yaml").write_text("not: a bag\n")
    with pytest.raises(InputError, match="not a readable ROS 2 bag"):
        read_bag(tmp_path / "junk", bag_map(talos))
    (tmp_path / "bad.toml").write_text('[joint_states]\ntopic = "/js"\n')
    with pytest.raises(InputError, match="no \\[\\[contacts\\]\\] entry"):
        load_bag_map(tmp_path / "bad.toml")


def test_convert_and_estimate_commands_take_a_bag(talos, short_log, tmp_path):

    write_bag(tmp_path / "bag", short_log, talos, odom_every=1)
    left, right = talos.contact_frames
    (tmp_path / "map.toml").write_text(
        f'[joint_states]\ntopic = "/joint_states"\n[[contacts]]\nframe = "{left}"\ntopic = "/left_ft"\n'
        f'threshold = 50\n[[contacts]]\nframe = "{right}"\ntopic = "/right_contact"\n[base]\ntopic = "/odom"\n')
    res = run("convert", tmp_path / "bag", "--map", tmp_path / "map.toml", "-o", tmp_path / "log.parquet")
    assert res.returncode == 0, res.stderr
    assert len(read_log(tmp_path / "log.parquet", talos)) == len(short_log)
    res = run("estimate", tmp_path / "bag", "--map", tmp_path / "map.toml", "-o", tmp_path / "f.parquet")
    assert res.returncode == 0, res.stderr
    assert_one_line_error(run("estimate", tmp_path / "bag", "-o", tmp_path / "x.parquet"), "needs a topic map")
    (tmp_path / "bad.toml").write_text('[joint_states]\ntopic = "/nope"\n[[contacts]]\nframe = "x"\ntopic = "/y"\n')
    assert_one_line_error(run("convert", tmp_path / "bag", "--map", tmp_path / "bad.toml", "-o",
                               tmp_path / "x.parquet"), "no topic '/nope' in the bag")
    assert not (tmp_path / "x.parquet").exists()
