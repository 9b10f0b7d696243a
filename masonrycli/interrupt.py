"""Ctrl-C (SIGINT), SIGTERM and SIGHUP (the terminal closed), handled in one place for the whole run.

Three phases, because what a signal may safely do depends on what is under way:

- **setup** (model, first numba compile, output files opened): nothing is computed yet, so the signal
  raises :class:`StopRun` at once — the caller removes its temporary files and exits;
- **stepping**: the signal only sets :attr:`StopSignals.signum`; the time loop polls :meth:`requested`
  after each step, so the step in progress finishes and every frame handed to the sinks is whole — unless
  that step is compiling numba kernels (a first run compiles some in step 1, others in the first step
  that stalls): the signal then raises :class:`StopStep` and the loop ends at the step before (below);
- **closing** (files being finished and renamed): further signals are counted and acknowledged on stderr,
  never raised, so a second Ctrl-C or a ``kill`` during shutdown cannot lose a file.

Outside the main thread (where Python cannot install handlers) the context does nothing.

A handler's raise can land where Python cannot pass an exception on: a first run compiles the numba kernels
for seconds, and numba's compiler calls back into Python through ctypes (llvmlite's object cache), where an
exception is reported as "Exception ignored …" with a traceback and dropped. A Ctrl-C there printed that
traceback, then the compile failed on its own (``RuntimeError: no compiled object yet``), reported as an
internal error with exit 1 instead of the stop. So while the handlers are installed a dropped exception of
theirs is not printed but noted (:attr:`dropped`), and :meth:`StopSignals.setup_work` raises the stop
instead of the error it caused; :func:`raise_dropped` does so for code that catches errors itself (``masonry
sweep --workers 0`` made that error a failed row, went on, and took every later Ctrl-C for a repeat).

A compilation inside a step is why a stop cannot always wait for the step to end: with an empty cache and a
loaded machine it lasts minutes (a SIGTERM of ``timeout 120`` at load 23 was acknowledged, "already
stopping", and the run went on compiling for 10 more minutes until SIGKILLed; at load 8 the compilations of
step 1 and of the first stalled step took 16 s and 23 s). So :meth:`StopSignals.stepping` is given a
``compiling()`` test (``engine.compile_log.watched_compiles``), and a signal while it is true inside the loop's
:func:`abandonable` work (a step, a frame being built) — the first signal or a repeat — raises
:class:`StopStep` out of the compilation; the time loop puts the state back as it was before the step and
ends there (``run.simulate``). That raise, too, can be dropped inside the compiler; then the next start or end
of a compilation raises it (:meth:`StopSignals.compile_event`, from numba's own Python code). Elsewhere (the
summary's last kernels) a compilation is waited for.

:class:`FirstSignalStops` is the same rule for a command that stops by ``KeyboardInterrupt`` (``masonry
sweep``): the first signal raises it, later ones are acknowledged and ignored (after the context too,
once a signal has stopped the command: it is on its way out), and a block can hold it (a report file
renamed into place and recorded as written, with no signal between the two).

Once a command is over — whatever its exit code — :func:`ignore_signals_while_exiting` lets the interpreter
shut down undisturbed: Python puts its handlers back to the default action when it finalizes, so a Ctrl-C
in those last hundred milliseconds killed the process (exit -2 after the one-line "interrupted" message of
a stopped run, or after ``masonry build`` had written its file whole), and one slightly earlier, in the
``atexit`` callbacks, printed a ``KeyboardInterrupt`` traceback. Every output is closed by then, so there
is nothing left for a signal to stop.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading

SIGNALS = (signal.SIGINT, signal.SIGTERM, *((signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ()))
"""Ctrl-C, ``kill``, and the terminal closing (an SSH session dropped: SIGHUP to the session's processes; before
it was handled, a run killed so left only its ``.part`` files). SIGHUP is left alone when it is ignored as the
run starts (``nohup``): the run then goes on, as the user asked."""


class StopRun(BaseException):
    """A stop signal arrived before the first step (not an ``Exception``: nothing should swallow it)."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


class StopStep(BaseException):
    """A stop signal arrived while the step in progress was compiling numba kernels (module doc): the step
    is abandoned, the run ends at the step before it."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def exit_code(signum: int) -> int:
    """The shell convention for a process stopped by a signal: 128 + its number (130 SIGINT, 143 SIGTERM)."""
    return 128 + int(signum)


def signal_name(signum: int) -> str:
    return "Ctrl-C" if signum == signal.SIGINT else signal.Signals(signum).name


class _Handlers:
    """Installs :meth:`_handle` (through :meth:`_dispatch`) for :data:`SIGNALS` on entry (main thread only) and puts the previous
    handlers back on exit."""

    def __init__(self) -> None:
        self._previous: dict[int, object] = {}
        self._raised: BaseException | None = None
        self._hook = None
        self.dropped = False
        """The exception a handler raised was dropped by Python (module doc): the signal stopped nothing."""

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._hook = sys.unraisablehook
            sys.unraisablehook = self._unraisable
            _INSTALLED.append(self)
            try:
                for sig in SIGNALS:
                    if _nohup(sig):
                        continue
                    self._previous[sig] = signal.signal(sig, self._dispatch)
            except BaseException:  # a signal between two installs (StopRun): __exit__ will not run
                self.__exit__()
                raise
        return self

    def __exit__(self, *exc) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()
        self._release_hook()

    def _release_hook(self) -> None:
        if self._hook is not None:
            sys.unraisablehook, self._hook = self._hook, None
        if self in _INSTALLED:
            _INSTALLED.remove(self)

    def _raise(self, exc: BaseException):
        """Raise ``exc`` from a handler, remembered so that :meth:`_unraisable` knows it."""
        self._raised = exc
        raise exc

    def _unraisable(self, unraisable) -> None:
        if self._raised is not None and unraisable.exc_value is self._raised:
            self.dropped = True  # said by the command's own stop line, not by a traceback
            return
        self._hook(unraisable)

    def _dispatch(self, signum, frame) -> None:
        if signum == getattr(signal, "SIGHUP", None):
            detach_hung_up_terminal()
        self._handle(signum, frame)

    def _handle(self, signum, _frame) -> None:
        raise NotImplementedError


class StopSignals(_Handlers):
    """Context manager installing the handlers; starts in the setup phase."""

    def __init__(self) -> None:
        super().__init__()
        self.signum: int | None = None
        self.phase = "setup"
        self.repeats = 0
        self._compiling = None

    def stepping(self, compiling=None) -> None:
        """From now on a signal asks the time loop to stop after its current step; ``compiling()``: whether
        numba is compiling in this thread now, when a signal raises :class:`StopStep` instead (module doc)."""
        self.phase = "stepping"
        self._compiling = compiling

    def closing(self) -> None:
        """From now on signals are acknowledged and otherwise ignored until the files are closed."""
        self.phase = "closing"
        self._compiling = None

    @contextlib.contextmanager
    def held(self):
        """In the setup phase: a signal during the block only sets :attr:`signum` and is raised as
        :class:`StopRun` once the block is over, so a file the block writes whole (``masonry limit``'s
        recording) is not cut."""
        previous, self.phase = self.phase, "stepping"
        try:
            yield
        finally:
            self.phase = previous
        if previous == "setup" and self.signum is not None:
            raise StopRun(self.signum)

    def requested(self) -> bool:
        return self.signum is not None

    @contextlib.contextmanager
    def setup_work(self):
        """Around work of the setup phase that may compile numba kernels: a StopRun that Python dropped there
        (module doc) is raised instead of the error it caused, or at the end of the block if the work went on."""
        try:
            yield
        except Exception:
            if self.dropped:
                raise StopRun(self.signum) from None
            raise
        if self.dropped:
            raise StopRun(self.signum)

    def compile_event(self) -> None:
        """A numba compilation of the stepping thread starts or ends: once a stop is asked, inside the loop's
        :func:`abandonable` work, raise :class:`StopStep` from there — the handler's own raise is often dropped
        inside the compiler (module doc; measured: a SIGTERM in the first frame's compilation was dropped, and
        step 1 then compiled for 10 s before the loop stopped)."""
        if self.signum is not None and self.phase == "stepping" and _ABANDONABLE:
            self._raise(StopStep(self.signum))

    def _handle(self, signum, _frame) -> None:
        first = self.signum is None
        if first:
            self.signum = signum
        else:
            self.repeats += 1
            already_stopping(signum)
        if first and self.phase == "setup":
            self._raise(StopRun(signum))
        # a repeat too: the first one's StopStep may have been dropped inside the compiler (module doc)
        if self.phase == "stepping" and _ABANDONABLE and self._compiling is not None and self._compiling():
            self._raise(StopStep(self.signum))


class FirstSignalStops(_Handlers):
    """Handlers for a command that stops by ``KeyboardInterrupt`` (``masonry sweep``: its study and its
    report): the first SIGINT or SIGTERM raises it — at once, or at the end of a :meth:`held` block — and
    :attr:`signum` says which; later ones are acknowledged on stderr and ignored, so the shutdown that
    follows the first (the table written, the cluster closed) is not cut. Main thread only, as above."""

    def __init__(self) -> None:
        super().__init__()
        self.signum: int | None = None
        self._holding = False
        self._deferred = False

    def __exit__(self, *exc) -> None:
        # Stopped: the command is leaving with exit 130/143 and has said what it wrote. Python's handlers,
        # put back here, would turn a second Ctrl-C on the rest of the way out (typer's exit, weakref and
        # atexit callbacks) into "stopped before any output was written" or a KeyboardInterrupt traceback
        # under the complete table (CI, 2026-11-27 18:25 UTC); ignored instead, as once the command is over.
        # SIG_IGN replaces our handlers directly: restoring Python's first, even for a moment, let a signal
        # that arrived just before (it runs at the next bytecode boundary, with the handler installed then)
        # meet the default handler (CI at 017b831).
        if self.signum is not None and self._previous:
            ignore_signals_while_exiting()
            self._previous.clear()
            self._release_hook()
        else:
            super().__exit__(*exc)

    def raised(self) -> bool:
        """The first signal's handler raised its KeyboardInterrupt (it was not held): an error that comes out
        instead is that interrupt, replaced by the code it landed in (``masonry sweep``)."""
        return self._raised is not None

    def stopping(self) -> int:
        """The signal that stopped the command (SIGINT for a KeyboardInterrupt of other origin); from now
        on every signal is a repeat."""
        if self.signum is None:
            self.signum = signal.SIGINT
        return self.signum

    @contextlib.contextmanager
    def held(self):
        """A first signal during the block is raised when the block is over: a file renamed into place
        inside it is also recorded as written inside it, with no signal between the two.

        If the block raises (the rename failed), its error goes on instead, as out of
        :meth:`StopSignals.held`: it says what went wrong, and the command is leaving anyway — the signal
        stays in :attr:`signum` (so later ones are repeats) but is not raised later: a deferral kept past
        the block made the next held block raise a KeyboardInterrupt for it, after the error."""
        self._holding = True
        try:
            yield
        finally:
            self._holding = False  # first: a signal from now on raises at once instead of being deferred
            deferred, self._deferred = self._deferred, False
        if deferred:
            raise KeyboardInterrupt

    def _handle(self, signum, _frame) -> None:
        if self.signum is not None:
            already_stopping(signum)
            return
        self.signum = signum
        if self._holding:
            self._deferred = True
            return
        self._raise(KeyboardInterrupt())


_ABANDONABLE: list[bool] = []
"""Non-empty inside :func:`abandonable`."""


@contextlib.contextmanager
def abandonable():
    """Work the time loop can abandon (a step, a frame being built): a signal while it compiles numba kernels
    raises :class:`StopStep` (module doc); the caller puts back what the block changed."""
    _ABANDONABLE.append(True)
    try:
        yield
    finally:
        _ABANDONABLE.pop()


_INSTALLED: list[_Handlers] = []
"""The contexts whose handlers are installed, the innermost last."""


def raise_dropped() -> None:
    """Raise again the stop that the innermost context's handler raised where Python dropped it (module
    doc), for code that would take the error it caused for its own; nothing when there is none."""
    if _INSTALLED and _INSTALLED[-1].dropped:
        handlers = _INSTALLED[-1]
        handlers.dropped = False
        raise handlers._raised


def _nohup(sig: int) -> bool:
    """SIGHUP ignored by whoever started the run (``nohup``, a service manager): it stays ignored."""
    return sig == getattr(signal, "SIGHUP", None) and signal.getsignal(sig) == signal.SIG_IGN


def detach_hung_up_terminal() -> None:
    """Point stdin, stdout and stderr that are a terminal hung up (closed: an SSH session dropped) at
    /dev/null, so that every later message goes nowhere instead of failing.

    Once the kernel has hung the terminal up (before it sends SIGHUP) every write to it fails with EIO: the
    line of a stopped command (``masonry limit``'s "interrupted: …", ``masonry build``'s note, a study's
    last progress line) raised there, and the error of the error line made the command exit 1 with a
    traceback for nobody, where its files were whole (exit 129 said so). A hung-up terminal is told apart by
    ``tcgetattr`` failing with EIO; a file or pipe (``--json > out.json``) fails with ENOTTY and is kept, so
    is a live terminal (``kill -HUP``). Safe in a signal handler: no buffered I/O."""
    import errno
    import termios

    null = None
    try:
        for fd in (0, 1, 2):
            try:
                termios.tcgetattr(fd)
            except termios.error as exc:
                if exc.args[0] != errno.EIO:
                    continue
            except OSError:  # closed, or no such descriptor
                continue
            else:
                continue  # a live terminal
            if null is None:
                null = os.open(os.devnull, os.O_RDWR)
            os.dup2(null, fd)
    except OSError:
        pass
    finally:
        if null is not None:
            os.close(null)


def already_stopping(signum: int) -> None:
    """What a repeated signal prints, once a stop is under way (on stderr, one line)."""
    # os.write: no buffered I/O inside a signal handler (it may interrupt a print). A closed terminal (SIGHUP)
    # or pipe makes the write fail: an error raised here would land in the code finishing the files.
    with contextlib.suppress(OSError):
        os.write(2, f"{signal_name(signum)}: already stopping — finishing the output files\n".encode())


def ignore_signals_while_exiting() -> None:
    """Ignore SIGINT and SIGTERM from now on: the command is over and the process is on its way out
    (module doc). SIG_IGN, unlike a Python handler, survives the interpreter's finalization. Main thread
    only."""
    if threading.current_thread() is threading.main_thread():
        for sig in SIGNALS:
            signal.signal(sig, signal.SIG_IGN)
