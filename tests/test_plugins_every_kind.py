"""Every kind the extending guide plugs in, through a real entry point, a broken plugin of its kind beside it (issue
81, class 6).

Each of the guide's examples (``docs/extending.md``: its code as the page shows it, up to its registration, which the
entry point takes the place of) is advertised under its registry's entry-point group by a distribution on the path
(a ``dist-info`` folder, read by ``importlib.metadata`` as an installed package's), beside a plugin of the same kind
whose module does not import: the log format (``wbfriction.log_formats``), the torque source
(``wbfriction.torque_sources``), the contact model (``wbfriction.contact_models``), the export target
(``wbfriction.export_targets``), the rig (``wbfriction.rigs``) and the engine (``wbfriction.engines``); the family
(``wbfriction.families``): ``tests/test_plugins_entry_points.py``. Each is used as the guide uses it, by a command:
the broken one is one ``warning:`` line where every kind is asked for (a file's format, a log's torque source, a
robot's rig, a rig's engines, an output's target), nothing where kinds are named (a contact model), and the good one
runs; naming the broken one is its one ``error:`` line.
"""

from __future__ import annotations

import importlib.metadata
import re
import sys
from pathlib import Path
from types import SimpleNamespace
from unittest.mock import patch

import pytest

from helpers import run_cli_printed, said
from wbfriction.export.registry import TARGETS
from wbfriction.friction.families.names import FAMILIES
from wbfriction.logs.formats.registry import FORMATS
from wbfriction.logs.torque import SOURCES
from wbfriction.model.contacts import MODELS
from wbfriction.registry import PluginWarning
from wbfriction.rigs.registry import RIGS
from wbfriction.sim.engines.registry import ENGINES

GUIDE = (Path(__file__).resolve().parents[1] / "docs" / "extending.md").read_text()
DIST = "guide-plugins 0.1"
GONE = "ModuleNotFoundError: No module named 'wbfriction_gone'"
REGISTRIES = (FORMATS, SOURCES, MODELS, TARGETS, FAMILIES, RIGS, ENGINES)

KINDS = {  # the guide's section, its registration, the entry's name, the registry's group and what it calls a kind
    "log_format": ("## A log format", "register_format(Tsv())", "tsv", "wbfriction.log_formats", "log format"),
    "torque": ("## A torque source", "register_torque_source(Effort())", "effort", "wbfriction.torque_sources",
               "torque source"),
    "contact": ("## A contact model", "register_contact_model(LocalPoint())", "local-point",
                "wbfriction.contact_models", "contact model"),
    "target": ("## An export target", "register_target(CsvTarget())", "csv", "wbfriction.export_targets",
               "export target"),
    "rig": ("## A rig", "register_rig(SineArm())", "sine-arm", "wbfriction.rigs", "rig"),
    "engine": ("## An engine", "register_engine(FineIdeal())", "ideal-fine", "wbfriction.engines", "engine"),
}


def section(heading: str) -> str:
    start = GUIDE.index(f"\n{heading}\n")
    end = GUIDE.find("\n## ", start + 1)
    return GUIDE[start:end if end >= 0 else None]


def guide_code(kind: str) -> tuple[str, str]:
    """The guide's example of ``kind``, as its page shows it, up to its registration, and the class registered."""
    heading, registration, *_ = KINDS[kind]
    block = re.search(r"```python\n(.*?)```", section(heading), re.S)
    assert block is not None
    code, found, _ = block[1].partition(registration)
    assert found, f"{heading}: no {registration}"
    return code, registration[registration.index("(") + 1:registration.index("(", registration.index("(") + 1)]


def test_each_section_shows_its_entry_point_group():
    """Each section of the guide names its group in a plugin package's ``pyproject.toml`` lines, as the test
    advertises it, the class its code registers under the name the test gives it."""
    for kind, (heading, _, name, group, _) in KINDS.items():
        text = section(heading)
        _, cls = guide_code(kind)
        assert f'[project.entry-points."{group}"]' in text, heading
        assert re.search(rf'^"?{re.escape(name)}"? = "[\w.]+:{cls}"$', text, re.M), heading


@pytest.fixture
def install(tmp_path, monkeypatch):
    """``install(kind)``: a distribution on the path advertising the guide's example of ``kind`` under its group,
    beside ``broken``, whose module does not import; every registry's entry points read again before and after."""
    site = tmp_path / "site"
    package = site / "guide_plugins"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "gone.py").write_text("import wbfriction_gone  # not installed\n")
    dist = site / "guide_plugins-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: guide-plugins\nVersion: 0.1\n")

    def make(kind: str) -> SimpleNamespace:
        code, cls = guide_code(kind)
        _, _, name, group, what = KINDS[kind]
        (package / f"{kind}.py").write_text(code)
        (dist / "entry_points.txt").write_text(f"[{group}]\n{name} = guide_plugins.{kind}:{cls}\n"
                                               "broken = guide_plugins.gone:Broken\n")
        monkeypatch.syspath_prepend(str(site))  # importlib's caches invalidated
        reread()
        warned = (f"warning: {what} 'broken' left out: the entry point 'broken = guide_plugins.gone:Broken' of {DIST} "
                  f"does not load: {GONE}")
        return SimpleNamespace(name=name, warned=warned, error=warned.replace(f"warning: {what} 'broken' left out",
                                                                              "error"))

    yield make
    reread()
    for module in [m for m in sys.modules if m == "guide_plugins" or m.startswith("guide_plugins.")]:
        del sys.modules[module]


def reread() -> None:
    for registry in REGISTRIES:
        registry.reread()


def warnings_said(err: str) -> list[str]:
    """The warning lines of a plugin left out (a simulation's own warnings aside)."""
    assert "Traceback" not in err, err
    return [line for line in said(err) if line.startswith("warning:") and "entry point" in line]


@pytest.fixture(scope="module")
def arm(tmp_path_factory) -> Path:
    """A folder with a simulated Panda's log (1 s), its friction table and its fitted parameters."""
    folder = tmp_path_factory.mktemp("arm")
    capsys = SimpleNamespace(readouterr=lambda: SimpleNamespace(out="", err=""))
    for args in (("simulate", "--robot", "panda", "--duration", "1", "-o", folder / "arm.parquet"),
                 ("estimate", folder / "arm.parquet", "--robot", "panda", "-o", folder / "friction.parquet"),
                 ("fit", folder / "friction.parquet", "--model", "coulomb-viscous", "--terms", "none", "-o",
                  folder / "params.json")):
        code, _, err = run_cli_printed(capsys, *args)
        assert code == 0, err
    return folder


def test_the_guides_log_format_writes_and_reads_logs_a_broken_one_beside_it(install, arm, tmp_path, capsys):
    """``simulate -o arm.tsv`` (the output's suffix none of the built-in formats': the advertised ones loaded, the
    broken one its one line) and ``estimate arm.tsv`` read it; a Parquet log is read without a word of either."""
    plugin = install("log_format")
    with patch("importlib.metadata.entry_points", wraps=importlib.metadata.entry_points) as read:
        code, _, err = run_cli_printed(capsys, "estimate", arm / "arm.parquet", "--robot", "panda", "-o",
                                       tmp_path / "f.parquet")
    assert code == 0 and warnings_said(err) == [], err
    assert "wbfriction.log_formats" not in {c.kwargs.get("group") for c in read.call_args_list}  # none read
    assert plugin.name not in FORMATS.loaded() and FORMATS.broken() == {}
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--duration", "1", "-o",
                                   tmp_path / "arm.tsv")
    assert code == 0 and warnings_said(err) == [plugin.warned], err
    assert (tmp_path / "arm.tsv").read_text().startswith("\"time\"\t")
    code, _, err = run_cli_printed(capsys, "estimate", tmp_path / "arm.tsv", "--robot", "panda", "-o",
                                   tmp_path / "tsv_friction.parquet")
    assert code == 0 and warnings_said(err) == [], err  # said once
    assert (tmp_path / "tsv_friction.parquet").exists()


def test_the_guides_torque_source_is_chosen_by_its_columns_a_broken_one_beside_it(install, arm, tmp_path, capsys):
    """The guide's ``effort.<joint>`` log written through its source (named: loaded alone), then ``estimate``
    chooses it by its columns among every source (the broken one its one line) and says it."""
    import wbfriction

    plugin = install("torque")
    robot = wbfriction.load_robot("panda")
    with pytest.warns(PluginWarning, match="^torque source 'broken' left out: the entry point 'broken = "):
        log = wbfriction.read_log(arm / "arm.parquet", robot)  # its columns checked against every source
    log.torque_source = plugin.name
    wbfriction.write_log(log, robot, tmp_path / "arm_effort.parquet")
    reread()  # the command line's run reads the entry points anew: its warning line
    code, _, err = run_cli_printed(capsys, "estimate", tmp_path / "arm_effort.parquet", "--robot", "panda", "-o",
                                   tmp_path / "f.parquet")
    assert code == 0 and warnings_said(err) == [plugin.warned], err
    assert "torque: the drives' effort in mN·m (effort.<joint>)" in err


def test_the_guides_contact_model_is_named_by_a_robot_toml_a_broken_one_beside_it(install, tmp_path, capsys):
    """The guide's ``go2_local.toml`` names the guide's model: ``estimate`` reads a trot with it (the broken model,
    named by nothing, never loaded: no line); a TOML naming the broken one is its one ``error:`` line, before the
    log is read."""
    plugin = install("contact")
    toml = re.search(r"<!-- write: go2_local.toml -->\n```toml\n(.*?)```", GUIDE, re.S)
    assert toml is not None and f'contact_model = "{plugin.name}"' in toml[1]
    (tmp_path / "go2_local.toml").write_text(toml[1])
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2_walking", "--duration", "1", "-o",
                                   tmp_path / "trot.parquet")
    assert code == 0 and warnings_said(err) == [], err
    code, _, err = run_cli_printed(capsys, "estimate", tmp_path / "trot.parquet", "--config",
                                   tmp_path / "go2_local.toml", "-o", tmp_path / "f.parquet")
    assert code == 0 and warnings_said(err) == [] and "broken" not in MODELS.loaded(), err
    assert "determined: share of samples, by feet on the ground" in err  # three constraints a foot, as points
    (tmp_path / "broken.toml").write_text(toml[1].replace(plugin.name, "broken"))
    code, _, err = run_cli_printed(capsys, "estimate", tmp_path / "trot.parquet", "--config",
                                   tmp_path / "broken.toml", "-o", tmp_path / "g.parquet")
    assert code == 1 and said(err) == [plugin.error], err
    assert not (tmp_path / "g.parquet").exists()


def test_the_guides_export_target_writes_its_suffix_a_broken_one_beside_it(install, arm, tmp_path, capsys):
    """``export -o panda_friction.csv -o panda_extended.xml``: the CSV's suffix none of the built-in targets' (every
    advertised target loaded, the broken one its one line), both written."""
    plugin = install("target")
    csv, xml = tmp_path / "panda_friction.csv", tmp_path / "panda_extended.xml"
    code, _, err = run_cli_printed(capsys, "export", arm / "params.json", "--robot", "panda", "-o", csv, "-o", xml,
                                     "--include", "weak")  # a 1 s log's fits
    assert code == 0 and warnings_said(err) == [plugin.warned], err
    assert csv.read_text().startswith("joint,F_c,F_v\n") and xml.exists()
    assert f"panda_friction.csv ({plugin.name})" in err


def test_the_guides_rig_claims_the_arm_a_broken_one_beside_it(install, tmp_path, capsys):
    """``simulate --robot panda --rig-option sine_share=0.33``: every rig asked (the broken one its one line), the
    guide's (precedence 25) claims the arm before the built-in one and simulates its sines."""
    plugin = install("rig")
    out = tmp_path / "sine_arm.parquet"
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--rig-option", "sine_share=0.33",
                                   "--duration", "1", "-o", out)
    assert code == 0 and warnings_said(err) == [plugin.warned], err
    assert "1000 samples, sines" in err and out.exists()


def test_the_guides_engine_runs_a_walk_a_broken_one_beside_it(install, tmp_path, capsys):
    """``simulate --robot talos --simulator ideal-fine``: the engine named, loaded; the rig's engines asked (the
    broken one its one line); the walk written. ``--simulator broken`` is its one ``error:`` line."""
    plugin = install("engine")
    out = tmp_path / "fine_walk.parquet"
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "talos", "--simulator", plugin.name, "--steps", "1",
                                   "-o", out)
    assert code == 0 and warnings_said(err) == [plugin.warned], err
    assert out.exists()
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "talos", "--simulator", "broken", "--steps", "1",
                                   "-o", tmp_path / "never.parquet")
    assert code == 1 and said(err) == [plugin.error], err
    assert not (tmp_path / "never.parquet").exists()
