#!/usr/bin/env python3
"""Recognise the objects of an RGB-D scene against a model database.

    python3 examples/python/recognize_scene.py --db DB SCENE.pcd
    python3 examples/python/recognize_scene.py --db DB --colour C.png --depth D.png --meta M.json
    python3 examples/python/recognize_scene.py --db DB --models a.xyz b.xyz ... SCENE

With --models, the database DB is first made from full models (plain "x y z" files, metres; the
object is named after the file's folder, as YCB-Video lays them out) when it does not exist.
Prints each object's name, score and pose, and writes the per-point object ids as a .npy file.
"""

import argparse
import os
import sys

import numpy as np

import proxseg


def make_database(path, models):
    db = proxseg.Database(path, create=True)
    if len(db) == 0:
        for model in models:
            name = os.path.basename(os.path.dirname(os.path.abspath(model)))
            db.add_view(name, np.loadtxt(model, dtype=np.float32), viewpoint=None, source=model)
    return db


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", help="point cloud (.pcd or .ply); or --colour/--depth")
    ap.add_argument("--db", required=True, help="model database directory")
    ap.add_argument("--models", nargs="*", default=[], help="full models to build the database")
    ap.add_argument("--colour", "--color", dest="color", metavar="COLOUR",
                    help="colour image of an RGB-D pair")
    ap.add_argument("--depth")
    ap.add_argument("--meta", help="YCB-Video meta JSON of the RGB-D pair")
    ap.add_argument("-o", "--output", default="object_ids.npy", help="per-point object ids (.npy)")
    args = ap.parse_args()

    try:
        db = make_database(args.db, args.models) if args.models else proxseg.Database(args.db)
        if args.scene:
            frame = proxseg.read_point_cloud(args.scene)
        else:
            frame = proxseg.read_rgbd(args.color, args.depth, meta=args.meta)
        result = proxseg.recognize(frame, db)
    except (OSError, ValueError) as e:
        sys.exit(f"recognize_scene: {e}")
    print(f"{db}: {len(result.objects)} objects "
          f"(segment {result.times_ms['segment']:.0f} ms, recognise "
          f"{result.times_ms['recognize']:.0f} ms)")
    np.set_printoptions(precision=3, suppress=True)
    for o in result.objects:
        print(f"{o.id:3d} {o.name:20s} score {o.score:.3f} ({len(o.points)} points)")
        if o.known:
            print("    pose (camera <- model):\n    " + str(o.pose).replace("\n", "\n    "))
    np.save(args.output, result.object_ids)
    print(f"object ids: {args.output}")


if __name__ == "__main__":
    main()
