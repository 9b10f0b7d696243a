"""What the blocks and contacts mean to an engineer, computed from a step's state (numpy only).

- ``tensors``: the cell stress and strain tensors of Chetouane et al. (2003) and their invariants.
- ``mechanism``: joint opening, sliding and hinges; ``joint_forces``: one resultant per joint.
- ``collapse``: collapse, defined and watched step by step.
"""
