"""Studies: many runs of one structure over a grid of parameters or a set of records, on Dask.

axes.py (what a parameter changes) · task.py (one run -> one row) · drivers.py (grid, threshold
search) · runner.py (Dask) · store.py (rows on disk, resume) · study.py (the whole study) · plan.py
(the command's options checked into a study) · fragility.py (lognormal fit) · plots.py (PNG). ``masonry
sweep`` is in :mod:`masonrycli.cli.sweep`.
"""
