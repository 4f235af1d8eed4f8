"""Monte Carlo campaigns, trade studies and regressions: executors (local pool, Dask) and result storage."""
