"""Sweep benchmark: speed-up of a study on a LocalCluster over the same runs one by one, and the
per-task overhead of going through Dask. Run with ``.venv/bin/python benchmarks/bench_sweep.py``.

* **speed-up** — ``--tasks`` runs of the 51-block wall (amp swept, ``--duration`` s each) made serially
  in this process vs on a LocalCluster of ``--workers`` single-threaded worker processes (cluster
  start excluded: it is reported apart; the numba cache is warm in both). Repeats are interleaved
  (serial, cluster, serial, cluster, ...) and the minimum wall time of each is kept.
* **accuracy** — every row of the cluster study is compared with the serial row of the same point
  (energy dissipated, state, drifts, IMs, NLGS sweeps): the speed-up is only claimed for identical
  results.
* **per-task overhead** — ``--tiny`` one-step runs through the cluster vs in process, per task.
* **CPU time per task** in process and on a worker (``time.thread_time`` inside the task): on a machine
  whose other processes take the cores, the wall-time speed-up says more about them than about the
  sweep; workers × (CPU time in process / CPU time on a worker) is the speed-up with a free core each.

Figures are printed and written to ``benchmarks/results_sweep.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("RERUN_ANALYTICS", "0")

from masonrycli.scenario.motion import Sine  # noqa: E402
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder  # noqa: E402
from masonrycli.study.axes import StudyBase, grid, parse_axis  # noqa: E402
from masonrycli.study.drivers import GridDriver  # noqa: E402
from masonrycli.study.runner import open_cluster, run_on_cluster, run_serially  # noqa: E402

COMPARED = ("energy_dissipated", "state", "residual_drift", "peak_drift", "max_opening", "hinges", "pga", "sa")
COMPARED += ("steps", "sweeps_mean")


def study_base(duration: float) -> StudyBase:
    motions = {"ground": Sine(amplitude=1.0, frequency=2.0)}
    return StudyBase(scenario_from_builder("wall", {"blocks": 51}, RunConfig(duration=duration), Material(), motions))


def timed(run, base, axes) -> tuple[float, list[dict]]:
    driver = GridDriver(axes, {})
    start = time.perf_counter()
    run(base, driver)
    return time.perf_counter() - start, driver.rows()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", type=int, default=8)
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tiny", type=int, default=40)
    args = ap.parse_args()

    base = study_base(args.duration)
    axes = [parse_axis(f"amp=0.2:1.2:{args.tasks}")]
    serial = lambda b, d: run_serially(b, d, lambda p, r: None, True)  # noqa: E731
    run_serially(base, GridDriver([parse_axis("amp=0.5")], {}), lambda p, r: None, True)  # compile / cache load

    t0 = time.perf_counter()
    client, cluster = open_cluster(None, args.workers)
    cluster_start = time.perf_counter() - t0
    on_cluster = lambda b, d: run_on_cluster(client, b, d, lambda p, r: None, True)  # noqa: E731
    t0 = time.perf_counter()
    on_cluster(base, GridDriver([parse_axis(f"amp=0.5:0.6:{args.workers}")], {}))  # workers load the numba cache
    warm_up = time.perf_counter() - t0

    serial_times, cluster_times = [], []
    for _ in range(args.repeat):
        t, serial_rows = timed(serial, base, axes)
        serial_times.append(t)
        t, cluster_rows = timed(on_cluster, base, axes)
        cluster_times.append(t)
    identical = all(all(a[k] == b[k] for k in COMPARED) for a, b in zip(serial_rows, cluster_rows))
    # a task's own wall time: the same in both modes on idle cores; longer on the workers when the
    # machine's other processes take the cores (then no speed-up can show)
    task_serial = sum(r["wall_time"] for r in serial_rows) / len(serial_rows)
    task_cluster = sum(r["wall_time"] for r in cluster_rows) / len(cluster_rows)
    cpu_serial = sum(r["cpu_time"] for r in serial_rows) / len(serial_rows)
    cpu_cluster = sum(r["cpu_time"] for r in cluster_rows) / len(cluster_rows)

    tiny = study_base(1e-3)
    tiny_axes = [parse_axis(f"amp=0.1:1.0:{args.tiny}")]
    tiny_serial = min(timed(serial, tiny, tiny_axes)[0] for _ in range(args.repeat))
    tiny_cluster = min(timed(on_cluster, tiny, tiny_axes)[0] for _ in range(args.repeat))
    client.close()
    cluster.close()

    res = {
        "tasks": args.tasks,
        "duration_s": args.duration,
        "workers": args.workers,
        "cores": os.cpu_count(),
        "load_average_1min": os.getloadavg()[0],
        "serial_s": min(serial_times),
        "cluster_s": min(cluster_times),
        "speedup": min(serial_times) / min(cluster_times),
        "rows_identical": identical,
        "task_wall_serial_s": task_serial,
        "task_wall_on_worker_s": task_cluster,
        "task_cpu_serial_s": cpu_serial,
        "task_cpu_on_worker_s": cpu_cluster,
        "speedup_from_cpu_time": args.workers * cpu_serial / cpu_cluster,
        "cluster_start_s": cluster_start,
        "worker_warm_up_s": warm_up,
        "tiny_tasks": len(grid(tiny_axes)),
        "overhead_ms_per_task": 1e3 * (tiny_cluster - tiny_serial / args.workers) / len(grid(tiny_axes)),
        "tiny_serial_ms_per_task": 1e3 * tiny_serial / len(grid(tiny_axes)),
        "tiny_cluster_ms_per_task": 1e3 * tiny_cluster / len(grid(tiny_axes)),
    }
    print(f"{args.tasks} runs of the 51-block wall, {args.duration:g} s each, {args.workers} workers")
    print(f"  serial {res['serial_s']:.2f} s, cluster {res['cluster_s']:.2f} s: speed-up {res['speedup']:.2f}x")
    print(f"  rows identical to the serial runs: {identical}")
    print(f"  one task's own wall time: {task_serial:.2f} s in process, {task_cluster:.2f} s on a worker")
    print(f"  one task's CPU time: {cpu_serial:.2f} s in process, {cpu_cluster:.2f} s on a worker")
    print(
        f"  speed-up the CPU times give with a free core per worker: {res['speedup_from_cpu_time']:.2f}x "
        "(workers × CPU time in process / CPU time on a worker)"
    )
    print(f"  cluster start {cluster_start:.1f} s, workers' first task (numba cache load) {warm_up:.1f} s")
    print(
        f"  per-task overhead: {res['overhead_ms_per_task']:.1f} ms ({res['tiny_tasks']} one-step tasks: "
        f"{res['tiny_serial_ms_per_task']:.1f} ms each in process, {res['tiny_cluster_ms_per_task']:.1f} ms "
        f"each through the cluster)"
    )
    print(f"  load average during the run: {res['load_average_1min']:.1f} on {os.cpu_count()} cores")
    (ROOT / "benchmarks" / "results_sweep.json").write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
