"""Fleets (issue 25): many logs of many robots, batched on Dask, and friction trends per joint."""
