"""The identification route is the rig's: ``identify --actuator pd`` on a robot whose rig does not identify PD
drivers (a quadruped on point feet) is one line naming the rig and the route it takes, before the log is read."""

from __future__ import annotations

from helpers import run_cli_printed


def test_identify_actuator_pd_asks_the_rig(tmp_path, capsys):
    log = tmp_path / "trot.parquet"
    log.write_bytes(b"not read")
    code, _, err = run_cli_printed(capsys, "identify", log, "--robot", "go2_walking", "--actuator", "pd")
    assert (code, err.strip()) == (2, "error: --actuator pd: robot 'go2_walking' stands on point feet (a walking "
                                      "quadruped): its identification is the inertia model's and the friction's "
                                      "('identify' without --actuator pd)")
