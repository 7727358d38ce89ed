"""A record's own picture (``shipblock info FILE --figure``) and the RotD50 spectrum it draws."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest

from shipblock.cli import main
from shipblock.errors import ParameterError
from shipblock.intensity import response_spectrum
from shipblock.records.motion import GroundMotion
from shipblock.plot import plot_record_overview, stated_peaks
from shipblock.rotd import ANGLES_DEG, rotd_spectrum
from shipblock.units import STANDARD_GRAVITY as G

matplotlib.use("Agg")

DT = 0.01
PERIODS = np.array([0.05, 0.2, 0.5, 1.0, 3.0])
V2 = Path("/work/shared/records/outside-tests/readv2/ce89486SampleInput.v2")


@pytest.fixture(scope="module")
def noise():
    rng = np.random.default_rng(20100601)  # seeded: the same record every run
    return rng.normal(0.0, 1.0, 3000), rng.normal(0.0, 1.0, 3000)


def test_rotd_of_two_identical_horizontals_is_their_own_spectrum(noise):
    """u(theta) = sqrt(2)|sin(theta + 45 deg)| S_d: over 0..179 deg the 90th and 91st largest
    are those at 45 and 135 deg, sqrt(2) sqrt(2)/2 S_d = S_d; the largest sqrt(2) S_d (45 deg)."""
    a, _ = noise
    single = response_spectrum(a, DT, PERIODS).psa
    rot = rotd_spectrum(a, a, DT, PERIODS)
    np.testing.assert_allclose(rot.rotd50, single, rtol=1e-12)
    np.testing.assert_allclose(rot.rotd100, np.sqrt(2) * single, rtol=1e-12)
    assert ANGLES_DEG.size == 180 and rot.peaks.shape == (PERIODS.size, 180)


def test_rotd_of_one_horizontal_alone_is_its_spectrum_over_root_two(noise):
    """u(theta) = |cos theta| S_d: median over 0..179 deg is cos 45 deg S_d, largest S_d."""
    a, _ = noise
    single = response_spectrum(a, DT, PERIODS).psa
    rot = rotd_spectrum(a, np.zeros_like(a), DT, PERIODS)
    np.testing.assert_allclose(rot.rotd50, single / np.sqrt(2), rtol=1e-12)
    np.testing.assert_allclose(rot.rotd100, single, rtol=1e-12)
    # a rotated copy of the pair has the same RotD50 up to the 1 deg angle grid
    b = noise[1]
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    base = rotd_spectrum(a, b, DT, PERIODS)
    turned = rotd_spectrum(c * a + s * b, -s * a + c * b, DT, PERIODS)
    np.testing.assert_allclose(turned.rotd50, base.rotd50, rtol=2e-3)
    assert np.all(base.rotd50 <= base.rotd100)


def test_rotd_refuses_horizontals_of_different_lengths(noise):
    with pytest.raises(ParameterError, match="same length"):
        rotd_spectrum(noise[0], noise[1][:-1], DT, PERIODS)


def test_record_picture_marks_the_stated_peaks_and_titles_every_panel(noise):
    a, b = noise
    raw = GroundMotion.from_arrays(a, 0.5 * b, dt=DT, name="noise")
    for tr in raw.stream:
        if tr.stats.motion_component == "H1":
            tr.stats.stated_peak_si = 4.0
    assert stated_peaks(raw) == {"H1": 4.0}
    processed = raw.with_stream(raw.stream.copy(), "shipblock.processing.demean()")
    axes = plot_record_overview(raw, processed, periods=PERIODS)
    assert set(axes) == {"H1", "V", "spectra", "fourier"}
    for ax in axes.values():
        assert ax.get_title(loc="left")
    red = [ln for ln in axes["H1"].get_lines() if ln.get_color() == "red"]
    assert sorted(float(ln.get_ydata()[0]) for ln in red) == pytest.approx([-4.0 / G, 4.0 / G])
    labels = [ln.get_label() for ln in axes["spectra"].get_lines()]
    assert "RotD50 (H1, H2)" not in labels  # one horizontal: no RotD50
    title = axes["H1"].figure.get_suptitle()
    assert title.startswith("record noise") and "processed: demean" in title


@pytest.mark.skipif(not V2.exists(), reason="outside test files not present")
def test_info_figure_of_a_real_file(tmp_path, capsys):
    png = tmp_path / "v2.png"
    assert main(["-q", "info", str(V2), "--figure", str(png)]) == 0
    assert f"figure written to {png}" in capsys.readouterr().out
    assert png.exists() and png.stat().st_size > 10_000
    from shipblock.records.reading import read_motion

    peaks = stated_peaks(read_motion(str(V2)))
    assert set(peaks) == {"H1", "H2", "V"}  # the V2 header's own peaks
    axes = plot_record_overview(read_motion(str(V2)), periods=PERIODS)
    labels = [ln.get_label() for ln in axes["spectra"].get_lines()]
    assert "RotD50 (H1, H2)" in labels
