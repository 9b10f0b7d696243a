import os

os.environ.setdefault("RERUN_ANALYTICS", "0")


import signal  # noqa: E402

import pytest  # noqa: E402


@pytest.fixture(autouse=True)
def _signal_handlers_restored():
    # A command stopped in process (a sweep given a real Ctrl-C) leaves SIGINT/SIGTERM ignored, as a
    # process on its way out should: the next test gets the handlers this one started with.
    saved = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    yield
    for sig, handler in saved.items():
        signal.signal(sig, handler)
