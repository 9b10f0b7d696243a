"""What to simulate and how: scenarios, their TOML files, the built-in structures and the support motions.

- ``scenario``: the Scenario (structure, material, motions, run settings), checked; ``sampling``: its
  supports against its time step.
- ``builtin``: the paper's structures with their loadings; ``structure``: blocks and supports, checked.
- ``target``: a command's TARGET (a built-in name or a file); ``record_option``: a --record and the
  supports it shakes.
- ``motion``: imposed support motions; ``values``: checked input values and their TOML spelling.
- ``toml_file``: the scenario file reader and writer; ``toml_bodies``: its [[block]] and [[support]] tables;
  ``toml_lines``: the line of a file an error is about.
- ``caveats``: what a valid scenario may still have wrong (one warning line each).
"""
