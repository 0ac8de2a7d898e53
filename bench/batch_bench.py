#!/usr/bin/env python3
"""Batch work over a dataset (`make bench-batch`): throughput, bytes written, memory over a long
batch, and what 100,000 frames would cost.

1. Throughput on the same frames (90 mOSD learn scenes, learn0-44 twice, and the 10 YCB-Video
   RGB-D pairs; a folder of symbolic links under --out), default outputs (pcd,png,json):
   (a) one `proxseg segment --batch` process, all cores; (b) the same with --threads 1;
   (c) `python3 -m proxseg.dask segment --batch` with 2 workers and --threads 1; (d) one
   `proxseg segment` process per frame, one after the other. The configurations alternate over
   --rounds rounds (order reversed every other round); medians are reported. For the batch runs
   the summary.jsonl is polled, which gives the rate from the first to the last finished frame
   (without start-up); a LocalCluster is also started and closed alone to time Dask's own
   start-up. The outputs of every configuration are compared (k, candidates, and the bytes of
   the PCD and PNG of every frame).
2. Bytes written per frame for each --outputs choice (18 mOSD + 2 YCB frames), beside the
   uncompressed binary PCD of the same points and fields.
3. Memory over a long batch: `segment --batch --outputs labels` over --frames-long frames
   (cycling the 45 mOSD scenes and the 10 YCB pairs), the resident set after each frame from
   summary.json. Exits 1 when the resident set grows by more than --max-growth % from the frame
   after warm-up (100) to the last frame.
4. An estimate for 100,000 frames on N workers from the Dask run's rate per worker.

    python3 bench/batch_bench.py --build build --data ../shared/data --out build/bench-out
    python3 bench/batch_bench.py --quick ...   # smoke run: 20 frames, 100 long frames, 1 round
"""

import argparse
import datetime
import hashlib
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

MB = 1e6  # bytes, decimal: file sizes, bandwidth
GB = 1e9
CONFIGS = {
    "a": "`segment --batch`, one process, all cores",
    "b": "`segment --batch --threads 1`, one process",
    "c": "`python3 -m proxseg.dask`, 2 workers, `--threads 1`",
    "d": "`segment` once per frame (a process each), all cores",
}
OUTPUT_CHOICES = ["labels", "pcd", "png", "json", "pcd,png,json", "all"]

# Dask's own start-up and shutdown, in a fresh interpreter as proxseg.dask pays them.
CLUSTER_ALONE = r"""
import json, time
t0 = time.perf_counter()
from distributed import Client, LocalCluster
import proxseg.dask  # noqa: F401  (what `python3 -m proxseg.dask` imports)
t1 = time.perf_counter()
cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                       dashboard_address=None)
client = Client(cluster)
client.wait_for_workers(2)
t2 = time.perf_counter()
client.close()
cluster.close()
t3 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "start_s": t2 - t1, "close_s": t3 - t2}))
"""


# ---- frame sets: folders of symbolic links ----

def learn_scenes(data):
    learn = sorted(Path(data, "mosd/learn").glob("learn*.pcd"), key=lambda p: int(p.stem[5:]))
    if len(learn) != 45:
        sys.exit(f"batch_bench: expected 45 mOSD learn scenes in {data}/mosd/learn, found {len(learn)}")
    return learn


def ycb_pairs(data):
    folder = Path(data, "ycbv/frames")
    ids = sorted(p.name[:-len("-color.png")] for p in folder.glob("*-color.png"))
    if len(ids) != 10:
        sys.exit(f"batch_bench: expected 10 YCB-Video pairs in {folder}, found {len(ids)}")
    return [{"color": folder / f"{i}-color.png", "depth": folder / f"{i}-depth.png",
             "meta": folder / f"{i}-meta.json", "name": i} for i in ids]


def link(src, dst):
    dst.parent.mkdir(parents=True, exist_ok=True)
    os.symlink(os.path.abspath(src), dst)


def make_set(folder, clouds, pairs):
    """folder/mosd/sceneNNN.pcd for the clouds and folder/ycb/<name>-{color,depth,meta} for the
    pairs. Returns the frames as the CLI names them: {"id", "kind", "cloud" | "color", ...}."""
    shutil.rmtree(folder, ignore_errors=True)
    frames = []
    for i, c in enumerate(clouds):
        dst = folder / "mosd" / f"scene{i:03d}.pcd"
        link(c, dst)
        frames.append({"id": f"mosd/scene{i:03d}", "kind": "mosd", "cloud": dst, "source": c.name})
    for p in pairs:
        f = {"id": f"ycb/{p['name']}", "kind": "ycb", "source": p["name"]}
        for part in ("color", "depth", "meta"):
            dst = folder / "ycb" / f"{p['name']}-{part}{p[part].suffix}"
            link(p[part], dst)
            f[part] = dst
        frames.append(f)
    return frames


def make_long_set(folder, learn, pairs, n):
    """n frames fNNNNN, cycling the 45 clouds then the 10 pairs."""
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    cycle = len(learn) + len(pairs)
    kinds = []
    for i in range(n):
        j = i % cycle
        if j < len(learn):
            link(learn[j], folder / f"f{i:05d}.pcd")
            kinds.append("mosd")
        else:
            p = pairs[j - len(learn)]
            for part in ("color", "depth", "meta"):
                link(p[part], folder / f"f{i:05d}-{part}{p[part].suffix}")
            kinds.append("ycb")
    return kinds


# ---- runs ----

def summary_rows(jsonl):
    """Rows (not the header or end lines) of a summary.jsonl written so far."""
    try:
        text = Path(jsonl).read_text()
    except FileNotFoundError:
        return 0
    return sum(1 for line in text.split("\n")[:-1]
               if line and not line.startswith('{"header"') and not line.startswith('{"end"'))


def run_polled(cmd, out_dir, log, env=None, poll=0.02, parallel=1):
    """Runs a batch command writing out_dir/summary.jsonl, polling it: wall time, the times (from
    the start) at which the first and the last row appeared, and the rate between them:
    (rows - parallel) / (last - first), parallel = frames in flight at once (the first of each
    worker end at about the same time, after the same work)."""
    jsonl = Path(out_dir, "summary.jsonl")
    with open(log, "w") as err:
        start = time.perf_counter()
        proc = subprocess.Popen([str(c) for c in cmd], stdout=subprocess.DEVNULL, stderr=err,
                                env=env)
        seen, size, first, last = 0, -1, None, None
        while proc.poll() is None:
            try:
                s = jsonl.stat().st_size
            except FileNotFoundError:
                s = -1
            if s != size:
                size = s
                now = time.perf_counter() - start
                n = summary_rows(jsonl)
                if n > seen:
                    first = now if first is None else first
                    last, seen = now, n
            time.sleep(poll)
        wall = time.perf_counter() - start
    if proc.returncode != 0:
        sys.stderr.write(Path(log).read_text()[-3000:])
        sys.exit(f"batch_bench: {' '.join(map(str, cmd))} exited {proc.returncode} (log: {log})")
    n = summary_rows(jsonl)
    if n > seen:  # rows written after the last poll: the process ended meanwhile
        last = wall if first is not None else None
        first = wall if first is None else first
        seen = n
    steady = ((seen - parallel) / (last - first)
              if first is not None and last > first and seen > parallel else None)
    return {"wall_s": wall, "first_row_s": first, "last_row_s": last, "rows_polled": seen,
            "steady_fps": steady}


def read_summary(out_dir, expected):
    """summary.json, with "rows": the frames' rows of summary.jsonl (one run: one a frame)."""
    s = json.loads(Path(out_dir, "summary.json").read_text())
    if s["frames_done"] != expected or s["frames_failed"]:
        sys.exit(f"batch_bench: {out_dir}: {s['frames_done']} of {expected} frames done, "
                 f"{s['frames_failed']} failed")
    lines = Path(out_dir, "summary.jsonl").read_text().splitlines()
    s["rows"] = [row for row in map(json.loads, lines) if "frame" in row]
    return s


def digest(path):
    return hashlib.sha1(Path(path).read_bytes()).hexdigest()[:16]


def fingerprint(out_dir, frames, reports):
    """Per frame: k, candidates and digests of the PCD and PNG (deterministic outputs; the JSON
    holds times). reports: {id: (k, candidates)}."""
    fp = {}
    for f in frames:
        prefix = Path(out_dir, f["id"])
        fp[f["id"]] = {"k": reports[f["id"]][0], "candidates": reports[f["id"]][1],
                       "pcd": digest(f"{prefix}.pcd"), "png": digest(f"{prefix}.png")}
    return fp


def run_batch_cli(build, src, out_dir, log, frames, extra=()):
    shutil.rmtree(out_dir, ignore_errors=True)
    r = run_polled([build / "proxseg", "segment", "--batch", src, "-o", out_dir, *extra], out_dir,
                   log)
    s = read_summary(out_dir, len(frames))
    r["summary"] = s
    return r


def run_dask(build, src, out_dir, log, frames, workers=2):
    shutil.rmtree(out_dir, ignore_errors=True)
    env = dict(os.environ, PYTHONPATH=str(build / "python") + (
        os.pathsep + os.environ["PYTHONPATH"] if os.environ.get("PYTHONPATH") else ""))
    r = run_polled([sys.executable, "-m", "proxseg.dask", "segment", "--batch", src, "-o", out_dir,
                    "--workers", str(workers), "--threads", "1"], out_dir, log, env=env,
                   parallel=workers)
    r["summary"] = read_summary(out_dir, len(frames))
    return r


def run_per_frame(build, out_dir, log, frames):
    shutil.rmtree(out_dir, ignore_errors=True)
    calls = []
    with open(log, "w") as err:
        start = time.perf_counter()
        for f in frames:
            prefix = Path(out_dir, f["id"])
            if f["kind"] == "mosd":
                cmd = [build / "proxseg", "segment", f["cloud"], "-o", prefix]
            else:
                cmd = [build / "proxseg", "segment", "--color", f["color"], "--depth", f["depth"],
                       "--meta", f["meta"], "-o", prefix]
            t = time.perf_counter()
            p = subprocess.run([str(c) for c in cmd], stdout=subprocess.DEVNULL, stderr=err)
            calls.append(time.perf_counter() - t)
            if p.returncode != 0:
                sys.exit(f"batch_bench: {' '.join(map(str, cmd))} exited {p.returncode} (log: {log})")
        wall = time.perf_counter() - start
    return {"wall_s": wall, "call_median_s": statistics.median(calls), "steady_fps": None}


def report_counts(report):
    return report["k"] if "k" in report else report["counts"]["k"], report["selection"]["candidates"]


def cluster_alone(build):
    env = dict(os.environ, PYTHONPATH=str(build / "python"))
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", CLUSTER_ALONE], capture_output=True, text=True,
                       env=env)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        sys.stderr.write(p.stderr[-3000:])
        sys.exit("batch_bench: starting a LocalCluster alone failed")
    r = json.loads(p.stdout.strip().splitlines()[-1])
    r["process_s"] = wall
    r["stderr"] = [l for l in p.stderr.splitlines() if l.strip()]
    return r


def other_stderr(log):
    """The lines of a run's stderr that are not its progress: Dask's warnings, errors."""
    keep = []
    for line in Path(log).read_text().replace("\r", "\n").splitlines():
        line = line.strip()
        if not line or re.match(r"^(\[\d+/\d+\]|proxseg(\.dask)?: \d+ frames)", line):
            continue
        keep.append(line)
    return keep


# ---- parts ----

def throughput(build, work, frames, src, rounds):
    runs = {c: [] for c in CONFIGS}
    alone = []
    fps = {}  # config -> round -> fingerprint
    logs = work / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    dask_stderr = []
    for r in range(rounds):
        order = list(CONFIGS) if r % 2 == 0 else list(reversed(CONFIGS))
        for c in order:
            out = work / "runs" / f"{c}-r{r + 1}"
            log = logs / f"{c}-r{r + 1}.stderr"
            print(f"batch_bench: throughput round {r + 1}/{rounds}, ({c}) {CONFIGS[c]} ...",
                  file=sys.stderr, flush=True)
            if c == "a":
                res = run_batch_cli(build, src, out, log, frames)
            elif c == "b":
                res = run_batch_cli(build, src, out, log, frames, ["--threads", "1"])
            elif c == "c":
                res = run_dask(build, src, out, log, frames)
                dask_stderr += other_stderr(log)
            else:
                res = run_per_frame(build, out, log, frames)
            if c == "d":
                reports = {f["id"]: report_counts(json.loads(Path(out, f["id"] + ".json").read_text()))
                           for f in frames}
            else:
                s = res.pop("summary")
                reports = {row["frame"]: (row["k"], row["candidates"]) for row in s["rows"]}
                res["row_ms_median"] = statistics.median(row["ms"] for row in s["rows"])
                res["peak_rss_mib"] = s["peak_rss_mib"]
            fps.setdefault(c, []).append(fingerprint(out, frames, reports))
            shutil.rmtree(out)
            res["round"] = r + 1
            runs[c].append(res)
            print(f"batch_bench:   {res['wall_s']:.1f} s", file=sys.stderr, flush=True)
            if c == "c":
                alone.append(cluster_alone(build))
                dask_stderr += alone[-1].pop("stderr")
    # Every configuration and round against (a) of round 1.
    ref = fps["a"][0]
    mismatches = []
    for c, rounds_fp in fps.items():
        for r, fp in enumerate(rounds_fp):
            for fid, v in fp.items():
                for key in ("k", "candidates", "pcd", "png"):
                    if v[key] != ref[fid][key]:
                        mismatches.append({"config": c, "round": r + 1, "frame": fid, "field": key,
                                           "value": v[key], "reference": ref[fid][key]})
    n = len(frames)
    med = {}
    for c in CONFIGS:
        wall = statistics.median(x["wall_s"] for x in runs[c])
        steady = [x["steady_fps"] for x in runs[c] if x["steady_fps"]]
        med[c] = {"wall_s": wall, "fps": n / wall,
                  "steady_fps": statistics.median(steady) if steady else None,
                  "first_row_s": statistics.median(x["first_row_s"] for x in runs[c])
                  if c != "d" else None}
    for c in CONFIGS:
        med[c]["wall_ratio_to_a"] = med[c]["wall_s"] / med["a"]["wall_s"]
        med[c]["fps_ratio_to_a"] = med[c]["fps"] / med["a"]["fps"]
    cl = {k: statistics.median(x[k] for x in alone) for k in ("import_s", "start_s", "close_s",
                                                              "process_s")}
    return {"frames": n, "mosd": sum(f["kind"] == "mosd" for f in frames),
            "ycb": sum(f["kind"] == "ycb" for f in frames), "rounds": rounds, "runs": runs,
            "median": med, "cluster_alone": alone, "cluster_alone_median": cl,
            "mismatches": mismatches, "dask_stderr": list(dict.fromkeys(dask_stderr))}


def pcd_uncompressed(path):
    """Size of the binary (uncompressed) PCD of the same points and fields: the file's own header
    with DATA binary, plus POINTS x the bytes of a point."""
    head = b""
    with open(path, "rb") as f:
        while True:
            line = f.readline()
            if not line:
                raise ValueError(f"{path}: no DATA line")
            head += line
            if line.startswith(b"DATA"):
                break
    fields = {}
    for line in head.decode("ascii", "replace").splitlines():
        parts = line.split()
        if parts and parts[0] in ("FIELDS", "SIZE", "COUNT", "POINTS", "DATA"):
            fields[parts[0]] = parts[1:]
    sizes = [int(s) for s in fields["SIZE"]]
    counts = [int(c) for c in fields.get("COUNT", ["1"] * len(sizes))]
    per_point = sum(s * c for s, c in zip(sizes, counts))
    header = head.replace(b"DATA " + fields["DATA"][0].encode(), b"DATA binary")
    return {"bytes": len(header) + int(fields["POINTS"][0]) * per_point,
            "fields": fields["FIELDS"], "bytes_per_point": per_point,
            "points": int(fields["POINTS"][0]), "compression": fields["DATA"][0]}


def bytes_written(build, work, frames, src):
    logs = work / "logs"
    out = {}
    uncompressed = {}
    for choice in OUTPUT_CHOICES:
        d = work / "runs" / f"bytes-{choice.replace(',', '+')}"
        print(f"batch_bench: bytes, --outputs {choice} ...", file=sys.stderr, flush=True)
        r = run_batch_cli(build, src, d, logs / f"bytes-{choice.replace(',', '+')}.stderr", frames,
                          ["--outputs", choice])
        rows = {row["frame"]: row for row in r["summary"]["rows"]}
        per = {}
        files = {}
        for f in frames:
            outs = rows[f["id"]]["outputs"]
            per[f["id"]] = sum(outs.values())
            for name, size in outs.items():
                ext = name[len(f["id"]):]  # ".label.png", ".pcd", ...
                files.setdefault(ext, []).append(size)
        if choice == "pcd":
            for f in frames:
                uncompressed[f["id"]] = pcd_uncompressed(Path(d, f["id"] + ".pcd"))
        shutil.rmtree(d)
        kinds = {k: [per[f["id"]] for f in frames if f["kind"] == k] for k in ("mosd", "ycb")}
        out[choice] = {"mean": statistics.mean(per.values()),
                       "mean_mosd": statistics.mean(kinds["mosd"]),
                       "mean_ycb": statistics.mean(kinds["ycb"]) if kinds["ycb"] else None,
                       "per_file_mean": {k: statistics.mean(v) for k, v in files.items()},
                       "per_frame": per}
    unc = {"mean": statistics.mean(u["bytes"] for u in uncompressed.values()),
           "mean_mosd": statistics.mean(uncompressed[f["id"]]["bytes"] for f in frames
                                        if f["kind"] == "mosd"),
           "mean_ycb": statistics.mean(uncompressed[f["id"]]["bytes"] for f in frames
                                       if f["kind"] == "ycb") if any(f["kind"] == "ycb" for f in frames) else None,
           "fields": next(iter(uncompressed.values()))["fields"],
           "bytes_per_point": next(iter(uncompressed.values()))["bytes_per_point"],
           "compression_of_written": sorted({u["compression"] for u in uncompressed.values()}),
           "points": {k: u["points"] for k, u in uncompressed.items()}}
    inputs = [sum(os.path.getsize(f[k]) for k in ("cloud", "color", "depth", "meta") if k in f)
              for f in frames]
    return {"frames": len(frames), "mosd": sum(f["kind"] == "mosd" for f in frames),
            "ycb": sum(f["kind"] == "ycb" for f in frames), "choices": out,
            "uncompressed_pcd": unc, "input_mean": statistics.mean(inputs)}


def memory(build, work, learn, pairs, n, max_growth):
    src = work / "frames-long"
    print(f"batch_bench: memory, {n} frames with --outputs labels ...", file=sys.stderr, flush=True)
    kinds = make_long_set(src, learn, pairs, n)
    d = work / "runs" / "long"
    r = run_batch_cli(build, src, d, work / "logs" / "long.stderr", kinds, ["--outputs", "labels"])
    rows = sorted(r.pop("summary")["rows"], key=lambda row: row["frame"])  # fNNNNN: run order
    shutil.rmtree(d)
    shutil.rmtree(src)
    rss = [row["rss_mib"] for row in rows]
    ref = min(100, max(1, n // 5))  # the frame after warm-up (100 in the full run)
    marks = sorted({m for m in (1, 10, 100, 500, 1000, 2000, 5000, 10000) if m <= n} | {ref, n})
    growth = 100 * (rss[-1] - rss[ref - 1]) / rss[ref - 1]
    early = statistics.median(rss[ref - 1:2 * ref])      # frames ref..2 ref
    late = statistics.median(rss[-ref:])                 # the last ref frames
    growth_median = 100 * (late - early) / early
    return {"frames": n, "wall_s": r["wall_s"], "fps": n / r["wall_s"],
            "steady_fps": r["steady_fps"], "reference_frame": ref,
            "rss_at": {str(m): rss[m - 1] for m in marks}, "rss_max": max(rss),
            "rss_max_frame": rss.index(max(rss)) + 1, "growth_pct": growth,
            "window_early": [ref, 2 * ref], "window_late": [n - ref + 1, n],
            "median_early_mib": early, "median_late_mib": late,
            "growth_median_pct": growth_median, "max_growth_pct": max_growth,
            "ok": growth <= max_growth, "rss_mib": rss,
            "rss_mosd_median": statistics.median(x for x, k in zip(rss, kinds) if k == "mosd"),
            "rss_ycb_median": statistics.median(x for x, k in zip(rss, kinds) if k == "ycb")
            if "ycb" in kinds else None}


def estimate(tp, by):
    c = tp["median"]["c"]
    per_worker = (c["steady_fps"] or c["fps"]) / 2
    per_worker_wall = c["fps"] / 2
    rows = []
    for n in (1, 2, 8, 32, 64):
        rate = n * per_worker
        rows.append({"workers": n, "fps": rate, "hours": 100000 / rate / 3600,
                     "hours_with_wall_rate": 100000 / (n * per_worker_wall) / 3600,
                     "mb_per_s": {ch: rate * by["choices"][ch]["mean"] / MB for ch in OUTPUT_CHOICES},
                     "mb_per_s_read": rate * by["input_mean"] / MB})
    return {"per_worker_fps": per_worker, "per_worker_fps_wall": per_worker_wall,
            "from": "steady" if c["steady_fps"] else "wall", "rows": rows}


# ---- report ----

def fmt(x, d=1):
    return "-" if x is None else f"{x:.{d}f}"


def markdown(res, quick):
    tp, by, mem, est = res["throughput"], res["bytes"], res["memory"], res["estimate"]
    m = tp["median"]
    cl = tp["cluster_alone_median"]
    note = ("\n**Smoke run (`--quick`): too few frames for results.md.**\n" if quick else "")
    lines = [f"""## Batch: throughput, bytes written, memory over a long batch

`make bench-batch` (bench/batch_bench.py), {res['machine']['cores']} cores, {res['machine']['date']}, {res['machine']['version']}; load average {res['machine']['load_before']} before the run.
{note}
### Throughput

The same {tp['frames']} frames ({tp['mosd']} mOSD 640x480 clouds, learn0-44 cycled, and {tp['ycb']} YCB-Video RGB-D pairs), default outputs (pcd,png,json); {tp['rounds']} round{'s' if tp['rounds'] > 1 else ''}, the configurations alternating (order reversed every other round), medians.

| configuration | wall s | frames/s | wall / (a) | frames/s / (a) | frames/s from first to last finished frame | first row after s |
|---|---:|---:|---:|---:|---:|---:|"""]
    for c, name in CONFIGS.items():
        x = m[c]
        lines.append(f"| ({c}) {name} | {x['wall_s']:.1f} | {x['fps']:.2f} | {x['wall_ratio_to_a']:.2f} "
                     f"| {x['fps_ratio_to_a']:.2f} | {fmt(x['steady_fps'], 2)} | {fmt(x['first_row_s'], 1)} |")
    lines.append(f"""
(c)'s wall time includes Python's start-up, the LocalCluster's start and close and the workers' import of proxseg. A LocalCluster of 2 workers started and closed alone (a fresh interpreter, median of {len(tp['cluster_alone'])}): import of distributed and proxseg.dask {cl['import_s']:.1f} s, start until both workers are up {cl['start_s']:.1f} s, close {cl['close_s']:.1f} s; the whole process {cl['process_s']:.1f} s.

"From first to last finished frame" is (frames - frames in flight at once: 1, for (c) 2) / (time between the first and the last row of summary.jsonl, polled every 20 ms): the rate without start-up. (d) is one `proxseg segment` process per frame (median call {statistics.median(x['call_median_s'] for x in tp['runs']['d']) * 1000:.0f} ms).

Outputs of every configuration and round against (a)'s first: {'identical (k, candidates, and the bytes of every PCD and PNG)' if not tp['mismatches'] else f"**{len(tp['mismatches'])} differences** (batch.json, throughput.mismatches)"}.

### Bytes written per frame

`segment --batch --outputs CHOICE` on {by['frames']} of those frames ({by['mosd']} mOSD, {by['ycb']} YCB), the rows' "outputs" sizes; MB = 10^6 bytes.

| --outputs | files | mean kB/frame | mOSD cloud kB | YCB pair kB | 100k frames GB |
|---|---|---:|---:|---:|---:|""")
    for ch in OUTPUT_CHOICES:
        x = by["choices"][ch]
        files = ", ".join(f"{k} {v / 1e3:.0f} kB" for k, v in sorted(x["per_file_mean"].items()))
        lines.append(f"| {ch} | {files} | {x['mean'] / 1e3:.0f} | {x['mean_mosd'] / 1e3:.0f} | "
                     f"{fmt(x['mean_ycb'] and x['mean_ycb'] / 1e3, 0)} | {x['mean'] * 1e5 / GB:.1f} |")
    u = by["uncompressed_pcd"]
    lines.append(f"| uncompressed binary PCD (for comparison) | {' '.join(u['fields'])}, {u['bytes_per_point']} bytes a point + header | "
                 f"{u['mean'] / 1e3:.0f} | {u['mean_mosd'] / 1e3:.0f} | {fmt(u['mean_ycb'] and u['mean_ycb'] / 1e3, 0)} | {u['mean'] * 1e5 / GB:.1f} |")
    pcd = by["choices"]["pcd"]["mean"]
    lines.append(f"""
The written PCD ({', '.join(u['compression_of_written'])}) is {100 * pcd / u['mean']:.0f} % of the uncompressed binary PCD of the same points and fields.

### Memory over a long batch

`segment --batch --outputs labels` over {mem['frames']} frames (the 45 mOSD scenes and the 10 YCB pairs cycled), all cores, {mem['wall_s']:.0f} s ({mem['fps']:.2f} frames/s); resident set after each frame (the rows' "rss_mib").

| after frame | {' | '.join(mem['rss_at'])} | highest |
|---|{'---:|' * (len(mem['rss_at']) + 1)}
| RSS MiB | {' | '.join(f'{v:.1f}' for v in mem['rss_at'].values())} | {mem['rss_max']:.1f} (frame {mem['rss_max_frame']}) |

Growth from frame {mem['reference_frame']} (after warm-up) to the last: {mem['growth_pct']:+.1f} % of the RSS at frame {mem['reference_frame']}; median of frames {mem['window_early'][0]}-{mem['window_early'][1]} ({mem['median_early_mib']:.1f} MiB) to median of the last {mem['reference_frame']} ({mem['median_late_mib']:.1f} MiB): {mem['growth_median_pct']:+.1f} %. The benchmark fails above {mem['max_growth_pct']:.0f} % (the first figure){'' if mem['ok'] else ': **FAILED**'}.

### Estimate: 100,000 frames on N workers

From (c)'s rate per worker: {est['per_worker_fps']:.2f} frames/s ({'from the first to the last finished frame' if est['from'] == 'steady' else 'wall time'}, / 2 workers; with the whole wall time, start-up included: {est['per_worker_fps_wall']:.2f}). Hours = 100,000 / (N x rate per worker). Assumes linear scaling, one core per worker as here (2 workers, `--threads 1`), the {by['mosd']}:{by['ycb']} mix of 640x480 mOSD clouds and YCB pairs above, and a shared filesystem that sustains N x rate x bytes per frame: the writes (MB/s per --outputs choice) and the reading of the inputs ({by['input_mean'] / MB:.1f} MB a frame on average: the last column).

| workers N | frames/s | hours | {' | '.join(f'MB/s written, {ch}' for ch in OUTPUT_CHOICES)} | MB/s read |
|---:|---:|---:|{'---:|' * (len(OUTPUT_CHOICES) + 1)}""")
    for r in est["rows"]:
        lines.append(f"| {r['workers']} | {r['fps']:.1f} | {r['hours']:.2f} | "
                     + " | ".join(f"{r['mb_per_s'][ch]:.1f}" for ch in OUTPUT_CHOICES)
                     + f" | {r['mb_per_s_read']:.1f} |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--data", default="../shared/data")
    ap.add_argument("--out", default="build/bench-out")
    ap.add_argument("--rounds", type=int, help="throughput rounds (default 2; --quick 1)")
    ap.add_argument("--frames-long", type=int,
                    help="frames of the memory batch (default 2000; --quick 100)")
    ap.add_argument("--max-growth", type=float, default=5.0,
                    help="fail when the memory batch's RSS grows more than this, %% (default 5)")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: 20 frames (18 mOSD + 2 YCB), 100 long frames, 1 round; "
                         "writes batch-quick.md/.json")
    args = ap.parse_args()
    rounds = args.rounds or (1 if args.quick else 2)
    n_long = args.frames_long or (100 if args.quick else 2000)
    build = Path(args.build).resolve()
    out = Path(args.out).resolve()
    work = out / ("batch-quick" if args.quick else "batch")
    work.mkdir(parents=True, exist_ok=True)
    for exe in (build / "proxseg", build / "python" / "proxseg"):
        if not exe.exists():
            sys.exit(f"batch_bench: {exe} is missing (build the targets proxseg_cli and _proxseg)")

    version = subprocess.run([str(build / "proxseg"), "--version"], capture_output=True,
                             text=True).stdout.strip().splitlines()[0]
    learn, pairs = learn_scenes(args.data), ycb_pairs(args.data)
    if args.quick:
        frames = make_set(work / "frames", learn[:18], pairs[:2])
        bframes = frames
    else:
        frames = make_set(work / "frames", [learn[i % 45] for i in range(90)], pairs)
        bframes = make_set(work / "frames-bytes", learn[:18], pairs[:2])
    load_before = os.getloadavg()
    t0 = time.perf_counter()
    res = {"machine": {"cores": os.cpu_count(), "date": datetime.date.today().isoformat(),
                       "version": version, "load_before": " ".join(f"{x:.2f}" for x in load_before),
                       "python": sys.version.split()[0]}}
    try:
        import distributed
        res["machine"]["distributed"] = distributed.__version__
    except ImportError:
        pass
    res["throughput"] = throughput(build, work, frames, work / "frames", rounds)
    res["bytes"] = bytes_written(build, work, bframes, bframes[0]["cloud"].parent.parent)
    res["memory"] = memory(build, work, learn, pairs, n_long, args.max_growth)
    res["estimate"] = estimate(res["throughput"], res["bytes"])
    res["total_s"] = time.perf_counter() - t0
    res["quick"] = args.quick
    res["machine"]["load_after"] = " ".join(f"{x:.2f}" for x in os.getloadavg())

    stem = "batch-quick" if args.quick else "batch"
    md = markdown(res, args.quick)

    def plain(o):
        return str(o) if isinstance(o, Path) else o
    Path(out, stem + ".json").write_text(json.dumps(res, indent=2, default=plain) + "\n")
    Path(out, stem + ".md").write_text(md)
    print(md)
    for line in res["throughput"]["dask_stderr"]:
        print(f"batch_bench: dask stderr: {line}", file=sys.stderr)
    if res["throughput"]["mismatches"]:
        print(f"batch_bench: {len(res['throughput']['mismatches'])} output differences between "
              f"configurations (see {stem}.json)", file=sys.stderr)
    print(f"batch_bench: {res['total_s']:.0f} s; {out / (stem + '.md')}, {out / (stem + '.json')}",
          file=sys.stderr)
    if not res["memory"]["ok"]:
        print(f"batch_bench: the resident set grew by {res['memory']['growth_pct']:.1f} % over the "
              f"long batch (more than {args.max_growth:g} %)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
