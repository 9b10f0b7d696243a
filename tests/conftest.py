import os

os.environ.setdefault("RERUN_ANALYTICS", "0")
# The tests set the console's width themselves (COLUMNS in a CliRunner's env, or none: 80). One inherited from
# the caller was read by rich when cli/messages.py made its Console at import and then fixed: a pytest-xdist
# worker starts with COLUMNS=80 LINES=24 (readline sets them) and test_limit_cli's 250-column tables wrapped.
for _name in ("COLUMNS", "LINES"):
    os.environ.pop(_name, None)


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
