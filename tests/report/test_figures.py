"""The figures: PNG files that are the same bytes for the same input, the panels each figure promises, and
the helpers they are drawn with."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import drawn_texts, text_overlaps
from wbfriction.fit.joints import fit_estimate
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import FrictionParams
from wbfriction.report.figures import REPORT_DPI, png_bytes, save_png
from wbfriction.report.friction_figures import friction_curves_figure, friction_overview_figure, joint_figure
from wbfriction.report.timeaxis import widest_run

TRUE = FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=0.5, a=40.0)


@pytest.fixture(scope="module")
def estimate() -> FrictionEstimate:
    """Two joints over 4 s at 1 kHz: 'moving' follows model (3.5) in its valid samples (single support,
    1-3 s); 'still' has no valid sample."""
    t = np.arange(4000) * 1e-3
    qd = np.column_stack([np.sin(2 * np.pi * 0.5 * t), np.zeros_like(t)])
    tau_f = np.column_stack([TRUE.torque(qd[:, 0]), np.zeros_like(t)])
    single = (t >= 1.0) & (t < 3.0)
    valid = np.column_stack([single, np.zeros_like(single)])
    contact = np.column_stack([np.ones_like(t, dtype=bool), ~single])
    return FrictionEstimate(joints=("moving", "still"), time=t, qd=qd, tau_f=tau_f, valid=valid,
                            phase=np.where(single, "single", "double"), unique=single, contact=contact,
                            contact_frames=("left", "right"), qdd=np.zeros_like(qd), delta_qdd=np.zeros_like(qd),
                            tau_f_true=tau_f.copy())


def test_png_bytes_are_a_png_and_the_same_for_the_same_figure(estimate):
    fits = {f.joint: f for f in fit_estimate(estimate)}
    one = png_bytes(joint_figure(estimate, "moving", fits["moving"], TRUE))
    two = png_bytes(joint_figure(estimate, "moving", fits["moving"], TRUE))
    assert one[:8] == b"\x89PNG\r\n\x1a\n"
    assert one == two


def test_joint_figure_has_its_four_panels_even_without_valid_samples(estimate):
    fig = joint_figure(estimate, "moving", None, TRUE, (np.linspace(0, 50, 11), np.ones(11), 10.0))
    assert len(fig.axes) >= 4  # (d) may add a twin axis for qd
    titles = [ax.get_title() for ax in fig.axes]
    assert any(t.startswith("(a)") for t in titles) and any(t.startswith("(b)") for t in titles)
    fig = joint_figure(estimate, "still", None, None)  # nothing valid: drawn, not raised
    assert len(fig.axes) >= 4


def test_overview_marks_flagged_joints_each_on_its_own_axes(estimate):
    fig = friction_overview_figure(estimate, ["moving", "still"], {}, {"moving": TRUE}, flagged={"still"},
                                   labels={"moving": "right knee"})
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title() for ax in visible] == ["right knee", "still"]
    red = visible[1].title.get_color()
    assert red != visible[0].title.get_color()
    assert not visible[0].get_shared_y_axes().joined(visible[0], visible[1])  # a knee does not squash an ankle


def test_files_are_written_whole(estimate, tmp_path):
    fits = fit_estimate(estimate)
    friction_curves_figure(estimate, fits, tmp_path / "curves.png")
    assert (tmp_path / "curves.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(Exception, match="does not exist"):
        save_png(joint_figure(estimate, "moving", None, None), tmp_path / "missing" / "x.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["curves.png"]  # no temporary file left


@pytest.mark.parametrize(("mask", "x", "expected"), [
    ([0, 1, 1, 0, 1, 1, 1, 0], [0, 0, 5, 0, 0, 1, 2, 0], slice(1, 3)),  # widest range of x, not the longest run
    ([1, 1, 1, 0, 1], [0, 1, 2, 0, 9], slice(0, 3)),  # a run of one sample spans no range
    ([0, 0, 0], [1, 2, 3], slice(0, 0)),
])
def test_widest_run(mask, x, expected):
    assert widest_run(np.array(mask, dtype=bool), np.array(x, dtype=float)) == expected


def test_report_figures_are_readable_at_their_own_size(estimate):
    """The report's figures at 1400 px (shown at their own width, REPORT_WIDTH x REPORT_DPI px): every text at
    least 11 px high, no two texts overlapping (tick labels, titles, legends, axis labels), no offset text."""
    fits = {f.joint: f for f in fit_estimate(estimate)}
    spectrum = (np.linspace(0, 500, 501), np.exp(-np.linspace(0, 5, 501)), 262.0)  # a cutoff beyond 50 Hz
    for fig in (joint_figure(estimate, "moving", fits["moving"], TRUE, spectrum),
                joint_figure(estimate, "still", None, None),
                friction_overview_figure(estimate, ["moving", "still", "moving"], fits, {"moving": TRUE},
                                         labels={"moving": "right knee"})):
        assert fig.get_figwidth() * REPORT_DPI <= 1200
        fig.set_dpi(REPORT_DPI)
        texts = drawn_texts(fig)
        assert texts
        small = [(t, round(px, 1)) for t, _, px in texts if px < 11]
        assert not small, small
        assert not text_overlaps(texts), text_overlaps(texts)
        assert not [t for t, _, _ in texts if t.startswith(("1e", "+", "−1e"))], "an offset text"


def test_the_spectrum_panel_reaches_a_cutoff_beyond_50_hz(estimate):
    spectrum = (np.linspace(0, 500, 501), np.ones(501), 262.0)
    fig = joint_figure(estimate, "moving", None, None, spectrum)
    panel = next(ax for ax in fig.axes if ax.get_title().startswith("(d)"))
    assert panel.get_xlim()[1] >= 262.0
    assert "amplitude [rad/s²]" == panel.get_ylabel()


def _installed_font_draws(text: str) -> bool:
    """Whether some font matplotlib knows has a glyph for every character of ``text`` (read from the fonts)."""
    from matplotlib import font_manager
    from matplotlib.ft2font import FT2Font

    for entry in font_manager.fontManager.ttflist:
        try:
            charmap = FT2Font(entry.fname).get_charmap()
        except (OSError, RuntimeError):
            continue
        if all(ord(c) in charmap for c in text):
            return True
    return False


def test_a_joint_name_no_font_draws_is_drawn_readable_without_a_warning(estimate):
    """Issue 53, class 15: CJK joint names drew as boxes, with matplotlib's 'Glyph ... missing from font(s)' on
    standard error for each. With a font that has the glyphs the name is drawn in it; without, the joint is drawn
    as 'joint #<index>' and the figure says so once; no warning either way."""
    import dataclasses
    import warnings

    knee = "右膝关节"
    est = dataclasses.replace(estimate, joints=("still", knee))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning fails the test
        fig = friction_overview_figure(est, [knee, "still"], {}, {}, labels={knee: knee, "still": "still"})
        png_bytes(fig)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    titles = [ax.get_title() for ax in visible]
    if _installed_font_draws(knee):
        assert titles == [knee, "still"]
    else:
        assert titles == ["joint #1", "still"]  # its index among the estimate's joints
        said = [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text")) if "joint #i" in t.get_text()]
        assert len(said) == 1 and "no installed font" in said[0]


def test_the_drawn_fit_passes_through_the_samples_it_predicts_with_its_terms_and_family():
    """Issue 63: the KUKA's lwr_6 was drawn at +2.3 N·m where its samples sat at 0-0.5 (a velocity curve without
    the terms its fit kept) and every legend said ``fit (coulomb-viscous)``. Constructed: a joint whose friction is a
    Stribeck curve with an offset and a position ripple of 0.4 N·m, exactly; another a Coulomb-viscous curve. The
    drawn data (not the picture) of the first pass through every valid sample to rounding; the second's curve
    meets its samples; each panel's legend names its own model."""
    from wbfriction.fit.result import FitResult
    from wbfriction.fit.terms import TermFit
    from wbfriction.friction.models import CoulombViscousParams, StribeckParams

    t = np.arange(3000) * 1e-3
    qd = np.column_stack([np.sin(2 * np.pi * 0.7 * t), 0.8 * np.cos(2 * np.pi * 0.4 * t)])
    q = np.column_stack([0.5 + 0.3 * np.cos(2 * np.pi * 0.7 * t), np.sin(t)])
    stribeck = StribeckParams(F_v=0.3, F_c=0.2, F_s=0.35, v_s=0.1, tau_os=0.25)
    terms = TermFit(stribeck, kept=("ripple",), harmonics=1, coefficients={"ripple_sin1": 0.4, "ripple_cos1": -0.3},
                    q_range=(0.2, 0.8))
    plain = CoulombViscousParams(F_v=0.5, F_c=0.3, tau_os=-0.1)
    tau_f = np.column_stack([-(stribeck.f(qd[:, 0]) + 0.4 * np.sin(q[:, 0]) - 0.3 * np.cos(q[:, 0])),
                             plain.torque(qd[:, 1])])
    valid = np.ones_like(qd, dtype=bool)
    est = FrictionEstimate(joints=("lwr_6", "other"), time=t, qd=qd, tau_f=tau_f, valid=valid,
                           phase=np.full(t.size, "single"), unique=valid[:, 0], contact=valid,
                           contact_frames=("left", "right"), qdd=np.zeros_like(qd), delta_qdd=np.zeros_like(qd), q=q)
    fits = {"lwr_6": FitResult(joint="lwr_6", n_samples=3000, params=stribeck, success=True, terms=terms),
            "other": FitResult(joint="other", n_samples=3000, params=plain, success=True)}
    fig = friction_overview_figure(est, ["lwr_6", "other"], fits, {})
    for ax, i, name in zip(fig.axes, (0, 1), ("fit: stribeck + ripple", "fit: coulomb-viscous")):
        line = next(ln for ln in ax.get_lines() if ln.get_label().startswith("fit: "))
        assert line.get_label() == name
        assert [text.get_text() for text in ax.get_legend().get_texts()] == [name]
        x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
        if i == 0:  # a dot per valid sample, at its own friction
            assert np.array_equal(x, qd[:, 0]) and np.allclose(y, tau_f[:, 0], atol=1e-12)
        else:  # the curve, where the samples are (away from the Coulomb jump, between two of its 400 points)
            away = np.abs(qd[:, 1]) > 0.01
            assert np.allclose(np.interp(qd[away, 1], x, y), tau_f[away, 1], atol=1e-9)
    velocity_only = stribeck.torque(qd[:, 0])  # what was drawn before: off the samples by the offset and ripple
    assert np.max(np.abs(velocity_only - tau_f[:, 0])) > 0.2


def test_runs_of_a_log_stamped_in_epoch_seconds():
    """Issue 67: two runs of 25 s at 200 Hz, 29 min apart, stamped in Unix epoch seconds (the KUKA's): two runs,
    the second from 29 min 25 s; each sample's time from its run's start; a 0.1 s dropout in a run is no new run."""
    from wbfriction.report.timeaxis import log_runs, run_title, time_from_start

    run = np.arange(5000) * 0.005
    t = 1.46e9 + np.r_[run, run + 25.0 + 29 * 60]
    runs = log_runs(t)
    assert [(r.rows.start, r.rows.stop) for r in runs] == [(0, 5000), (5000, 10000)]
    assert runs[1].start == pytest.approx(25.0 + 29 * 60, abs=1e-6)
    assert run_title(1, runs[1]) == "run 2, from 29.4 min"
    assert np.allclose(time_from_start(t), np.r_[run, run], atol=1e-5)
    dropout = np.r_[run[:2000], run[2020:]]  # 20 samples lost: a step of 0.105 s, 0.4 % of the run
    assert len(log_runs(dropout)) == 1


def test_time_panels_one_per_run():
    """Two runs: two axes side by side, each from 0 to its duration, a shared torque axis; five runs (more than
    MAX_PANELS): one axes of recorded time, the runs one after the other."""
    from matplotlib.figure import Figure

    from wbfriction.report.timeaxis import MAX_PANELS, time_panels

    run = np.arange(2000) * 0.01
    for n in (1, 2, MAX_PANELS + 1):
        t = 1.46e9 + np.concatenate([run + k * 3600.0 for k in range(n)])
        fig = Figure()
        axes = time_panels(fig, fig.add_gridspec(1, 1)[0, 0], t, lambda ax, rows, x: ax.plot(x, np.sin(x)))
        assert len(axes) == (n if n <= MAX_PANELS else 1)
        for ax in axes:
            x = np.concatenate([line.get_xdata() for line in ax.get_lines()])
            assert x.min() == 0 and x.max() == pytest.approx(19.99 if len(axes) > 1 else 19.99 * n + 0.01 * (n - 1))
        png_bytes(fig)
