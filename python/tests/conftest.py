"""Fixtures of the Python tests: the real data (../shared/data), the CLI built beside the
module, a temporary directory. ctest sets PROXSEG_DATA_DIR, PROXSEG_CLI and PYTHONPATH
(tests/CMakeLists.txt); the data must be there (the tests fail, not skip, without it)."""

import os
import subprocess
from pathlib import Path

import pytest

DATA = Path(os.environ.get("PROXSEG_DATA_DIR", Path(__file__).resolve().parents[2].parent /
                           "shared" / "data"))
CLI = os.environ.get("PROXSEG_CLI", "proxseg")
YCB_OBJECTS = ("009_gelatin_box", "025_mug", "061_foam_brick")


def data(relative: str) -> Path:
    path = DATA / relative
    assert path.exists(), f"{path}: missing (the tests read ../shared/data)"
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess:
    """Runs the proxseg CLI; fails the test with its stderr unless it exits 0."""
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"proxseg {' '.join(map(str, args))}: exit {r.returncode}\n{r.stderr}"
    return r


def mosd_learn() -> list:
    scenes = sorted(data("mosd/learn").glob("*.pcd"), key=lambda p: int(p.stem[5:]))
    assert len(scenes) == 45, f"{DATA}/mosd/learn: {len(scenes)} scenes (expected 45)"
    return scenes


def scene_folder(folder: Path, learn: tuple) -> Path:
    """A folder of the given mOSD learn scenes (links) and one broken PCD, as a batch reads it."""
    folder.mkdir()
    for k in learn:
        (folder / f"learn{k}.pcd").symlink_to(data(f"mosd/learn/learn{k}.pcd"))
    (folder / "broken.pcd").write_text("not a pcd\n")
    return folder


def ycb_frame(k: int) -> dict:
    base = data("ycbv/frames") / f"{k:06d}"
    return {"color": f"{base}-color.png", "depth": f"{base}-depth.png", "meta": f"{base}-meta.json"}


@pytest.fixture(scope="session")
def ycb_db(tmp_path_factory) -> Path:
    """The database of the YCB-Video frames' three models (a full model each, from points.xyz),
    built by the CLI as tests/cli/test_recognize_outputs.cpp builds it."""
    db = tmp_path_factory.mktemp("ycb") / "db"
    for name in YCB_OBJECTS:
        run_cli("db", "add", db, "--name", name, "--xyz", data(f"ycbv/models/{name}/points.xyz"))
    return db
