"""IBIG fusion (Manero Contreras & Hajiyev eqs. 9-10) and its minimum-variance counterpart."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim.nav.fusion import IbigFusion, ibig_altitude, ibig_fuse, ibig_weights
from approachsim.seeding import stream


def test_eq9_as_printed() -> None:
    dh, _ = ibig_fuse(10.0, 4.0, 2.0, 1.0, "paper")
    assert dh == pytest.approx((4.0 * 10.0 + 1.0 * 2.0) / 5.0)  # (P1 dH_IIG + P2 dH_IBI) / (P1 + P2)


def test_eq9_leans_to_the_less_certain_channel_and_inverse_variance_does_not() -> None:
    w_iig, w_ibi = ibig_weights(0.3, 25.0, "paper")
    assert w_ibi > 0.95 and w_iig + w_ibi == pytest.approx(1.0)
    w_iig, w_ibi = ibig_weights(0.3, 25.0, "inverse-variance")
    assert w_iig > 0.95 and w_iig + w_ibi == pytest.approx(1.0)


def test_inverse_variance_is_minimum_variance_for_independent_errors() -> None:
    rng = stream(11, 0, "fusion")
    v1, v2, n = 4.0, 1.0, 200_000
    e1 = rng.normal(0, np.sqrt(v1), n)
    e2 = rng.normal(0, np.sqrt(v2), n)
    fused, var = ibig_fuse(e1, np.full(n, v1), e2, np.full(n, v2), "inverse-variance")
    assert var[0] == pytest.approx(v1 * v2 / (v1 + v2))
    assert np.var(fused) == pytest.approx(var[0], rel=0.02)  # 200k samples: ~0.3 % sampling error
    assert np.var(fused) < min(v1, v2)
    # the package's weight is the empirical minimizer: over a grid of convex weights, the sample variance of
    # w e1 + (1 - w) e2 is smallest at the grid point nearest ibig_weights' w_iig (0.2 here)
    w_iig, _ = ibig_weights(v1, v2, "inverse-variance")
    grid = np.linspace(0.0, 1.0, 21)
    best = grid[int(np.argmin([np.var(w * e1 + (1 - w) * e2) for w in grid]))]
    assert best == pytest.approx(float(w_iig), abs=0.05 / 2 + 1e-12)
    paper, pvar = ibig_fuse(e1, np.full(n, v1), e2, np.full(n, v2), "paper")
    assert np.var(paper) == pytest.approx(pvar[0], rel=0.02)
    assert pvar[0] > var[0]


def test_fusion_object_on_state_arrays_and_eq10() -> None:
    rng = stream(12, 0, "fusion")
    x1, x2 = rng.normal(size=(7, 5)), rng.normal(size=(7, 5))
    A = rng.normal(size=(7, 5, 5))
    P1 = A @ np.swapaxes(A, -1, -2) + np.eye(5)
    P2 = 2.0 * P1
    dh, _ = IbigFusion().fuse(x1, P1, x2, P2)
    np.testing.assert_allclose(dh, (P1[:, 0, 0] * x1[:, 0] + P2[:, 0, 0] * x2[:, 0]) / (3 * P1[:, 0, 0]))
    np.testing.assert_allclose(ibig_altitude(1000.0 + x1[:, 0], x1[:, 0]), 1000.0)


def test_bad_inputs_are_refused() -> None:
    with pytest.raises(ValueError, match="weighting"):
        IbigFusion(weighting="mean")
    with pytest.raises(ValueError, match="weighting"):
        ibig_weights(1.0, 1.0, "equal")
    with pytest.raises(ValueError, match="positive"):
        ibig_weights(0.0, 1.0)
