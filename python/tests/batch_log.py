"""A generated batch log (summary.jsonl) of many frames, for the batch page's tests and
benchmark (bench/view_bench.py): frame k takes 50 + k % 97 ms, finds k % 9 candidates, and every
50th frame (k % 50 == 7) failed."""

import json
from pathlib import Path


def ms_of(k: int) -> int:
    return 50 + k % 97


def failed(k: int) -> bool:
    return k % 50 == 7


def write_batch_log(folder: Path, frames: int) -> Path:
    """Writes folder/summary.jsonl for `frames` frames named scene0, scene1, ...; returns folder."""
    folder.mkdir(parents=True, exist_ok=True)
    header = {"header": {"command": "segment", "frames": frames, "frames_all": frames,
                         "outputs": "json", "parameters": {}, "proxseg": {}, "sources": ["x"],
                         "shard": None}}
    lines = [json.dumps(header)]
    for k in range(frames):
        row = {"frame": f"scene{k}", "inputs": [f"x/scene{k}.pcd"], "ms": ms_of(k)}
        if failed(k):
            row["error"] = f"x/scene{k}.pcd: damaged"
        else:
            row.update(candidates=k % 9, outputs={f"scene{k}.json": 1000})
        lines.append(json.dumps(row))
    lines.append(json.dumps({"end": {"interrupted": False}}))
    (folder / "summary.jsonl").write_text("\n".join(lines) + "\n")
    return folder
