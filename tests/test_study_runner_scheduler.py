"""``--scheduler ADDRESS`` (masonrycli/study/scheduler.py): an address where no Dask scheduler answers (silent,
talking another protocol, dropping the connection, nothing listening, no such host) is refused in one line
after a short probe, a lookup that may pass on a retry is left to the client, and a client that connects
after the command gave up (or a Ctrl-C) is closed, one in time returned open."""

from __future__ import annotations

import re
import time

import pytest

from masonrycli.study import runner, scheduler


class Listener:
    """A TCP service on a free local port that is not a Dask scheduler: it accepts and says ``greeting``
    (or nothing) and keeps the connection open."""

    def __init__(self, greeting: bytes):
        import socket
        import threading

        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen()
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        self.greeting, self.held = greeting, []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.held.append(conn)
            if self.greeting:
                conn.sendall(self.greeting)

    def close(self):
        self.sock.close()
        for conn in self.held:
            conn.close()


@pytest.mark.parametrize(
    "greeting",
    [b"", b"SSH-2.0-OpenSSH_9.2\r\n" * 4],
    ids=["silent (an HTTP port waiting for a request)", "talking (another protocol)"],
)
def test_a_scheduler_address_where_no_dask_scheduler_answers_is_one_line(greeting, monkeypatch):
    # Before: an HTTP server on the port (the dashboard's 8787, say) held the command forever, Client's own
    # timeout notwithstanding; a service that spoke first ended in a MemoryError traceback (exit 1), Dask
    # reading its bytes as a frame count ("Unable to allocate 3.07 EiB").
    import threading
    import time

    from masonrycli.errors import InputError

    monkeypatch.setattr(scheduler, "CONNECT_TIMEOUT", 2.0)
    monkeypatch.setattr(scheduler, "CONNECT_GRACE", 1.0)
    listener = Listener(greeting)
    start = time.monotonic()
    try:
        with pytest.raises(InputError, match=r"^--scheduler tcp://127\.0\.0\.1:\d+: ") as raised:
            runner.open_cluster(listener.address, None)
    finally:
        listener.close()
    took = time.monotonic() - start
    for thread in threading.enumerate():  # the given-up connect ends with the listener: not in a later test
        if thread.name == "masonry-scheduler-connect":
            thread.join(10.0)
    assert took < 2.0 + scheduler.CONNECT_GRACE + 5.0
    assert "\n" not in str(raised.value) and "Dask scheduler" in str(raised.value)


def test_a_listener_that_says_nothing_is_refused_after_the_probe(monkeypatch):
    # the dashboard's port 8787 (HTTP, waiting for a request) held the command for Client's 20 s and the
    # grace after it, 30 s; a scheduler greets as it accepts, so the probe's wait tells
    from masonrycli.errors import InputError

    monkeypatch.setattr(scheduler, "PROBE_TIMEOUT", 1.0)
    listener = Listener(b"")
    start = time.monotonic()
    try:
        with pytest.raises(InputError) as raised:
            runner.open_cluster(listener.address, None)
    finally:
        listener.close()
    assert time.monotonic() - start < 1.0 + 3.0
    assert str(raised.value) == (
        f"--scheduler {listener.address}: no Dask scheduler answered within 1 s (something listens there but does "
        "not speak Dask: the dashboard's port, or another service?)"
    )


def test_a_client_that_failed_to_connect_is_collected_before_the_command_goes_on(monkeypatch):
    # A half-made Client left to a later garbage collection ran its finaliser inside the next LocalCluster's
    # start, under distributed's class-wide LoopRunner lock that the finaliser also takes: the process hung
    # (CI at 72dc25a, this module's log-level test). Nothing may be left for a later collection.
    import gc

    from distributed import Client

    from masonrycli.errors import InputError

    monkeypatch.setattr(scheduler, "CONNECT_TIMEOUT", 2.0)
    listener = Listener(b"SSH-2.0-OpenSSH_9.2\r\n" * 4)  # Client fails on its answer
    gc.collect()
    gc.disable()  # only the command's own collection counts
    try:
        before = {id(o) for o in gc.get_objects() if isinstance(o, Client)}
        with pytest.raises(InputError, match="not a Dask scheduler"):
            runner.open_cluster(listener.address, None)
        left = [o for o in gc.get_objects() if isinstance(o, Client) and id(o) not in before]
    finally:
        gc.enable()
        listener.close()
    assert left == []  # before: the failed Client (closed, its IO loop still to stop in its finaliser)


def test_a_port_where_nothing_listens_is_refused_at_once():
    # Client retried a refused connection for its whole 20 s timeout before the one line
    import socket
    import time

    from masonrycli.errors import InputError

    with socket.socket() as probe:  # a free port where nothing listens
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    start = time.monotonic()
    with pytest.raises(InputError) as raised:
        runner.open_cluster(f"tcp://127.0.0.1:{port}", None)
    assert time.monotonic() - start < scheduler.PROBE_TIMEOUT
    assert str(raised.value) == (
        f"--scheduler tcp://127.0.0.1:{port}: cannot connect (nothing listens at 127.0.0.1:{port}: connection refused)"
    )


def test_a_host_that_does_not_exist_is_refused_at_once():
    # Client retried the name lookup for its whole 20 s timeout before the one line (.invalid: RFC 6761,
    # never a host)
    import time

    from masonrycli.errors import InputError

    start = time.monotonic()
    with pytest.raises(InputError) as raised:
        runner.open_cluster("nosuchhost.invalid:8786", None)
    assert time.monotonic() - start < scheduler.CONNECT_TIMEOUT / 2
    assert re.fullmatch(
        r"--scheduler nosuchhost\.invalid:8786: cannot connect \(no host named nosuchhost\.invalid: [^\n]+\)",
        str(raised.value),
    )


def test_an_address_that_drops_the_connection_is_refused_after_the_probe(monkeypatch):
    # a firewall that drops packets (or a host that is down) took Client's whole 20 s, 23 s in all: here a
    # listener whose accept queue is full, so the kernel drops further SYNs as such a firewall would
    import socket

    from masonrycli.errors import InputError

    monkeypatch.setattr(scheduler, "PROBE_TIMEOUT", 1.0)
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(0)
        port = listener.getsockname()[1]
        queued = [socket.socket() for _ in range(4)]
        for sock in queued:  # fill the queue: connects that never complete, then dropped ones
            sock.setblocking(False)
            sock.connect_ex(("127.0.0.1", port))
        time.sleep(0.3)
        try:
            start = time.monotonic()
            with pytest.raises(InputError) as raised:
                runner.open_cluster(f"tcp://127.0.0.1:{port}", None)
            took = time.monotonic() - start
        finally:
            for sock in queued:
                sock.close()
    assert took < 1.0 + 3.0
    assert str(raised.value) == (
        f"--scheduler tcp://127.0.0.1:{port}: cannot connect (no answer from 127.0.0.1:{port} within 1 s: the host "
        "is down, or a firewall drops it)"
    )


def test_a_name_lookup_that_may_pass_on_a_retry_is_left_to_client(monkeypatch):
    # Only "no such name" is final: a resolver that did not answer in time (EAI_AGAIN) may answer
    # Client's retries within its CONNECT_TIMEOUT, so the scheduler is not refused as "no host named ...".
    import socket

    def lookup_fails(*args, **kwargs):
        raise socket.gaierror(socket.EAI_AGAIN, "Temporary failure in name resolution")

    monkeypatch.setattr(socket, "create_connection", lookup_fails)
    assert scheduler._refused("tcp://scheduler.example:8786") == ""


class SlowClient:
    """A ``Client`` that connects ``delay`` s after it is made (``interrupt``: Ctrl-C in the main thread
    first); every one made is in ``made``."""

    made: list = []
    delay = 0.6
    interrupt = False

    def __init__(self, scheduler, timeout=None):
        import signal
        import threading
        import time

        if self.interrupt:  # a real SIGINT during the wait: it wakes the main thread, as a Ctrl-C does
            time.sleep(0.05)
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)
        time.sleep(self.delay)
        self.closed = False
        SlowClient.made.append(self)

    def close(self):
        self.closed = True


def _wait_for_made(n: int = 1, within: float = 5.0) -> list:
    import time

    end = time.monotonic() + within
    while len(SlowClient.made) < n and time.monotonic() < end:
        time.sleep(0.02)
    time.sleep(0.1)  # the thread's close after the append
    return SlowClient.made


@pytest.mark.parametrize("interrupt", [False, True], ids=["gave up waiting", "Ctrl-C while waiting"])
def test_a_client_that_connects_after_the_command_gave_up_is_closed(interrupt, monkeypatch):
    # Before: the thread's Client connected after the 20 + 10 s wait (or a Ctrl-C during it) and stayed
    # open, the process's default client, in a long-lived process (a notebook) until it ended.
    from masonrycli.errors import InputError

    monkeypatch.setattr(scheduler, "CONNECT_TIMEOUT", 0.1)
    monkeypatch.setattr(scheduler, "CONNECT_GRACE", 0.1)
    monkeypatch.setattr(scheduler, "_refused", lambda scheduler: "")  # the fake client's port 1 is closed
    monkeypatch.setattr(SlowClient, "made", [])
    monkeypatch.setattr(SlowClient, "interrupt", interrupt)
    with pytest.raises(KeyboardInterrupt if interrupt else InputError):
        scheduler.connect(SlowClient, "tcp://127.0.0.1:1")
    made = _wait_for_made()
    assert len(made) == 1 and made[0].closed


def test_a_client_that_connects_in_time_is_returned_open(monkeypatch):
    monkeypatch.setattr(scheduler, "_refused", lambda scheduler: "")
    monkeypatch.setattr(SlowClient, "made", [])
    monkeypatch.setattr(SlowClient, "delay", 0.05)
    client = scheduler.connect(SlowClient, "tcp://127.0.0.1:1")
    assert client is SlowClient.made[0] and not client.closed
