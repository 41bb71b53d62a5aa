"""Checks of the HTML report shared by its tests (tests/report): its figures as drawn (every ``ok`` fit inside its
samples, no two texts overlapping by matplotlib's own text boxes, time axes in seconds from each run's start) and
its page as headless Chromium shows it (Debian's ``chromium`` and ``chromium-driver``, which ``.ci/run`` installs):
issue 67."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from wbfriction.report.build import Report, acceleration_spectra
from wbfriction.report.friction_figures import drawn_fit
from wbfriction.report.html import report_figure
from wbfriction.report.timeaxis import log_runs

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"


def off_samples(est, i: int, drawn: tuple[str, np.ndarray, np.ndarray], bins: int = 12) -> list[str]:
    """Where a drawn fit (:func:`~wbfriction.report.friction_figures.drawn_fit`) leaves its valid samples: beyond
    their range of ``tau_f`` (by more than a tenth of it), or, in one of ``bins`` bins of velocity holding 10 samples
    or more, its median beyond the range of the bin's samples (by a tenth of the whole range); the bin across zero
    velocity left out (the Coulomb step, where a sign model's jump and a smooth transition part by design). Empty: it
    lies in its cloud."""
    _, qd, tau = drawn
    m = est.valid[:, i]
    x, y = est.qd[m, i], est.tau_f[m, i]
    margin = 0.1 * float(np.ptp(y))
    out = []
    if tau.min() < y.min() - margin or tau.max() > y.max() + margin:
        out.append(f"drawn {tau.min():.2f}..{tau.max():.2f} N·m, samples {y.min():.2f}..{y.max():.2f}")
    edges = np.linspace(x.min(), x.max(), bins + 1)
    for lo, hi in zip(edges[:-1], edges[1:]):
        if lo < 0 < hi:
            continue
        s, d = (x >= lo) & (x <= hi), (qd >= lo) & (qd <= hi)
        if s.sum() >= 10 and d.any():
            median = float(np.median(tau[d]))
            if not y[s].min() - margin <= median <= y[s].max() + margin:
                out.append(f"qd {lo:.2f}..{hi:.2f} rad/s: drawn {median:.2f}, samples {y[s].min():.2f}.."
                           f"{y[s].max():.2f} N·m")
    return out


def check_fits_drawn_in_their_samples(report: Report) -> list[str]:
    """Every joint whose fit is ``ok``: its drawn fit within its samples (:func:`off_samples`); returns those
    checked."""
    checked = []
    for joint in report.moved:
        fit = report.fits.get(joint)
        if fit is None or not fit.verdict().ok:
            continue
        i = report.est.joints.index(joint)
        drawn = drawn_fit(report.est, i, fit)
        assert drawn is not None, joint
        assert not off_samples(report.est, i, drawn), (joint, off_samples(report.est, i, drawn))
        checked.append(joint)
    return checked


def _texts(fig) -> list:
    """The texts a drawn figure shows, with their boxes [px]: titles, axis labels, legends, figure texts, and the
    tick labels inside their axis's view."""
    from matplotlib.text import Text

    shown = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for axis, view in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            lo, hi = sorted(view)
            for tick in axis.get_major_ticks():
                if lo - 1e-9 * (hi - lo) <= tick.get_loc() <= hi + 1e-9 * (hi - lo):
                    shown += [t for t in (tick.label1, tick.label2) if t.get_visible() and t.get_text()]
        shown += [t for t in (ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label,
                              ax.xaxis.get_offset_text(), ax.yaxis.get_offset_text())
                  if t.get_visible() and t.get_text()]
        if ax.get_legend() is not None:
            shown += [t for t in ax.get_legend().get_texts() if t.get_text()]
    shown += [t for t in fig.texts if isinstance(t, Text) and t.get_visible() and t.get_text()]
    shown += [t for t in (fig._suptitle, fig._supxlabel, fig._supylabel) if t is not None and t.get_text()]
    for legend in fig.legends:
        shown += [t for t in legend.get_texts() if t.get_text()]
    return list({id(t): t for t in shown}.values())  # each once (a suptitle is one of fig.texts too)


def text_overlaps(fig) -> list[tuple[str, str]]:
    """Pairs of texts of ``fig`` whose boxes overlap by more than 1 px each way, measured by matplotlib's renderer
    (the figure drawn at the report's resolution)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from wbfriction.report.figures import REPORT_DPI

    canvas = FigureCanvasAgg(fig)
    fig.set_dpi(REPORT_DPI)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in _texts(fig)]
    return [(a, b) for k, (a, ba) in enumerate(boxes) for b, bb in boxes[k + 1:]
            if min(ba.x1, bb.x1) - max(ba.x0, bb.x0) > 1 and min(ba.y1, bb.y1) - max(ba.y0, bb.y0) > 1]


def check_figures(report: Report) -> None:
    """The report's figures as the page shows them: no two texts overlapping; every axis over time in seconds from
    its run's start (from 0 up to the longest run's duration, no offset such as ``1e9``)."""
    est = report.est
    runs = log_runs(est.time)
    longest = max(float(est.time[r.rows.stop - 1] - est.time[r.rows.start]) for r in runs)
    spectra = acceleration_spectra(est)
    for joint in [None, *report.moved]:
        fig = report_figure(report, joint, spectra)
        assert not text_overlaps(fig), (joint, text_overlaps(fig))
        over_time = [ax for ax in fig.axes if ax.get_label().startswith("time")]
        assert joint is None or len(over_time) >= min(len(runs), 4) + 1, joint  # panel (b)'s runs, panel (c)
        for ax in over_time:
            x = np.concatenate([np.asarray(line.get_xdata(), dtype=float) for line in ax.get_lines()
                                if np.ndim(line.get_xdata()) and len(line.get_xdata()) > 2])
            assert np.nanmin(x) >= 0 and np.nanmax(x) <= longest + 1e-6, (joint, np.nanmin(x), np.nanmax(x))
            assert not ax.xaxis.get_offset_text().get_text(), joint


_PAGE_TEXT = """
const rects = [], small = [];
const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
let node, k = 0;
while ((node = walker.nextNode())) {
  const text = node.textContent.trim();
  const el = node.parentElement;
  if (!text || !el.checkVisibility()) continue;
  const size = parseFloat(getComputedStyle(el).fontSize);
  if (size < 11) small.push([text.slice(0, 40), size]);
  const range = document.createRange();
  range.selectNodeContents(node);
  for (const r of range.getClientRects())
    if (r.width > 0 && r.height > 0)
      rects.push([k, r.left, r.top + scrollY, r.right, r.bottom + scrollY, text.slice(0, 40)]);
  k++;
}
rects.sort((a, b) => a[2] - b[2]);
const overlaps = [];
for (let i = 0; i < rects.length; i++)
  for (let j = i + 1; j < rects.length && rects[j][2] < rects[i][4] - 1; j++) {
    const a = rects[i], b = rects[j];
    if (a[0] === b[0]) continue;
    const w = Math.min(a[3], b[3]) - Math.max(a[1], b[1]), h = Math.min(a[4], b[4]) - Math.max(a[2], b[2]);
    if (w > 1 && h > 1) overlaps.push([a[5], b[5]]);
  }
const images = [...document.images].map(im => [im.id, im.complete, im.naturalWidth, im.getBoundingClientRect().width]);
const cut = [...document.querySelectorAll("table")].filter(t => t.getBoundingClientRect().width > 0)
  .map(t => [t.id || t.className || t.rows[0].textContent.slice(0, 40), t.scrollWidth,
             (t.closest(".scroll") || document.body).clientWidth])
  .filter(([, table, room]) => table > room);
return {small, overlaps, texts: rects.length, images, width: document.documentElement.scrollWidth, cut};
"""
"""What the page shows at 1400 px, measured in the browser: texts under 11 px, pairs of texts whose boxes overlap,
the images (id, loaded, natural width, width shown), the page's width and the tables wider than the room they
have (their columns cut, to be scrolled to)."""


CHROMIUM_MISSING = pytest.mark.skipif(not (Path(CHROMIUM).exists() and Path(CHROMEDRIVER).exists()),
                                      reason="Debian's chromium and chromium-driver are not both installed (.ci/run "
                                             "installs them)")


def render_in_chromium(report_file: Path, tmp_path: Path) -> dict:
    """The page at 1400 px in headless Chromium, measured (:data:`_PAGE_TEXT`), after checking that it loaded
    without an error; screenshots to ``tmp_path``."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--disable-dev-shm-usage", f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1400,1000",
                 "--hide-scrollbars"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    try:
        driver.get(report_file.as_uri())
        assert driver.execute_script("return document.readyState") == "complete"
        assert "wbfriction report" in driver.title
        severe = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        assert not severe, severe
        page = driver.execute_script(_PAGE_TEXT)
        for k, y in enumerate(range(0, driver.execute_script("return document.body.scrollHeight"), 900)):
            driver.execute_script(f"window.scrollTo(0, {y})")
            driver.save_screenshot(str(tmp_path / f"report_{k:02d}.png"))
        return page
    finally:
        driver.quit()


def check_page(page: dict, texts: int) -> dict[str, tuple[bool, int, int]]:
    """No text under 11 px, no two texts overlapping, nothing wider than the window, no table wider than its room,
    every figure loaded and shown at its own size (its fonts, at least 11 px, stay so); at least ``texts`` texts.
    Returns the images: id -> (loaded, natural width, width shown)."""
    assert page["texts"] > texts
    assert not page["small"], page["small"][:10]
    assert not page["overlaps"], page["overlaps"][:10]
    assert page["width"] <= 1400
    assert not page["cut"], page["cut"]  # every table whole at 1400 px (issue 39)
    images = {i: (loaded, natural, shown) for i, loaded, natural, shown in page["images"]}
    for i, (loaded, natural, shown) in images.items():
        assert loaded and natural >= 1000 and shown == natural, (i, natural, shown)
    return images
