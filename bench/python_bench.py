#!/usr/bin/env python3
"""The Python module's overhead (`make bench-python`), beside the C++ library and the CLI in the
same run, as ratios (the machine is shared and noisy: the two sides alternate).

1. One call: proxseg.segment() from Python against proxseg::segment() from a C++ process (bench/
   segment_loop), on the same 640x480 mOSD scenes, alternating call by call. Also the overhead
   within each Python call: its wall time minus the C++ segment()'s own (report
   "times_ms.total", which leaves out the destruction of segment()'s locals).
2. A loop of 100 frames: read + segment in one Python process against 100 `proxseg segment`
   CLI processes (each writes its PCD, PNG and JSON), in alternating blocks of 10; and the CLI
   with its labels read back into Python (the file round trip a Python user of the CLI pays).
3. Open3D clouds: segment(path) against segment(from_open3d(o3d.io.read_point_cloud(path)))
   on the same scenes, alternating, wall and CPU time of the process: the cloud's call timed
   without the Open3D read (what a cloud already in memory costs) and with it; and the cloud
   without its image grid (the unorganized path, once per scene), which from_open3d's warning
   quotes.

    python3 bench/python_bench.py --build build --data ../shared/data --out build/bench-out
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--data", default="../shared/data")
    ap.add_argument("--out", default="build/bench-out")
    ap.add_argument("--scenes", type=int, default=6, help="scenes of part 1")
    ap.add_argument("--rounds", type=int, default=8, help="rounds over the scenes of part 1")
    ap.add_argument("--calls", type=int, default=3, help="paired calls per scene per round")
    ap.add_argument("--frames", type=int, default=100, help="frames of part 2")
    args = ap.parse_args()
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())  # before the run: a shared machine
    build = Path(args.build).resolve()
    sys.path.insert(0, str(build / "python"))
    import proxseg

    learn = sorted(Path(args.data, "mosd/learn").glob("*.pcd"), key=lambda p: int(p.stem[5:]))
    scenes = learn[:: max(1, len(learn) // args.scenes)][: args.scenes]

    # 1. One call, C++ and Python alternating call by call on the same scene.
    frames = [proxseg.read_point_cloud(s) for s in scenes]
    cxx = subprocess.Popen([str(build / "bench/segment_loop"), *map(str, scenes)],
                           stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def cpp_call(i):
        cxx.stdin.write(f"{i}\n")
        cxx.stdin.flush()
        return float(cxx.stdout.readline().split()[0])

    for i, f in enumerate(frames):  # warm-up of both (OpenMP threads, caches, the heap)
        cpp_call(i)
        proxseg.segment(f)
    cpp, py, inner, ratios = [], [], [], []
    for _ in range(args.rounds):
        for i, f in enumerate(frames):
            for _ in range(args.calls):
                c = cpp_call(i)
                t = time.perf_counter()
                r = proxseg.segment(f)
                ms = (time.perf_counter() - t) * 1000
                cpp.append(c)
                py.append(ms)
                inner.append(ms - r.times_ms["total"])
                ratios.append(ms / c)
    cxx.stdin.close()
    cxx.wait()
    one_call = {"cpp_median_ms": statistics.median(cpp), "python_median_ms": statistics.median(py),
                "ratio": statistics.median(py) / statistics.median(cpp),
                "paired_ratio_median": statistics.median(ratios),
                "python_overhead_median_ms": statistics.median(inner),
                "python_overhead_share": statistics.median(inner) / statistics.median(py),
                "calls_each": len(py)}

    # 2. 100 frames: one Python process against 100 CLI processes, in blocks of 10.
    paths = [learn[i % len(learn)] for i in range(args.frames)]
    cli, loop, cli_read = 0.0, 0.0, 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for b in range(0, len(paths), 10):
            block = paths[b:b + 10]
            t = time.perf_counter()
            for i, p in enumerate(block):
                subprocess.run([str(build / "proxseg"), "segment", str(p), "-o",
                                f"{tmp}/f{b + i}"], capture_output=True, check=True)
            cli += time.perf_counter() - t
            t = time.perf_counter()
            for i in range(len(block)):
                proxseg.read_point_cloud(f"{tmp}/f{b + i}.pcd").label
            cli_read += time.perf_counter() - t
            t = time.perf_counter()
            for p in block:
                proxseg.segment(proxseg.read_point_cloud(p))
            loop += time.perf_counter() - t
    hundred = {"frames": len(paths), "cli_s": cli, "cli_with_read_back_s": cli + cli_read,
               "python_loop_s": loop, "speedup": cli / loop,
               "speedup_with_read_back": (cli + cli_read) / loop}

    clouds = open3d_clouds(proxseg, scenes, args.rounds)
    result = {"one_call": one_call, "loop": hundred, "open3d": clouds,
              "proxseg": proxseg.build_info(),
              "cores": os.cpu_count(), "load_before": load, "scenes": [s.name for s in scenes]}
    Path(args.out).mkdir(parents=True, exist_ok=True)
    Path(args.out, "python.json").write_text(json.dumps(result, indent=2) + "\n")
    md = f"""## Python module: overhead against C++ and the CLI

Python module against the C++ library and the CLI (`make bench-python`, one run, {os.cpu_count()} cores, commit {result['proxseg']['commit'][:7]}; load average {load} before the run).

| measure | C++ / CLI | Python | ratio |
|---|---|---|---|
| segment() on a 640x480 mOSD frame, median ms ({one_call['calls_each']} calls each, {len(scenes)} scenes) | {one_call['cpp_median_ms']:.1f} | {one_call['python_median_ms']:.1f} | Python / C++ = {one_call['ratio']:.3f} (median of the paired calls' ratios: {one_call['paired_ratio_median']:.3f}) |
| overhead inside a Python call (its wall time minus the C++ segment()'s), median ms | - | {one_call['python_overhead_median_ms']:.2f} | {100 * one_call['python_overhead_share']:.1f} % of the call |
| {hundred['frames']} frames, read + segment, s | {hundred['cli_s']:.1f} (CLI processes) | {hundred['python_loop_s']:.1f} (one process) | CLI / Python = {hundred['speedup']:.2f}x |
| the same, the CLI's labels read back into Python, s | {hundred['cli_with_read_back_s']:.1f} | {hundred['python_loop_s']:.1f} | {hundred['speedup_with_read_back']:.2f}x |

The C++ side calls `keep_freed_memory()` as the README asks of programs that segment frame after
frame; `import proxseg` does the same (without it the Python call took 1.6 times the C++ one).
C++ and Python alternate call by call on the same scene (after one warm-up call of each per
scene); "overhead inside a Python call" is its wall time minus segment()'s own total, which leaves
out the destruction of segment()'s locals and so counts them as overhead.
"""
    md += open3d_table(clouds)
    Path(args.out, "python.md").write_text(md)
    print(md)


def timed(fn):
    """fn()'s result, wall ms and CPU ms of the process (all threads)."""
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return out, (time.perf_counter() - w) * 1000, (time.process_time() - c) * 1000


def open3d_clouds(proxseg, scenes, rounds):
    """Part 3: the cost of an Open3D cloud input against the path's, medians over the calls."""
    try:
        import open3d as o3d
    except ImportError:
        return {"skipped": "open3d is not installed"}
    import numpy as np
    rows = {k: [] for k in ("path_wall", "path_cpu", "cloud_wall", "cloud_cpu", "read_wall",
                            "read_cpu", "unorganized_wall", "unorganized_cpu")}
    same = True
    for s in scenes:  # warm-up; the labels must be the path's
        same &= bool(np.array_equal(proxseg.segment(s).labels,
                                    proxseg.segment(proxseg.from_open3d(
                                        o3d.io.read_point_cloud(str(s)))).labels))
    for _ in range(rounds):
        for s in scenes:
            _, w, c = timed(lambda: proxseg.segment(s))
            rows["path_wall"].append(w)
            rows["path_cpu"].append(c)
            cloud, w, c = timed(lambda: o3d.io.read_point_cloud(str(s)))
            rows["read_wall"].append(w)
            rows["read_cpu"].append(c)
            _, w, c = timed(lambda: proxseg.segment(proxseg.from_open3d(cloud)))
            rows["cloud_wall"].append(w)
            rows["cloud_cpu"].append(c)
    for s in scenes:
        cloud = o3d.io.read_point_cloud(str(s))
        flat = proxseg.Frame(np.asarray(cloud.points, dtype=np.float32), np.asarray(cloud.colors))
        _, w, c = timed(lambda: proxseg.segment(flat))
        rows["unorganized_wall"].append(w)
        rows["unorganized_cpu"].append(c)
    m = {k: statistics.median(v) for k, v in rows.items()}
    m["with_read_wall"] = m["cloud_wall"] + m["read_wall"]
    m["with_read_cpu"] = m["cloud_cpu"] + m["read_cpu"]
    m.update(calls_each=len(rows["path_wall"]), unorganized_calls=len(rows["unorganized_wall"]),
             same_labels=same, open3d=o3d.__version__)
    return m


def open3d_table(m):
    """Part 3 as markdown."""
    if "skipped" in m:
        return f"\nOpen3D clouds: skipped ({m['skipped']}).\n"

    def row(what, key):
        return (f"| {what} | {m[key + '_wall']:.1f} | {m[key + '_cpu']:.1f} | "
                f"{m[key + '_wall'] / m['path_wall']:.2f} | {m[key + '_cpu'] / m['path_cpu']:.2f} |")
    lines = [
        "", "### Open3D clouds against paths", "",
        f"segment() of the same scenes from the path and from `o3d.io.read_point_cloud(path)` "
        f"(Open3D {m['open3d']}, which keeps an organized PCD's 307,200 points: from_open3d "
        f"keeps the grid), alternating, {m['calls_each']} calls each; medians; CPU time is the "
        f"process's (all threads). Same labels as the path's: {m['same_labels']}.", "",
        "| input | wall ms | CPU ms | wall ratio to the path | CPU ratio to the path |",
        "|---|---|---|---|---|",
        row("`segment(path)` (proxseg's PCD reader included)", "path"),
        row("`segment(from_open3d(cloud))`, the cloud in memory (Open3D read excluded)", "cloud"),
        row("the same with `o3d.io.read_point_cloud` included", "with_read"),
        row(f"the cloud without its grid (unorganized path; {m['unorganized_calls']} calls)",
            "unorganized"),
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
