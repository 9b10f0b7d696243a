"""Screenshots of a recording from a headless Rerun viewer (tests, docs and the viewer checks): moved out of
readback.py, which reads recordings back, to keep each module one concept."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import sys
import time

from masonrycli.recording._rerun_private import viewer_pid


# ---------------------------------------------------------------------------------------- headless viewer
def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _viewer_executable() -> str | None:
    """The `rerun` next to this interpreter (same version as the SDK), else the one on PATH."""
    here = os.path.join(os.path.dirname(sys.executable), "rerun")
    return here if os.access(here, os.X_OK) else shutil.which("rerun")


def screenshot_recording(
    rrd_path: str | os.PathLike,
    png_path: str | os.PathLike,
    time_s: float | None = None,
    timeout: float = 60,
    *,
    tabs_dir: str | os.PathLike | None = None,
    at_open: bool = False,
    without: tuple[str, ...] = (),
) -> list[str]:
    """Open a recording in a headless viewer, save a PNG of the window, return the views' error reports.

    ``time_s``: the ``sim_time`` shown, s (None: the last frame's). The cursor is set on ``sim_time`` (the
    timeline the blueprint opens on and the paper-figure tabs are pinned on; a recording without it, a
    limit analysis, is shown at its last ``step``); with ``at_open`` it is left
    where the viewer put it on opening the file (``time_s`` ignored): what a user sees first. The PNG shows the
    default layout, less the entities ``without`` (paths with the leading "/": compare two shots to see what
    an entity adds to the picture). A hidden tab
    is not drawn and cannot report, so every tab is then brought to the front in turn (saved as
    ``tabs_dir/tab<i>.png`` if given: the i-th tab of every tab container, unless those are the tabs shown
    at open). Returns "view: severity: summary" for every report of every view;
    empty means healthy. Needs a Vulkan driver (Debian: mesa-vulkan-drivers libvulkan1).
    """
    from rerun.experimental import ViewerClient

    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    deadline = time.monotonic() + timeout
    viewer = ViewerClient.spawn(
        headless=True, port=_free_port(), hide_welcome_screen=True, executable_path=_viewer_executable()
    )
    pid = viewer_pid(viewer)
    try:
        while True:  # until the viewer answers
            try:
                viewer.get_state()
                break
            except Exception:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.2)
        viewer.open(os.path.abspath(rrd_path))
        loaded_at = None
        while True:  # until the file is loaded and its timelines are known
            state = viewer.get_state()
            recs = [r for r in state.recordings if r.timelines]
            if not state.loading and state.views and state.recordings:
                loaded_at = loaded_at or time.monotonic()
                # a recording of static data alone (a study's state map) has no time line: it waited
                # for one until the timeout
                if recs or time.monotonic() - loaded_at > _STATIC_ONLY_WAIT:
                    break
            else:
                loaded_at = None
            if time.monotonic() > deadline:
                raise TimeoutError(f"viewer did not load {rrd_path} within {timeout} s")
            time.sleep(0.2)
        if without:
            layout = viewer.get_blueprint(of="recording").blueprint
            for entry in layout.values():
                query = entry.get("ViewContents", {}).get("query")
                if isinstance(query, list):
                    entry["ViewContents"]["query"] = [q for q in query if q.removeprefix("+ ") not in without]
            viewer.set_blueprint(layout, of="recording")
        if not at_open and recs:  # a static-only recording has no time to set
            line = next((t for r in recs for t in r.timelines if t.name == "sim_time"), None)
            if line is None:  # a limit-analysis recording has the mechanism's steps alone: its last
                step = next((t for r in recs for t in r.timelines if t.name == "step"), None)
                if step is not None and step.end is not None:
                    viewer.set_time("step", sequence=int(step.end), play_state="paused")
            else:
                if time_s is None:
                    time_s = 1e-9 * line.end if line.end is not None else 0.0
                viewer.set_time("sim_time", duration=float(time_s), play_state="paused")
        _settle(viewer)
        viewer.save_screenshot(os.path.abspath(png_path))
        reports = {v.view_id: (v.name, v.reports) for v in viewer.get_state().views}
        blueprint = viewer.get_blueprint(of="recording").blueprint
        tabs = [
            c["ContainerBlueprint"]
            for c in blueprint.values()
            if c.get("ContainerBlueprint", {}).get("container_kind") == "Tabs"
        ]
        # every tab not shown at open, the first one included: a paper run opens on its second tab, and
        # the loop started at the second, so the live tab (forces, principal stress) was never shown
        shown = [t.get("active_tab") or (t.get("contents") or [None])[0] for t in tabs]
        for i in range(max((len(t.get("contents", [])) for t in tabs), default=0)):
            picks = [t["contents"][min(i, len(t["contents"]) - 1)] for t in tabs]
            if picks == shown:
                continue
            if time.monotonic() > deadline:
                raise TimeoutError(f"viewer did not show every tab of {rrd_path} within {timeout} s")
            for t, pick in zip(tabs, picks):
                t["active_tab"] = pick
            viewer.set_blueprint(blueprint, of="recording")
            _settle(viewer)
            png = viewer.take_screenshot()
            if tabs_dir is not None:
                os.makedirs(tabs_dir, exist_ok=True)
                with open(os.path.join(tabs_dir, f"tab{i}.png"), "wb") as fh:
                    fh.write(png)
            for v in viewer.get_state().views:
                if v.reports or v.view_id not in reports:
                    reports[v.view_id] = (v.name, v.reports)
        return [
            f"{name}: {r.severity}: {r.summary}" + (f" ({r.details})" if r.details else "")
            for name, rs in reports.values()
            for r in rs
        ]
    finally:
        with contextlib.suppress(Exception):
            viewer.quit(timeout=5.0)
        if viewer_pid(viewer) is not None and pid is not None:  # quit failed: end the shim's process group
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)


_STATIC_ONLY_WAIT = 2.0  # s loaded with views but no time line: a recording of static data alone


def _settle(viewer, paints: int = 2, pause: float = 0.2) -> None:
    """Let the viewer paint a few frames: newly shown views fetch their chunks on demand."""
    for _ in range(paints):
        viewer.take_screenshot(max_size=64)
        time.sleep(pause)
