#!/usr/bin/env python3
"""Compares what builds of proxseg answer on the same frames (`make test-numerics`, issue 50).

Each build's CLI segments mOSD learn (default and paper presets) and the generated sets, builds a
database of the 21 YCB-Video models and recognises both YCB-Video scenes against it. Against the
first build (the reference), each other build must give, frame by frame, the same candidates (as
many, each matched one to one with IoU >= 0.95 of its points), the same names, and the same
labels on at least 99.9 % of the labelled points (points labelled by either build). Labels and
candidate ids are numbers given in scan order, so one surface more shifts every later id: they
are compared as partitions (each id of the reference matched one to one to the id it overlaps
most). Poses are compared within a tolerance (the largest translation and rotation difference is
printed). The table also counts the frames whose outputs are identical.

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
CANDIDATE_IOU = 0.95


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
    models = sorted((Path(data) / "ycbv" / "models").iterdir())
    for model in models:
        run([cli, "db", "add", str(out / "db"), "-q", "--name", model.name, "--xyz",
             str(model / "points.xyz")], env)


def run_set(cli, kind, sources, extra, out, db, env):
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


def matched_overlaps(a, b):
    """One-to-one matching of the ids of a to those of b, largest overlaps first (0, unlabelled,
    only with 0): (labelled points, {(id_a, id_b): points in both})."""
    labelled = (a != 0) | (b != 0)
    pairs, counts = np.unique(np.stack([a[labelled], b[labelled]]), axis=1, return_counts=True)
    used_a, used_b, matched = set(), set(), {}
    for i in np.argsort(-counts, kind="stable"):
        x, y = int(pairs[0, i]), int(pairs[1, i])
        if x in used_a or y in used_b or (x == 0) != (y == 0):
            continue
        used_a.add(x)
        used_b.add(y)
        matched[(x, y)] = int(counts[i])
    return int(labelled.sum()), matched


def equal_share(a, b):
    """(labelled points, points whose labels agree as partitions)."""
    n, matched = matched_overlaps(a, b)
    return n, sum(matched.values())


def candidate_ious(a, b):
    """IoU of each candidate (nonzero id) of a with its match in b; None when the counts differ."""
    ids_a, sizes_a = np.unique(a[a != 0], return_counts=True)
    ids_b, sizes_b = np.unique(b[b != 0], return_counts=True)
    if len(ids_a) != len(ids_b):
        return None
    size_a, size_b = dict(zip(ids_a.tolist(), sizes_a)), dict(zip(ids_b.tolist(), sizes_b))
    _, matched = matched_overlaps(a, b)
    ious = [n / (size_a[x] + size_b[y] - n) for (x, y), n in matched.items() if x != 0]
    return ious + [0.0] * (len(ids_a) - len(ious))


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
           "inst_points": 0, "inst_equal": 0, "pose_m": 0.0, "pose_deg": 0.0, "missing": 0,
           "identical": 0, "lowest_iou": 1.0}
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
        row["identical"] += (all(np.array_equal(a[f], b[f]) for f in label_fields)
                             and [c.get("points") for c in rc] == [c.get("points") for c in gc])
        ious = candidate_ious(a[inst], b[inst])
        lowest = min(ious, default=1.0) if ious is not None else 0.0
        row["lowest_iou"] = min(row["lowest_iou"], lowest)
        row["same_candidates"] += len(rc) == len(gc) and lowest >= CANDIDATE_IOU
        row["same_names"] += sorted(c.get("name", "") for c in rc) == sorted(
            c.get("name", "") for c in gc)
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
    if work.exists() and any(work.iterdir()):
        sys.exit(f"compare-builds: {work} is not empty (its outputs would be mixed with new ones)")
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
    print("| set | build | frames | identical | same candidates (lowest IoU) | same names | "
          "labels equal | instances / objects equal | largest pose difference |")
    print("|---|---|---|---|---|---|---|---|---|")
    ref_name = builds[0][0]
    for s, (title, kind, _, _) in enumerate(sets):
        for name, _ in builds[1:]:
            row = compare(proxseg, kind, work / ref_name / f"set{s}", work / name / f"set{s}")
            share = row["equal"] / max(row["points"], 1)
            inst = row["inst_equal"] / max(row["inst_points"], 1)
            pose = (f"{1000 * row['pose_m']:.2f} mm, {row['pose_deg']:.3f} deg"
                    if kind == "recognize" else "-")
            print(f"| {title} | {name} | {row['frames']} | {row['identical']}/{row['frames']} | "
                  f"{row['same_candidates']}/{row['frames']} ({row['lowest_iou']:.3f}) | "
                  f"{row['same_names']}/{row['frames']} | {100 * share:.4f} % | "
                  f"{100 * inst:.4f} % | {pose} |")
            ok &= (row["missing"] == 0 and row["same_candidates"] == row["frames"]
                   and row["same_names"] == row["frames"] and share >= LABEL_SHARE)
    print(f"compare-builds: {'every build answers as ' + ref_name if ok else 'builds differ'}",
          file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
