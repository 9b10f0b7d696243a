"""engine.compile_ahead: the child compiles exactly what a run calls, into the cache the run reads; it is
started only when the cache lacks it and two CPUs are there, and never outlives the run."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from masonrycli.engine import compile_ahead

from cli_helpers import invoke


def test_a_run_calls_every_kernel_with_the_signature_the_child_compiles(tmp_path):
    # The quick start's run: recorded frames (the joint and tensor kernels) and stalled steps (the
    # body-order stage) included. A signature the run does not use would be compiled for nothing.
    # At --tolerance 1e-6: since 479e3d0's rounded corners the quick start's 1 s has no stalled step at the
    # default 1e-5 (its first comes between 4 and 5 s); at 1e-6 six steps of its 1 s stall.
    done = invoke(
        "simulate",
        "wall",
        "--freq",
        2,
        "--amp",
        1,
        "--tolerance",
        1e-6,
        "--no-recording",
        "--history",
        tmp_path / "h.npz",
    )
    assert done.exit_code == 0, done.output
    for name, text in compile_ahead.KERNELS:
        assert compile_ahead.signature(text) in compile_ahead.dispatcher(name).signatures, name


def test_the_notation_reads_as_numba_types():
    import numba.types as nt

    assert compile_ahead.signature("(i4[:, ::1], f8, b1[::1], f8[:, :, :, ::1],)") == (
        nt.Array(nt.int32, 2, "C"),
        nt.float64,
        nt.Array(nt.boolean, 1, "C"),
        nt.Array(nt.float64, 4, "C"),
    )


def _child_env(cache) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), RERUN_ANALYTICS="0")
    root = os.path.dirname(os.path.dirname(os.path.abspath(compile_ahead.__file__)))
    env["PYTHONPATH"] = os.pathsep.join(p for p in (os.path.dirname(root), env.get("PYTHONPATH", "")) if p)
    return env


@pytest.mark.slow
def test_what_the_child_compiles_a_run_loads_from_the_cache(tmp_path):
    cache = tmp_path / "numba-cache"
    cache.mkdir()
    env = _child_env(cache)
    check = (
        "from masonrycli.engine import compile_ahead as c\n"
        "print(c.needed())\n"
        "for name, text in c.KERNELS:\n"
        "    d = c.dispatcher(name); d.compile(c.signature(text))\n"
        "    print(name, sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values()))\n"
    )
    child = subprocess.run([sys.executable, "-m", "masonrycli.engine.compile_ahead"], env=env, timeout=600)
    assert child.returncode == 0
    done = subprocess.run([sys.executable, "-c", check], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    # the cache now holds every kernel of a run's: no child needed, each loaded (a hit), none compiled
    assert lines[0] == "False" or compile_ahead._cpus() < 2
    assert lines[1:] == [f"{name} 1 0" for name, _ in compile_ahead.KERNELS]


def test_no_child_where_it_cannot_help(monkeypatch):
    monkeypatch.setattr(compile_ahead, "_cached", lambda name: False)
    monkeypatch.setattr(compile_ahead, "_cpus", lambda: 2)
    assert compile_ahead.needed()
    monkeypatch.setenv("MASONRY_COMPILE_AHEAD", "0")
    assert not compile_ahead.needed()
    monkeypatch.delenv("MASONRY_COMPILE_AHEAD")
    monkeypatch.setattr(compile_ahead, "_cpus", lambda: 1)
    assert not compile_ahead.needed()
    monkeypatch.setattr(compile_ahead, "_cpus", lambda: 2)
    monkeypatch.setattr(compile_ahead, "_cached", lambda name: True)
    assert not compile_ahead.needed()
    with compile_ahead.ahead() as child:
        assert child is None


def test_the_stalled_stage_alone_starts_no_child(monkeypatch):
    # a run that never stalls never caches the body-order stage: it must not start a child every time
    monkeypatch.setattr(compile_ahead, "_cpus", lambda: 2)
    monkeypatch.setattr(compile_ahead, "_cached", lambda name: name not in dict(compile_ahead.STALLED))
    assert not compile_ahead.needed()


def test_the_child_is_stopped_and_reaped_when_the_block_ends(monkeypatch):
    monkeypatch.setattr(compile_ahead, "needed", lambda: True)
    with pytest.raises(KeyboardInterrupt):
        with compile_ahead.ahead() as child:
            assert child is not None and child.poll() is None
            raise KeyboardInterrupt  # a Ctrl-C in the run: the child goes too
    assert child.returncode is not None


def test_the_child_stops_when_its_parent_is_gone():
    # started by a process that has exited: getppid() is no longer it, nothing is compiled
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    assert compile_ahead.compile_all(parent=int(gone.stdout)) == 0


class _Client:
    def __init__(self, workers):
        self.workers, self.submitted = workers, []

    def scheduler_info(self):  # the host as distributed gives it: the address's
        return {"workers": {w: {"host": w.split("//")[1].split(":")[0]} for w in self.workers}}

    def submit(self, fn, **kw):
        self.submitted.append((fn, kw))
        return "future"


def test_a_cluster_of_two_workers_or_more_compiles_on_its_last_one(monkeypatch):
    monkeypatch.setattr(compile_ahead, "needed", lambda: True)
    one, two = _Client(["tcp://a:1"]), _Client(["tcp://b:2", "tcp://a:1"])
    assert compile_ahead.on_cluster(one) is None and not one.submitted
    assert compile_ahead.on_cluster(two) == "future"
    [(fn, kw)] = two.submitted
    assert fn is compile_ahead.compile_quietly and kw["workers"] == ["tcp://b:2"] and not kw["allow_other_workers"]
    monkeypatch.setattr(compile_ahead, "needed", lambda: False)
    assert compile_ahead.on_cluster(_Client(["tcp://b:2", "tcp://a:1"])) is None


@pytest.mark.slow
def test_the_task_runs_on_a_real_local_cluster(monkeypatch):
    # needed() is the study's process's answer; the worker compiles (here: loads from the warm cache) all
    from distributed import Client, LocalCluster

    monkeypatch.setattr(compile_ahead, "needed", lambda: True)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        with Client(cluster) as client:
            future = compile_ahead.on_cluster(client)
            assert future.result(timeout=600) == len(compile_ahead.KERNELS)
            assert client.who_has(future)[future.key] == (max(client.scheduler_info()["workers"]),)


def test_an_external_cluster_compiles_on_the_last_worker_of_its_busiest_host(monkeypatch):
    # --scheduler: its workers' cache is theirs, not this process's; so the worker asks needed() itself
    monkeypatch.setattr(compile_ahead, "needed", lambda: False)  # this process's cache: warm, and beside the point
    spread = _Client(["tcp://a:1", "tcp://b:1", "tcp://c:1"])
    assert compile_ahead.on_cluster(spread, external=True) is None and not spread.submitted  # no cache shared
    two = _Client(["tcp://a:1", "tcp://b:3", "tcp://b:2", "tcp://c:1"])
    assert compile_ahead.on_cluster(two, external=True) == "future"
    [(fn, kw)] = two.submitted
    assert fn is compile_ahead.compile_if_needed and kw["workers"] == ["tcp://b:3"] and not kw["allow_other_workers"]


def test_the_external_workers_task_compiles_only_where_its_cache_needs_it(monkeypatch):
    monkeypatch.setattr(compile_ahead, "compile_all", lambda parent=None: 11)
    monkeypatch.setattr(compile_ahead, "needed", lambda: False)
    assert compile_ahead.compile_if_needed() == 0
    monkeypatch.setattr(compile_ahead, "needed", lambda: True)
    assert compile_ahead.compile_if_needed() == 11


def test_a_study_on_an_external_scheduler_compiles_ahead(tmp_path, monkeypatch):
    # The study asked for the compile task on a LocalCluster only: on a --scheduler's 2 workers of an empty
    # cache both compiled every kernel (workers' CPU 32.0-39.5 s for `sweep wall -p amp=0.2,0.4,0.6,0.8
    # --duration 0.3`, against 21.2-34.0 s with the task; benchmarks/JOURNAL.md, 2026-11-29)
    import threading

    from distributed import Client, LocalCluster

    from masonrycli.study import runner

    from sweep_helpers import invoke as sweep_invoke
    from sweep_helpers import write_block

    compiled = []
    monkeypatch.setattr(compile_ahead, "needed", lambda: True)
    monkeypatch.setattr(compile_ahead, "compile_all", lambda parent=None: compiled.append(threading.get_ident()))
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0")
    monkeypatch.setattr(runner, "open_cluster", lambda *args: (Client(cluster), None))  # as --scheduler's
    try:
        out = tmp_path / "s.csv"
        argv = ["sweep", write_block(tmp_path), "-p", "amp=0.05,0.1", "--duration", "0.02", "--no-recording"]
        result = sweep_invoke(*argv, "--scheduler", "tcp://127.0.0.1:1", "-o", out)
    finally:
        cluster.close()
    assert result.exit_code == 0, result.output
    assert len(compiled) == 1  # before: 0
