#!/usr/bin/env python3
"""Compares what builds of proxseg answer on the same frames (`make test-numerics`, issue 50).

Each build's CLI segments mOSD learn (default and paper presets) and the generated sets, builds a
database of the 21 YCB-Video models and recognises both YCB-Video scenes against it. Against the
first build (the reference), each other build must give, frame by frame, the same candidates (as
many, and the same points: instance labels), the same names, and labels equal on at least
99.9 % of the labelled points (points labelled by either build). Poses are compared within a
tolerance (the largest translation and rotation difference is printed).

Usage: compare-builds.py --data DATA --generated DIR --work DIR NAME=BUILD_DIR [NAME=BUILD_DIR ...]
       [--env NAME=VAR=VALUE ...]  (environment of one build's runs, e.g. OpenCV's dispatch held
       back); the first NAME is the reference. Prints a Markdown table; exits 1 when a build
       differs beyond the limits above.
"""
import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

LABEL_SHARE = 0.999


def run(cmd, env):
    done = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode not in (0,):
        sys.exit(f"compare-builds: {' '.join(map(str, cmd))} failed ({done.returncode}):\n{done.stderr}")


def frame_sets(data, generated):
    """(name, kind, sources, extra CLI arguments) of every set compared."""
    learn = str(Path(data) / "mosd" / "learn")
    sets = [("mOSD learn, default", "segment", [learn], []),
            ("mOSD learn, paper preset", "segment", [learn], ["--preset", "paper"])]
    if generated:
        sets.append(("generated (clutter, piles, occlusion)", "segment", [str(generated)], []))
    for scene in ("frames", "video0001"):
        sets.append((f"YCB-Video {scene}/ (21 models)", "recognize",
                     [str(Path(data) / "ycbv" / scene)], []))
    return sets


def make_database(cli, data, out, env):
    if (out / "done").exists():
        return
    models = sorted((Path(data) / "ycbv" / "models").iterdir())
    for model in models:
        run([cli, "db", "add", str(out / "db"), "-q", "--name", model.name, "--xyz",
             str(model / "points.xyz")], env)
    (out / "done").write_text("")


def run_set(cli, kind, sources, extra, out, db, env):
    if (out / "summary.json").exists():
        return
    cmd = [cli, kind, "--batch", *sources, "-o", str(out), "--outputs", "pcd,json", "-q", *extra]
    if kind == "recognize":
        cmd += ["--db", str(db)]
    run(cmd, env)


def reports(out):
    return {p.stem: json.loads(p.read_text()) for p in sorted(out.glob("*.json"))
            if p.name not in ("summary.json",) and not p.name.startswith("summary.")}


def fields(proxseg, pcd, names):
    return {n: np.asarray(proxseg.read_point_cloud(str(pcd), label_field=n).label).ravel()
            for n in names}


def equal_share(a, b):
    labelled = (a != 0) | (b != 0)
    n = int(labelled.sum())
    return n, int((a[labelled] == b[labelled]).sum())


def pose_difference(p, q):
    p, q = np.asarray(p), np.asarray(q)
    dt = float(np.linalg.norm(p[:3, 3] - q[:3, 3]))
    r = p[:3, :3].T @ q[:3, :3]
    angle = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2))))
    return dt, angle


def compare(proxseg, kind, ref_out, out):
    """Per-set figures of one build against the reference."""
    ref, got = reports(ref_out), reports(out)
    row = {"frames": len(ref), "same_candidates": 0, "same_names": 0, "points": 0, "equal": 0,
           "inst_points": 0, "inst_equal": 0, "pose_m": 0.0, "pose_deg": 0.0, "missing": 0}
    label_fields = ["label", "instance"] if kind == "segment" else ["object"]
    for frame, r in ref.items():
        g = got.get(frame)
        if g is None:
            row["missing"] += 1
            continue
        a = fields(proxseg, ref_out / f"{frame}.pcd", label_fields)
        b = fields(proxseg, out / f"{frame}.pcd", label_fields)
        n, e = equal_share(a[label_fields[0]], b[label_fields[0]])
        row["points"] += n
        row["equal"] += e
        inst = label_fields[-1]
        n_i, e_i = equal_share(a[inst], b[inst])
        row["inst_points"] += n_i
        row["inst_equal"] += e_i
        rc, gc = r.get("candidates", []), g.get("candidates", [])
        same = len(rc) == len(gc) and [c.get("points") for c in rc] == [c.get("points") for c in gc]
        row["same_candidates"] += same
        row["same_names"] += [c.get("name") for c in rc] == [c.get("name") for c in gc]
        if kind == "recognize" and len(rc) == len(gc):
            for c, d in zip(rc, gc):
                if c.get("name") == d.get("name") and c.get("name") != "unknown" and "pose" in c:
                    dt, da = pose_difference(c["pose"], d["pose"])
                    row["pose_m"] = max(row["pose_m"], dt)
                    row["pose_deg"] = max(row["pose_deg"], da)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True)
    ap.add_argument("--generated", default="")
    ap.add_argument("--work", required=True)
    ap.add_argument("--env", action="append", default=[], metavar="NAME=VAR=VALUE")
    ap.add_argument("builds", nargs="+", metavar="NAME=BUILD_DIR")
    args = ap.parse_args()
    builds = [b.split("=", 1) for b in args.builds]
    envs = {name: dict(os.environ) for name, _ in builds}
    for e in args.env:
        name, var, value = e.split("=", 2)
        envs[name][var] = value
    sys.path.insert(0, str(Path(builds[0][1]) / "python"))
    import proxseg  # the reference build's module reads every build's PCDs

    work = Path(args.work)
    sets = frame_sets(args.data, args.generated)
    for name, build in builds:
        cli = str(Path(build) / "proxseg")
        base = work / name
        base.mkdir(parents=True, exist_ok=True)
        make_database(cli, args.data, base, envs[name])
        for s, (title, kind, sources, extra) in enumerate(sets):
            print(f"compare-builds: {name}: {title}", file=sys.stderr)
            run_set(cli, kind, sources, extra, base / f"set{s}", base / "db", envs[name])

    ok = True
    print("| set | build | frames | same candidates | same names | labels equal | "
          "instances / objects equal | largest pose difference |")
    print("|---|---|---|---|---|---|---|---|")
    ref_name = builds[0][0]
    for s, (title, kind, _, _) in enumerate(sets):
        for name, _ in builds[1:]:
            row = compare(proxseg, kind, work / ref_name / f"set{s}", work / name / f"set{s}")
            share = row["equal"] / max(row["points"], 1)
            inst = row["inst_equal"] / max(row["inst_points"], 1)
            pose = (f"{1000 * row['pose_m']:.2f} mm, {row['pose_deg']:.3f} deg"
                    if kind == "recognize" else "-")
            print(f"| {title} | {name} | {row['frames']} | {row['same_candidates']}/{row['frames']} | "
                  f"{row['same_names']}/{row['frames']} | {100 * share:.3f} % | "
                  f"{100 * inst:.3f} % | {pose} |")
            ok &= (row["missing"] == 0 and row["same_candidates"] == row["frames"]
                   and row["same_names"] == row["frames"] and share >= LABEL_SHARE)
    print(f"compare-builds: {'every build answers as ' + ref_name if ok else 'builds differ'}",
          file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
