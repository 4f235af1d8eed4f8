"""Statistics of an error over Monte Carlo runs, with confidence intervals for the number of runs.

* RMS (bias included): the contract's "1 sigma". Interval: chi-square with n degrees of freedom,
  n rms^2 / sigma^2 ~ chi2(n) for zero-mean Gaussian errors (the interval is exact there and
  approximate with a bias).
* 95th percentile of |error| (the ICAO 95 % accuracy figure), numpy's linear interpolation; its interval
  is distribution-free from order statistics: ranks (l, u) with P(X_(l) <= q95 <= X_(u)) >= level from
  the binomial(n, 0.95) law (the upper end is +inf when n is too small to bound it).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy import stats as sps


@dataclass(frozen=True)
class ErrorStats:
    """Statistics of one error over n runs (same unit as the input)."""

    n: int
    rms: float
    rms_lo: float
    rms_hi: float
    mean: float
    std: float
    p95: float
    p95_lo: float
    p95_hi: float

    def scaled(self, factor: float) -> ErrorStats:
        """The same statistics in another unit (every value times `factor`)."""
        return ErrorStats(self.n, *(getattr(self, k) * factor for k in list(asdict(self))[1:]))


def rms_interval(rms: float, n: int, level: float = 0.95) -> tuple[float, float]:
    """Two-sided chi-square interval of the RMS of n zero-mean Gaussian samples: sqrt(n rms^2 / chi2(n))."""
    a = 1.0 - level
    lo = math.sqrt(n * rms**2 / sps.chi2.ppf(1.0 - a / 2.0, n))
    hi = math.sqrt(n * rms**2 / sps.chi2.ppf(a / 2.0, n))
    return lo, hi


def quantile_ranks(n: int, p: float = 0.95, level: float = 0.95) -> tuple[int | None, int | None]:
    """1-based order-statistic ranks (l, u) bracketing the p-quantile with coverage >= level.

    Symmetric in tail probability: l is the largest rank with P(B < l) <= (1-level)/2, u the smallest with
    P(B >= u) <= (1-level)/2, B ~ binomial(n, p). None where no rank in 1..n qualifies.
    """
    a2 = (1.0 - level) / 2.0
    ks = np.arange(0, n + 1)
    cdf = sps.binom.cdf(ks, n, p)  # cdf[k] = P(B <= k)
    # P(X_(l) <= q) = P(B >= l) ; P(B < l) = cdf[l-1]
    lows = [r for r in range(1, n + 1) if cdf[r - 1] <= a2]
    # P(X_(u) >= q) = P(B < u) = cdf[u-1] ; need P(B >= u) = 1 - cdf[u-1] <= a2
    highs = [r for r in range(1, n + 1) if 1.0 - cdf[r - 1] <= a2]
    return (max(lows) if lows else None, min(highs) if highs else None)


def error_stats(x: np.ndarray, level: float = 0.95) -> ErrorStats:
    """RMS, mean, std (ddof 1), 95th percentile of |x| and their intervals, over the finite values of x."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    n = int(x.size)
    if n == 0:
        nan = float("nan")
        return ErrorStats(0, nan, nan, nan, nan, nan, nan, nan, nan)
    rms = float(np.sqrt(np.mean(x**2)))
    lo, hi = rms_interval(rms, n, level)
    a = np.sort(np.abs(x))
    p95 = float(np.percentile(a, 95.0))
    l, u = quantile_ranks(n, 0.95, level)
    return ErrorStats(
        n=n,
        rms=rms,
        rms_lo=lo,
        rms_hi=hi,
        mean=float(np.mean(x)),
        std=float(np.std(x, ddof=1)) if n > 1 else float("nan"),
        p95=p95,
        p95_lo=float(a[l - 1]) if l is not None else 0.0,
        p95_hi=float(a[u - 1]) if u is not None else float("inf"),
    )
