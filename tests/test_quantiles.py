"""The chi-square and normal laws of :mod:`stewartid.identification.quantiles` against SciPy's."""

import numpy as np
import pytest
from scipy.special import chdtrc, chdtri, ndtr, ndtri

from stewartid.identification.quantiles import (
    chi2_tail,
    chi2_upper_quantile,
    normal_cdf,
    normal_upper_quantile,
)


@pytest.mark.parametrize("dof", [1, 2, 3, 4, 7, 12, 40, 151])
@pytest.mark.parametrize("level", [0.3, 0.05, 0.01, 1e-3, 1e-8])
def test_chi2_quantile_matches_scipy(dof, level):
    # the tail is a sum of positive terms, each to a few ulps: the point to ~1e-14 where the
    # tail is not near 1 (there its slope makes the point ill-conditioned)
    assert chi2_upper_quantile(dof, level) == pytest.approx(chdtri(dof, level), rel=1e-12)


@pytest.mark.parametrize("dof", [1, 2, 5, 30])
def test_chi2_tail_matches_scipy(dof):
    x = np.linspace(0.0, 8.0 * dof + 40.0, 57)
    ours = np.array([chi2_tail(v, dof) for v in x])
    np.testing.assert_allclose(ours, chdtrc(dof, x), rtol=1e-13, atol=1e-300)


def test_chi2_refuses_fractional_dof_and_bad_levels():
    with pytest.raises(ValueError, match="whole number"):
        chi2_tail(1.0, 2.5)
    with pytest.raises(ValueError, match=r"level in \(0, 1\)"):
        chi2_upper_quantile(3, 1.0)


def test_normal_law_matches_scipy():
    z = np.linspace(-12.0, 12.0, 4801)
    # both libraries' erfc lose a few ulps per unit of z^2 / 2 in the far lower tail
    np.testing.assert_allclose(normal_cdf(z), ndtr(z), rtol=1e-13, atol=0)
    # saturated ends are the doubles SciPy gives
    ends = np.array([-40.0, 8.3, 9.0, 50.0])
    np.testing.assert_array_equal(normal_cdf(ends), ndtr(ends))
    for level in (0.4, 0.05, 1e-4, 1e-9):
        assert normal_upper_quantile(level) == pytest.approx(ndtri(1.0 - level), rel=1e-14)
