"""The filter study (thesis 7.1-7.2, Fig. 7.2): a small grid of noise levels and schemes."""

from __future__ import annotations

import pyarrow.parquet as pq
import pytest

from wbfriction.signals.options import FilterOptions
from wbfriction.studies.filters import Scheme, run_filter_study


@pytest.mark.slow
def test_filter_study_writes_its_table_and_figure(talos, tmp_path):
    """A small study (2 steps, exact and 1e-4 rad, two schemes): rows for every pair, the
    noisy central differences far worse than the smoothed ones, files written. Two steps do not determine F_v
    (its standard error there is hundreds of percent), so the schemes are compared on F_c and tau_os, not by the
    study's score, which takes F_v in."""
    schemes = (Scheme("central", "central"), Scheme("savgol 101", "savgol", FilterOptions(window=101)))
    result = run_filter_study(talos, tmp_path, steps=2, levels=(None, 1e-4), schemes=schemes, workers=1)
    assert [(r.position_std, r.scheme) for r in result.rows] == [(None, "central"), (None, "savgol 101"),
                                                                 (1e-4, "central"), (1e-4, "savgol 101")]
    noisy = {r.scheme: r for r in result.rows if r.position_std == 1e-4}
    assert noisy["central"].rms_error > 20 * noisy["savgol 101"].rms_error
    for name in ("F_c", "tau_os"):
        assert noisy["savgol 101"].worst[name] < 0.2 * noisy["central"].worst[name], name
    assert pq.read_table(tmp_path / "filter_study.parquet").num_rows == 4
    assert (tmp_path / "filter_curves.png").stat().st_size > 1000
