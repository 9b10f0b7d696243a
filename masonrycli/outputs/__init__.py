"""What a run leaves behind: files written safely, the history, the terminal report and the exports.

- ``files``: output files checked before step 1, written under a temporary name, renamed when complete.
- ``frame``: one recorded frame; ``sinks``: what a run hands its frames to.
- ``history``: the history file (``.npz``); ``inspect_history``: ``masonry inspect H.npz``;
  ``export``: ``masonry export`` (a history as CSV).
- ``report``: the progress bar and summary table.
"""
