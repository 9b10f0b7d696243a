"""The lab's methods. Each is ``solve(ctx, target) -> Outcome`` (see ``harness.Context`` / ``Outcome``)."""
