"""The workers of an existing cluster run this masonry: its version and a digest of its source.

A study's rows are one table only if every run was made by the same code: runs are bit-identical by
design, a resumed study reuses finished rows, and a grid is read across. On a ``LocalCluster`` that holds
(its workers are started from this interpreter); on a cluster given by ``--scheduler`` the workers were
installed by someone else, perhaps with another masonry release, another checkout, or none. Before this
check a worker with another masonry wrote its rows into the study without a word, and a worker without
one failed every run (an error row each, "No module named 'masonrycli'").

What is compared: ``masonrycli.__version__`` and a SHA-256 of the source of ``masonrycli`` and
``geometry_library`` (every ``.py`` file, with its path inside the package), as the process imports them:
two checkouts of one release differ in their source, and that is what decides the numbers.

The probe is run on every worker with ``Client.run``. It is built inside :func:`_make_probe`, so
cloudpickle sends its code by value (a module-level function would be sent as a reference to
``masonrycli.study.versions``, which a worker without masonry, or with an older one, cannot import);
it imports only the standard library before it looks for masonry. The same probe describes this
process, so both sides are measured the same way. The digest is :data:`masonrycli.SOURCE_DIGEST`, taken
when the process imported masonry (:mod:`masonrycli.source_digest`): of the code it runs, not of the files
on disk when asked — a long-lived worker whose checkout changed since it started reported the new files
while running the old code. A worker whose masonry predates it is described by its files as they are.

The check before the study asks the workers present then, and waits at most :data:`PROBE_TIMEOUT`
for them (a worker inside a long numba call answers only when the call ends: the command waited as
long, without a word). Workers that join later are checked by every run: the task a worker runs
(:func:`make_task`, also sent by value) probes first and returns its answer and its address with the
row; it does not run a point for another masonry, and the driver refuses such a result
(:class:`WorkerMismatch`). The run's inputs travel pickled, opened after the probe, so a worker without
masonry answers too instead of failing to read them.
"""

from __future__ import annotations

from masonrycli.errors import InputError
from masonrycli.source_digest import source_digest

PROBE_TIMEOUT = 60.0
"""s: how long the check before a study waits for every worker's answer."""


def _make_probe():
    """The probe: a function of no arguments returning ``(version, source digest)``, or ``(None, why)``
    when masonry cannot be imported. Nested so that it travels by value (module doc)."""
    digest_of = source_digest  # travels with the probe, by value (masonrycli.source_digest)

    def probe():
        import importlib

        try:
            packages = [importlib.import_module(name) for name in ("masonrycli", "geometry_library")]
        except Exception as exc:  # noqa: BLE001 - any failure to import is "no usable masonry"
            return None, f"{type(exc).__name__}: {exc}"
        digest = getattr(packages[0], "SOURCE_DIGEST", None)  # of the source it imported (module doc)
        if digest is None:  # a masonry from before SOURCE_DIGEST: its files as they are now
            digest = digest_of()
        return str(getattr(packages[0], "__version__", "unknown")), digest

    return probe


def this_version() -> tuple[str | None, str]:
    """``(version, source digest)`` of the masonry this process runs."""
    return _make_probe()()


def describe(found) -> str:
    """``masonry 0.1.0 (source 3f2a9c1b7d0e)``, or why there is none."""
    version, source = found
    return f"masonry {version} (source {source})" if version is not None else f"no masonry ({source})"


def check_workers(client, scheduler: str) -> None:
    """Refuse (one-line :class:`InputError`) a cluster with a worker whose masonry differs from this
    process's, naming the worker and both versions, or that does not answer within :data:`PROBE_TIMEOUT`.
    Workers that join later are checked by each run (:func:`make_task`)."""
    ours = this_version()
    try:
        # where the study's client connected: the address the scheduler reports may not be reachable from
        # here (a container's own IP, a tunnel's far end)
        found = ask_workers(scheduler, _make_probe(), PROBE_TIMEOUT)
    except TimeoutError:
        workers = len(client.scheduler_info().get("workers", {}))
        raise InputError(
            f"--scheduler {scheduler}: the workers ({workers}) did not all answer the masonry check within "
            f"{PROBE_TIMEOUT:g} s (a worker inside a long call answers when it ends); try again when they are free"
        ) from None
    # {worker address: result or exception}
    wrong = {}
    for worker, theirs in sorted(found.items()):
        if isinstance(theirs, BaseException):
            wrong[worker] = f"could not be asked ({type(theirs).__name__}: {theirs})"
        elif tuple(theirs) != ours:
            wrong[worker] = "runs " + describe(theirs)
    if wrong:
        worker, what = next(iter(wrong.items()))
        more = f" (and {len(wrong) - 1} more of {len(found)} workers)" if len(wrong) > 1 else ""
        raise InputError(
            f"--scheduler {scheduler}: worker {worker}{more} {what}, this command runs {describe(ours)}; "
            "install the same masonry on every worker"
        )


def ask_workers(address: str, function, timeout: float) -> dict:
    """``Client.run(function, on_error="return")`` on every worker of the scheduler at ``address``:
    ``{worker address: result or exception}``, or :class:`TimeoutError` after ``timeout`` s.

    ``Client.run`` (public) has no deadline, so it is awaited under one, by an asynchronous client of
    its own (a connection for the check; the study's client is synchronous). ``Client.run`` rather than
    a task per worker (``submit(..., workers=[w])``): it runs beside the worker's tasks, not behind them
    (a cluster busy with another study answers at once; a task would wait for a free thread)."""
    import asyncio

    from distributed import Client

    async def ask():
        async with Client(address, asynchronous=True, set_as_default=False, timeout=timeout) as client:
            return await client.run(function, on_error="return")

    async def ask_in_time():
        return await asyncio.wait_for(ask(), timeout)

    return asyncio.run(ask_in_time())


class WorkerMismatch(InputError):
    """A run's result came from a worker whose masonry differs from this process's (it was not kept)."""

    def __init__(self, worker: str, theirs, ours, params: dict):
        point = " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())
        super().__init__(
            f"worker {worker} runs {describe(theirs)}, this command runs {describe(ours)}: its run of {point} "
            "is not kept and the study stops"
        )


def make_task():
    """``(keep, run)``, the two functions a study sends to its workers, by value (module doc).

    ``keep(payload)`` returns its argument: the task holding the pickled ``(run_task, base)``.
    ``run(expected, payload, params, *task_args)`` returns ``(answer, worker address, row)``: the worker's
    probe answer and, if it equals ``expected``, ``run_task(base, params, *task_args)`` (else None, not
    run). The payload is unpickled once per worker process (kept with the payload it came from)."""
    probe = _make_probe()

    def keep(payload):
        return payload

    def run(expected, payload, params, *task_args):
        import pickle
        import sys

        answer = probe()
        try:
            from distributed import get_worker

            worker = get_worker().address
        except Exception:  # noqa: BLE001 - outside a worker (never in a study): no address to name
            worker = "?"
        if tuple(answer) != tuple(expected):
            return answer, worker, None
        module = sys.modules["masonrycli"]
        opened = getattr(module, "_study_payload", None)
        if opened is None or opened[0] is not payload:  # by identity: the worker holds one copy per study
            opened = (payload, pickle.loads(payload))
            module._study_payload = opened
        run_task, base = opened[1]
        return answer, worker, run_task(base, params, *task_args)

    return keep, run


def check_result(answer, worker: str, params: dict, ours) -> None:
    """Raise :class:`WorkerMismatch` unless ``answer`` (a run's probe answer) is ``ours``."""
    if tuple(answer) != tuple(ours):
        raise WorkerMismatch(worker, answer, ours, params)
