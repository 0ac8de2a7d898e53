#!/usr/bin/env python3
"""Segment every point cloud of a folder in one process, with a progress bar.

    python3 examples/python/segment_folder.py FOLDER -o OUT [--threads N]

Writes OUT/<scene>.npz (labels, instances) per scene and OUT/summary.json (per scene its
candidates, k and time, or the error that stopped it). A scene that cannot be read is reported and
skipped. With tqdm installed (python3-tqdm) the bar is tqdm's.
"""

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

import proxseg

try:
    from tqdm import tqdm
except ImportError:  # a plain bar on stderr
    def tqdm(items, **_):
        items = list(items)
        for i, item in enumerate(items, 1):
            yield item
            print(f"\r{i}/{len(items)}", end="" if i < len(items) else "\n", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--preset", default="default", choices=["default", "paper"])
    ap.add_argument("--threads", type=int, default=0, help="per scene (0 = all cores)")
    args = ap.parse_args()

    scenes = sorted(p for p in Path(args.folder).iterdir() if p.suffix.lower() in (".pcd", ".ply"))
    if not scenes:
        sys.exit(f"segment_folder: {args.folder}: no .pcd or .ply files")
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    params = proxseg.SegmentParams(preset=args.preset, threads=args.threads)
    rows = []
    start = time.perf_counter()
    for scene in tqdm(scenes, desc="segment", unit="scene"):
        try:
            result = proxseg.segment(proxseg.read_point_cloud(scene), params)
        except (OSError, ValueError) as e:
            rows.append({"scene": scene.name, "error": str(e)})
            continue
        np.savez_compressed(out / f"{scene.stem}.npz", labels=result.labels,
                            instances=result.instances)
        rows.append({"scene": scene.name, "k": result.k, "candidates": len(result.candidates),
                     "ms": result.times_ms["total"]})
    summary = {"folder": os.fspath(args.folder), "scenes": rows,
               "seconds": time.perf_counter() - start, "proxseg": proxseg.build_info(),
               "parameters": params.to_dict()}
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    failed = [r for r in rows if "error" in r]
    print(f"{out / 'summary.json'}: {len(rows) - len(failed)} of {len(rows)} scenes segmented")
    for r in failed:
        print(f"segment_folder: {r['error']}", file=sys.stderr)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
