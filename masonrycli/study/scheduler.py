"""``--scheduler ADDRESS``: the address checked (``tcp://HOST:PORT``), a plain TCP probe first (nothing listening,
no such host, no answer, a listener that says nothing: one line at once, not after Client's timeout), then a
``Client`` made in a thread the command waits for within a timeout, every failure one line, and a client that
connects after the command gave up closed. The study's cluster and tasks: :mod:`masonrycli.study.runner`."""

from __future__ import annotations

import errno
import gc
import threading

from masonrycli.errors import InputError


def check_scheduler(address: str | None) -> str | None:
    """``address`` if it is a Dask scheduler address this command can use, ``tcp://HOST:PORT`` (or
    ``HOST:PORT``); else a one-line :class:`InputError`. Before, ``foo``, ``http://…``, ``tls://…`` and
    ``ucx://…`` ended in a Dask traceback (exit 1), ``tcp://h:99999`` waited 20 s to time out, and an empty
    ``--scheduler ''`` silently started a LocalCluster instead."""
    if address is None:
        return None
    expected = "expected tcp://HOST:PORT, the address `dask scheduler` prints"
    scheme, sep, rest = address.strip().partition("://")
    if not sep:
        scheme, rest = "tcp", address.strip()
    if scheme != "tcp":
        raise InputError(f"--scheduler {address}: {scheme}:// is not supported ({expected})")
    host, colon, port = rest.rpartition(":")
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise InputError(f"--scheduler {address!r}: not an address with a port from 1 to 65535 ({expected})")
    return address.strip()


CONNECT_TIMEOUT = 20.0
"""s: how long ``Client`` may try to reach the scheduler."""
CONNECT_GRACE = 10.0
"""s: how much longer the command waits for ``Client`` to give up before it says no scheduler answered."""


def connect(Client, scheduler: str):
    """A ``Client`` of ``scheduler``, or a one-line :class:`InputError`.

    The client is made in a thread the command waits for at most ``CONNECT_TIMEOUT + CONNECT_GRACE``:
    a port where something else listens (the dashboard's HTTP port 8787, say, waiting for a request)
    held ``Client`` forever, its own timeout notwithstanding; a thread left waiting there is a daemon and
    ends with the command. A service that speaks first made Dask read its bytes as a frame count
    (MemoryError: "Unable to allocate 3.07 EiB", a traceback): any failure but a connection's is "not
    a Dask scheduler". A client that connects after the command gave up waiting (or was interrupted
    while waiting) is closed by the thread: nobody else would, and it was the process's default client."""
    refused = _refused(scheduler)
    if refused:
        raise InputError(f"--scheduler {scheduler}: {refused}")
    made: dict = {}
    lock = threading.Lock()  # the thread hands its client over, or closes it once the command gave up

    def connect():
        try:
            client = Client(scheduler, timeout=f"{CONNECT_TIMEOUT:g}s")
        except BaseException as exc:  # noqa: BLE001 - reported below, in the command's thread
            # The error is kept without its traceback, which holds the half-made Client, whose
            # finaliser stops its IO loop under distributed's one class-wide LoopRunner lock. Left to a
            # later garbage collection, it ran inside the next LocalCluster's start, which holds that
            # lock: the process hung (CI, 2026-11-27). Collected here, in this thread, nothing holds it.
            exc.__traceback__ = exc.__context__ = exc.__cause__ = None
            with lock:
                made["error"] = exc
        else:
            with lock:
                if not made.get("given_up"):
                    made["client"] = client
                    return
            client.close()
            return
        gc.collect()  # out of the except block, where the traceback was still held

    def give_up():
        """Stop waiting: the thread closes a client it makes later; one it made already is closed here."""
        with lock:
            made["given_up"] = True
            late = made.pop("client", None)
        if late is not None:
            late.close()

    thread = threading.Thread(target=connect, name="masonry-scheduler-connect", daemon=True)
    try:
        thread.start()
        thread.join(CONNECT_TIMEOUT + CONNECT_GRACE)
        with lock:
            waiting = "client" not in made and "error" not in made
        if waiting:  # the raise gives up (below): a client that arrives from now on is closed
            raise InputError(
                f"--scheduler {scheduler}: " + SILENT.format(seconds=f"{CONNECT_TIMEOUT + CONNECT_GRACE:g}")
            )
        error = made.get("error")
        if isinstance(error, (OSError, TimeoutError)):
            raise InputError(f"--scheduler {scheduler}: cannot connect ({type(error).__name__}: {error})") from None
        if isinstance(error, Exception):
            why = ": ".join([type(error).__name__, *str(error).splitlines()[:1]])
            if isinstance(error, MemoryError):  # "Unable to allocate 3.07 EiB": its first bytes read as a size
                why = "the service there spoke first, and Dask read its bytes as an absurd message size"
            raise InputError(
                f"--scheduler {scheduler}: not a Dask scheduler (its answer is not Dask's protocol: {why})"
            )
        if error is not None:
            raise error
        return made["client"]
    except BaseException:  # given up, or Ctrl-C while waiting (also just after the wait)
        give_up()
        raise


SILENT = (
    "no Dask scheduler answered within {seconds} s (something listens there but does not speak Dask: the "
    "dashboard's port, or another service?)"
)
PROBE_TIMEOUT = 5.0
"""s: how long :func:`_refused` waits for a plain TCP connection: a host's kernel answers one at once, however
busy its scheduler, and a far one within a second; 5 s leaves room for two retries of a lost packet."""


def _refused(scheduler: str) -> str:
    """Why no scheduler can answer at a ``tcp://`` address, as the one line says it ("" if one may): a port where
    nothing listens refuses a plain TCP connection at once, while ``Client`` retried it for its whole
    ``CONNECT_TIMEOUT`` (a mistyped port waited 20 s for its one line); so did a host name the resolver
    does not know (``nosuchhost.invalid:8786``), a host that does not answer within ``PROBE_TIMEOUT`` (a firewall
    that drops the packets, a host that is down: 23 s, Client's 20 and the probe's), one with no route to it,
    and a listener that says nothing for ``PROBE_TIMEOUT`` once connected (a scheduler greets at once). Any
    other address, scheme or failure is left to ``Client`` and its ``CONNECT_TIMEOUT``, which says what it
    met."""
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(scheduler)
        host, port = parse_host_port(location)
    except Exception:  # noqa: BLE001 - not ours to judge: Client reports a malformed address
        return ""
    if scheme != "tcp":
        return ""
    try:
        sock = socket.create_connection((host, port), timeout=PROBE_TIMEOUT)
    except ConnectionRefusedError:
        return f"cannot connect (nothing listens at {host}:{port}: connection refused)"
    except socket.gaierror as error:  # Client retried the lookup for its 20 s: the name stays unknown
        if error.errno in (socket.EAI_NONAME, getattr(socket, "EAI_NODATA", socket.EAI_NONAME)):
            return f"cannot connect (no host named {host}: {error.strerror})"
        return ""  # EAI_AGAIN (a resolver that did not answer in time) and the like: may pass on a retry
    except TimeoutError:
        return (
            f"cannot connect (no answer from {host}:{port} within {PROBE_TIMEOUT:g} s: the host is down, or a "
            "firewall drops it)"
        )
    except OSError as error:
        if error.errno in (errno.EHOSTUNREACH, errno.ENETUNREACH):
            return f"cannot connect ({host}:{port}: {error.strerror})"
        return ""
    # A Dask scheduler speaks first: its handshake, as it accepts (distributed.comm.core, on_connection). A
    # listener that says nothing (the dashboard's HTTP port 8787, waiting for a request) held Client for its
    # CONNECT_TIMEOUT and the grace after it: 30 s before the line below, now PROBE_TIMEOUT.
    with sock:
        sock.settimeout(PROBE_TIMEOUT)
        try:
            sock.recv(1)
        except TimeoutError:
            return SILENT.format(seconds=f"{PROBE_TIMEOUT:g}")
        except OSError:  # reset: Client says what it meets
            pass
    return ""
