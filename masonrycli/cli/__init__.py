"""The ``masonry`` command line: thin Typer commands that turn options into a Scenario and errors into one line.

- ``app``: the Typer app and its commands (simulate, run, check, build, inspect, limit, docs).
- ``options``: the option groups shared by the commands.
- ``messages``: how the command line talks (consoles, one-line errors and warnings).
- ``sweep``: ``masonry sweep`` (a study on Dask); ``export``: ``masonry export``; ``docs``: ``masonry docs``.
"""
