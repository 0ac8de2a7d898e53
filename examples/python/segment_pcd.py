#!/usr/bin/env python3
"""Segment one point cloud and show its candidate objects.

    python3 examples/python/segment_pcd.py SCENE.pcd [-o candidates.png] [--show]

Writes a picture of the scene with every candidate object outlined in its colour and numbered
(matplotlib), prints one line per candidate, and with --show opens the labelled cloud in
Open3D's viewer.
"""

import argparse
import sys

import numpy as np

import proxseg


def picture(frame, result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = proxseg.label_colours(result.instances)
    if frame.organized:  # the colour image with the candidates over it
        image = frame.rgb / 255.0 if frame.coloured else np.full(colours.shape, 0.5)
        shown = np.where((result.instances > 0)[..., None], 0.4 * image + 0.6 * colours, image)
        fig, ax = plt.subplots(figsize=(frame.width / 100, frame.height / 100), dpi=100)
        ax.imshow(shown)
        for c in result.candidates:
            v, u = np.divmod(c.points, frame.width)
            ax.text(u.mean(), v.mean(), str(c.id), color="white", ha="center", va="center",
                    fontsize=12, bbox=dict(facecolor="black", alpha=0.6, pad=1))
    else:  # the points seen from above the sensor's axis
        xyz = frame.xyz
        fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=100)
        ax.scatter(xyz[:, 0], -xyz[:, 1], s=0.2, c=colours.reshape(-1, 3))
        for c in result.candidates:
            ax.text(c.centroid[0], -c.centroid[1], str(c.id), color="black")
        ax.set_aspect("equal")
    ax.set_axis_off()
    fig.savefig(path, bbox_inches="tight", pad_inches=0)
    plt.close(fig)


def show(result):
    import open3d as o3d

    cloud = result.to_open3d(by="instances")  # the valid points, coloured by candidate
    boxes = [c.box.to_open3d() for c in result.candidates]  # OrientedBoundingBox each
    for box in boxes:
        box.color = (0.0, 0.0, 0.0)
    o3d.visualization.draw_geometries([cloud, *boxes], window_name="proxseg candidates")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help="point cloud (.pcd or .ply)")
    ap.add_argument("-o", "--output", default="candidates.png", help="picture to write (PNG)")
    ap.add_argument("--preset", default="default", choices=["default", "paper"])
    ap.add_argument("--show", action="store_true", help="open the labelled cloud in Open3D")
    args = ap.parse_args()

    try:
        frame = proxseg.read_point_cloud(args.scene)
        result = proxseg.segment(frame, preset=args.preset)
    except (OSError, ValueError) as e:
        sys.exit(f"segment_pcd: {e}")
    print(f"{args.scene}: k = {result.k}, {len(result.candidates)} candidates, "
          f"{result.times_ms['total']:.0f} ms")
    for c in result.candidates:
        print(f"  {c.id:3d}: {len(c.points):6d} points at "
              f"({c.centroid[0]:+.3f}, {c.centroid[1]:+.3f}, {c.centroid[2]:+.3f}) m, "
              f"box {c.box.extent[0]:.3f} x {c.box.extent[1]:.3f} x {c.box.extent[2]:.3f} m")
    picture(frame, result, args.output)
    print(f"picture: {args.output}")
    if args.show:
        show(result)


if __name__ == "__main__":
    main()
