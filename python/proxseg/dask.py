"""Datasets on a Dask cluster: ``segment --batch`` and ``recognize --batch`` spread over workers.

``python3 -m proxseg.dask segment --batch DATA -o OUT`` takes the inputs and batch options of
``proxseg segment --batch`` (folders, list files, globs, RGB-D naming patterns, ``--outputs``,
``--resume``) and runs every frame in a Dask worker, with the library in the worker's process
(no CLI per frame). It starts a ``LocalCluster`` on this machine (``--workers`` processes on the
loopback interface) unless ``--scheduler ADDRESS`` names a running cluster. Each worker loads
the model database once. Workers write the outputs themselves (a folder every worker sees: a
shared filesystem on several machines); this process gathers the rows into
``OUT/summary.jsonl`` as they come and writes ``OUT/summary.json`` at the end, both as the CLI
writes them: the outputs equal a single ``proxseg ... --batch`` run's. A frame whose worker dies
is run again on another one (Dask reschedules it; ``--retries`` more times for other failures).
docs/batch.md has the steps for several machines.

From Python::

    from proxseg import dask as pdask
    summary = pdask.run_batch("segment", ["data/"], "out/", workers=2)
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
import time
import warnings
from typing import Any, Dict, List, Mapping, Optional, Sequence

from . import _proxseg
from ._params import resolve_recognition_params, resolve_segment_params

try:  # Dask is optional for the rest of proxseg
    from distributed import Client, LocalCluster, as_completed, get_worker
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # pragma: no cover - reported when run
    Client = None  # type: ignore[assignment,misc]
    WorkerPlugin = object  # type: ignore[assignment,misc]

__all__ = ["discover_frames", "frame_rows", "run_batch", "main"]

_PLUGIN = "proxseg-batch"


def discover_frames(sources: Sequence[str], *, color_pattern: str = "{id}-color.png",
                    depth_pattern: str = "{id}-depth.png", meta_pattern: str = "{id}-meta.json",
                    intrinsics: Optional[str] = None) -> List[Dict[str, str]]:
    """The frames of the sources as ``proxseg --batch`` finds them: a list of dicts with
    ``id`` (the name the outputs take), ``cloud`` or ``color``, ``depth`` and ``camera``, in
    natural order. Raises OSError for a missing source, ValueError for two frames of one name
    or none at all."""
    return _proxseg._discover_frames([os.fspath(s) for s in sources], color_pattern,
                                     depth_pattern, meta_pattern,
                                     os.fspath(intrinsics) if intrinsics else "")


def frame_rows(out_dir: str) -> List[Dict[str, Any]]:
    """Every frame's row of a batch's ``OUT/summary*.jsonl`` (its last, when a frame was run
    again), in natural order of ids: ``frame``, ``inputs``, ``outputs`` (file: bytes), ``ms``,
    ``rss_mib`` and the command's figures (``k``, ``candidates``; recognize: ``objects``), or
    ``error``. All in memory: about 3 KiB a frame (a million frames: 3.4 GB, 20 s); for more,
    read the ``.jsonl`` lines one at a time."""
    return _proxseg._frame_rows(os.fspath(out_dir))


class _BatchWorker(WorkerPlugin):
    """Set up once per worker process: the job's settings and, for recognition, the database,
    loaded once and shared by the worker's tasks."""

    name = _PLUGIN

    def __init__(self, job: Dict[str, Any]) -> None:
        self.job = job
        self.db: Optional[_proxseg._Database] = None
        self.load_ms = 0.0

    def setup(self, worker: Any = None) -> None:
        if self.job["command"] == "recognize":
            start = time.perf_counter()
            self.db = _proxseg._Database(self.job["db"], False, float("nan"), float("nan"), [])
            self.load_ms = (time.perf_counter() - start) * 1000

    def run(self, frame: Dict[str, str]) -> Dict[str, Any]:
        job = self.job
        if job["command"] == "segment":
            return _proxseg._segment_frame(frame, job["out_dir"], job["outputs"],
                                           job["segmentation"])
        assert self.db is not None, "setup() loads the database of a recognize job"
        return _proxseg._recognize_frame(frame, job["out_dir"], job["outputs"],
                                         job["segmentation"], job["recognition"], self.db,
                                         job["db"], self.load_ms)


def _run_frame(frame: Dict[str, str]) -> Dict[str, Any]:
    """A Dask task: one frame, with the worker's plugin (settings and database)."""
    plugin = get_worker().plugins[_PLUGIN]
    assert isinstance(plugin, _BatchWorker)
    return plugin.run(frame)


def _frames(n: int) -> str:
    """'1 frame', '2 frames': the CLI's counts."""
    return f"{n} frame" + ("" if n == 1 else "s")


def _write_atomic(path: str, text: str) -> None:
    tmp = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.tmp.{os.getpid()}")
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def _human_time(seconds: float) -> str:
    """A duration as people read it, as the CLI prints it: "51.6 ms", "1.23 s", "2 min 05 s"."""
    if not seconds >= 0 or seconds == float("inf"):
        return "?"
    ms = seconds * 1e3
    # Each range ends where its rounding would print the next range's first value ("1000 ms").
    if ms < 9.995:
        return f"{ms:.2f} ms"
    if ms < 99.95:
        return f"{ms:.1f} ms"
    if ms < 999.5:
        return f"{ms:.0f} ms"
    if seconds < 9.995:
        return f"{seconds:.2f} s"
    if seconds < 59.95:
        return f"{seconds:.1f} s"
    s = int(seconds + 0.5)
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    m = int(seconds / 60 + 0.5)
    return f"{m // 60} h {m % 60:02d} min"


class _Progress:
    """A progress line on stderr: done/total, frames per second, time left (as the CLI's)."""

    def __init__(self, total: int, quiet: bool) -> None:
        self.total, self.done, self.ok, self.quiet = total, 0, 0, quiet
        self.start = time.perf_counter()
        self.tty = sys.stderr.isatty()

    def step(self, what: str, failed: bool = False) -> None:
        self.done += 1
        self.ok += 0 if failed else 1
        if self.quiet:
            return
        seconds = time.perf_counter() - self.start
        line = f"[{self.done}/{self.total}] {what}" + (" (failed)" if failed else "")
        # The rate of the frames done well: a failed frame is often quick, and counting it
        # would tell of a rate no frame is done at.
        if self.ok > 0 and seconds > 0:
            rate = self.ok / seconds
            line += f"  {rate:.2f} frames/s, ETA {_human_time((self.total - self.done) / rate)}"
        if self.tty:
            sys.stderr.write("\r" + line + "\033[K" + ("\n" if self.done == self.total else ""))
        elif self.total <= 200 or self.done % ((self.total + 199) // 200) == 0 \
                or self.done == self.total:
            sys.stderr.write(line + "\n")
        sys.stderr.flush()


def _parameters(command: str, preset: str, config: Optional[Mapping[str, Any]],
                overrides: Mapping[str, Any]) -> Dict[str, Any]:
    """The checked parameters as the CLI resolves them: preset < config < overrides."""
    if command == "segment":
        return resolve_segment_params(config, preset, overrides)
    config = dict(config or {})
    seg_over = dict(overrides.get("segmentation", {}))
    rec_over = dict(overrides.get("recognition", {}))
    return {"segmentation": resolve_segment_params(config.get("segmentation"), preset, seg_over),
            "recognition": resolve_recognition_params(config.get("recognition"), rec_over)}


def run_batch(command: str, sources: Sequence[str], out_dir: str, *, db: Optional[str] = None,
              outputs: str = "pcd,png,json", resume: bool = False, preset: str = "default",
              config: Optional[Mapping[str, Any]] = None,
              overrides: Optional[Mapping[str, Any]] = None,
              color_pattern: str = "{id}-color.png", depth_pattern: str = "{id}-depth.png",
              meta_pattern: str = "{id}-meta.json", intrinsics: Optional[str] = None,
              scheduler: Optional[str] = None, client: Any = None, workers: int = 2,
              retries: int = 2, max_in_flight: int = 1000,
              progress: bool = True) -> Dict[str, Any]:
    """Runs ``command`` ("segment" or "recognize", which needs ``db``) over every frame of
    ``sources`` on a Dask cluster and returns the summary written to ``OUT/summary.json``.

    ``client`` (a ``distributed.Client``) or ``scheduler`` (its address) use a running cluster;
    otherwise a ``LocalCluster`` of ``workers`` processes, one thread each, on the loopback
    interface is started and closed. ``config`` is the ``--config`` layout (for recognize:
    ``{"segmentation": ..., "recognition": ...}``) and ``overrides`` names parameters as
    :class:`proxseg.SegmentParams` does (for recognize: ``{"segmentation": {...},
    "recognition": {...}}``). ``retries``: further runs of a task that raised (a frame's bad
    input does not raise: it is a row with "error"). ``max_in_flight``: frames submitted to the
    cluster at once (more than its workers, so that none waits; the rest follow as these
    finish). The summary holds counts and the failed frames' rows; :func:`frame_rows` reads
    every frame's. Raises ValueError / OSError for bad input before any work starts."""
    if Client is None:
        raise ImportError("proxseg.dask needs Dask distributed (apt install python3-distributed)")
    if command not in ("segment", "recognize"):
        raise ValueError(f"command {command!r} (expected 'segment' or 'recognize')")
    if command == "recognize" and not db:
        raise ValueError("recognize needs db (the model database folder)")
    if max_in_flight < 1:
        raise ValueError(f"max_in_flight {max_in_flight} (expected 1 or more)")
    out_dir = os.fspath(out_dir)
    outputs = _proxseg._canonical_outputs(outputs)
    params = _parameters(command, preset, config, overrides or {})
    sources = [os.fspath(s) for s in sources]
    header: Dict[str, Any] = {"command": command, "outputs": outputs, "parameters": params}
    if command == "recognize":
        assert db is not None  # checked above: recognize needs a database
        header["database"] = os.fspath(db)
    # The frames, the output folder's checks, what earlier runs finished and the summary log,
    # as the CLI's --batch starts (proxseg/io/batch_start.hpp).
    start = _proxseg._start_batch(sources, color_pattern, depth_pattern, meta_pattern,
                                  os.fspath(intrinsics) if intrinsics else "", out_dir, header,
                                  resume)
    for line in start["damaged"]:  # lines of the earlier logs that could not be read: skipped
        warnings.warn(line)
    todo, log = start["todo"], start["log"]
    if progress:
        if start["redone"]:
            sys.stderr.write(f"proxseg.dask: note: {out_dir} holds {_frames(start['redone'])} an "
                             "earlier run finished; doing them again (--resume skips them)\n")
        if start["changed"]:
            sys.stderr.write(f"proxseg.dask: note: {_frames(start['changed'])} whose input "
                             "changed (size or time) since an earlier run finished them; doing "
                             "them again\n")
        if start["unproven"]:
            sys.stderr.write(f"proxseg.dask: note: {_frames(start['unproven'])} logged without "
                             "their inputs' size and time or the settings' fingerprint (an older "
                             "proxseg's log); doing them again\n")
        sys.stderr.write(f"proxseg.dask: {_frames(start['frames'])}"
                         + (f", {start['frames'] - len(todo)} done before" if resume else "")
                         + "\n")

    job = {"command": command, "out_dir": out_dir, "outputs": outputs,
           "segmentation": params if command == "segment" else params["segmentation"],
           "recognition": params.get("recognition") if command == "recognize" else None,
           "db": os.fspath(db) if db else None}
    cluster = None
    own_client = client is None
    if own_client:
        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address="127.0.0.1:0")
            client = Client(cluster)
    peak = 0.0
    try:
        client.register_worker_plugin(_BatchWorker(job), name=_PLUGIN)
        bar = _Progress(len(todo), not progress)
        run_id = f"{os.getpid()}-{time.time_ns()}"

        def submit(frame: Dict[str, str]) -> Any:
            return client.submit(_run_frame, frame, key=f"proxseg-{run_id}-{frame['id']}",
                                 retries=retries, pure=False)

        # At most max_in_flight tasks on the cluster at once, the next one submitted as one
        # finishes: the scheduler's and this process's memory do not grow with the batch.
        waiting = iter(todo)
        running = as_completed([submit(f) for f in itertools.islice(waiting, max_in_flight)])
        for future in running:
            row = future.result()
            following = next(waiting, None)
            if following is not None:
                running.add(submit(following))
            log.append(row)
            peak = max(peak, row.get("rss_mib", 0.0))
            if "error" in row:
                sys.stderr.write(f"proxseg.dask: error: {row['error']}\n")
            bar.step(row["frame"], failed="error" in row)
            future.release()
        log.close(False, peak)
    except BaseException:
        log.close(True, peak)
        raise
    finally:
        if own_client:
            client.close()
            if cluster is not None:
                cluster.close()
    # What a worker killed mid-frame left (hidden temporary files): its frame was done again.
    _proxseg._remove_stale_temporaries(out_dir, todo)
    summary = _proxseg._summarize([log.path], True)
    _write_atomic(os.path.join(out_dir, "summary.json"), json.dumps(summary, indent=2) + "\n")
    return summary


def _parse_set(items: Sequence[str]) -> Dict[str, Any]:
    """--set NAME=VALUE (VALUE as JSON when it parses, else a string)."""
    out: Dict[str, Any] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise ValueError(f"--set {item}: expected NAME=VALUE (e.g. voxel_size=0.01)")
        try:
            out[name] = json.loads(value)
        except json.JSONDecodeError:
            out[name] = value
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python3 -m proxseg.dask {segment,recognize} --batch SOURCE... -o OUT [options]``.
    Exit codes as the CLI's: 0, 1 (bad input or a failed frame), 2 (usage)."""
    parser = argparse.ArgumentParser(
        prog="python3 -m proxseg.dask",
        description="Run proxseg segment/recognize --batch on a Dask cluster (docs/batch.md).")
    parser.add_argument("command", choices=["segment", "recognize"])
    parser.add_argument("--batch", nargs="+", required=True, metavar="SOURCE",
                        help="folders (recursive), list files, globs or .pcd/.ply files")
    parser.add_argument("-o", "--output", required=True, help="output folder")
    parser.add_argument("--db", help="model database (recognize)")
    parser.add_argument("--outputs", default="pcd,png,json",
                        help="labels, pcd, png, json or all, comma-separated")
    parser.add_argument("--resume", action="store_true",
                        help="skip the frames an earlier run into OUT finished")
    parser.add_argument("--color-pattern", default="{id}-color.png")
    parser.add_argument("--depth-pattern", default="{id}-depth.png")
    parser.add_argument("--meta-pattern", default="{id}-meta.json")
    parser.add_argument("--intrinsics", help="camera JSON for RGB-D pairs without a meta file")
    parser.add_argument("--preset", default="default", choices=["default", "paper"])
    parser.add_argument("--config", help="JSON parameters over the preset, as the CLI's")
    parser.add_argument("--threads", type=int,
                        help="threads per frame (0 = all cores; the parameter `threads`)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="a parameter by name, as proxseg.SegmentParams takes it "
                             "(recognize: recognition.NAME=VALUE for a recognition one)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler "
                                            "(default: a LocalCluster on this machine)")
    parser.add_argument("--workers", type=int, default=2,
                        help="LocalCluster worker processes (default 2)")
    parser.add_argument("--retries", type=int, default=2)
    parser.add_argument("--json", action="store_true", help="print the summary on stdout")
    args = parser.parse_args(argv)
    if args.command == "recognize" and not args.db:
        parser.error("recognize needs --db")
    if args.workers < 1:
        parser.error("--workers must be at least 1")
    try:
        config = None
        if args.config:
            with open(args.config) as f:
                config = json.load(f)
        overrides = _parse_set(args.set)
        if args.threads is not None:
            overrides["threads"] = args.threads
        if args.command == "recognize":
            rec = {k.split(".", 1)[1]: v for k, v in overrides.items()
                   if k.startswith("recognition.")}
            seg = {k: v for k, v in overrides.items() if not k.startswith("recognition.")}
            if "threads" in seg:
                rec["threads"] = seg["threads"]
            overrides = {"segmentation": seg, "recognition": rec}
        summary = run_batch(args.command, args.batch, args.output, db=args.db,
                            outputs=args.outputs, resume=args.resume, preset=args.preset,
                            config=config, overrides=overrides,
                            color_pattern=args.color_pattern, depth_pattern=args.depth_pattern,
                            meta_pattern=args.meta_pattern, intrinsics=args.intrinsics,
                            scheduler=args.scheduler, workers=args.workers,
                            retries=args.retries)
    except (ValueError, OSError, json.JSONDecodeError) as e:
        sys.stderr.write(f"proxseg.dask: error: {e}\n")
        return 1
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{os.path.join(args.output, 'summary.json')}: {summary['frames_done']} of "
              f"{_frames(summary['frames_total'])} done"
              + (f", {summary['frames_failed']} failed" if summary["frames_failed"] else ""))
    return 1 if summary["frames_failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
