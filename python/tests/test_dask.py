"""proxseg.dask: a batch on a Dask LocalCluster (2 workers, loopback) writes what the CLI's
single-process batch writes, and loses no frame when a worker dies mid-run."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from conftest import CLI, data, run_cli

from distributed import Client, LocalCluster

from proxseg import dask as pdask

MOSD = 6
YCB = 2


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    """Real frames in nested folders: mOSD clouds and YCB-Video RGB-D pairs."""
    root = tmp_path_factory.mktemp("data")
    for i in range(MOSD):
        target = root / ("tabletop/odd" if i % 2 else "tabletop") / f"learn{i}.pcd"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.symlink_to(data(f"mosd/learn/learn{i}.pcd"))
    (root / "ycb").mkdir()
    for k in range(1, YCB + 1):
        for part in ("-color.png", "-depth.png", "-meta.json"):
            (root / "ycb" / f"{k:06d}{part}").symlink_to(data(f"ycbv/frames/{k:06d}{part}"))
    return root


@pytest.fixture(scope="module")
def cli_batch(dataset, tmp_path_factory) -> Path:
    """The single-process batch: `proxseg segment --batch` (one thread per frame, as the
    workers run)."""
    out = tmp_path_factory.mktemp("cli")
    run_cli("segment", "--batch", dataset, "-o", out, "--threads", "1", "--outputs", "all")
    return out


@pytest.fixture(scope="module")
def cluster():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0") as c:
        yield c


def outputs(folder: Path) -> dict:
    """Every output file under folder but the summaries: relative path -> bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and not p.name.startswith("summary")}


def timeless(report: dict) -> dict:
    """A report without what varies from run to run: the times."""
    report = dict(report)
    report.pop("times_ms", None)
    report.pop("concurrent_times_ms", None)
    report.pop("step_times_ms", None)
    if isinstance(report.get("candidates"), list):
        report["candidates"] = [{k: v for k, v in c.items() if k != "times_ms"}
                                for c in report["candidates"]]
    return report


def assert_same_outputs(a: Path, b: Path) -> None:
    fa, fb = outputs(a), outputs(b)
    assert sorted(fa) == sorted(fb)
    for name, content in fa.items():
        if name.endswith(".json"):
            assert timeless(json.loads(content)) == timeless(json.loads(fb[name])), name
        else:
            assert content == fb[name], name


def assert_same_summary(dask_summary: dict, dask_out: Path, cli_out: Path) -> None:
    """The Dask run's summary and rows against the CLI batch's."""
    cli_summary = json.loads((cli_out / "summary.json").read_text())
    assert dask_summary["frames_done"] == cli_summary["frames_done"] == MOSD + YCB
    assert dask_summary["frames_failed"] == 0 and dask_summary["frames_missing"] == 0
    assert dask_summary["failed"] == [] and "frames" not in dask_summary
    assert dask_summary["parameters"] == cli_summary["parameters"]
    assert dask_summary["outputs"] == cli_summary["outputs"]
    dask_rows, cli_rows = pdask.frame_rows(dask_out), pdask.frame_rows(cli_out)
    assert len(dask_rows) == MOSD + YCB
    keep = ("frame", "inputs", "k", "candidates")
    assert [{k: r[k] for k in keep} for r in dask_rows] == [{k: r[k] for k in keep}
                                                            for r in cli_rows]
    for d, c in zip(dask_rows, cli_rows):  # reports' sizes vary
        assert {n: (None if n.endswith(".json") else b) for n, b in d["outputs"].items()} == \
            {n: (None if n.endswith(".json") else b) for n, b in c["outputs"].items()}


def test_a_local_cluster_writes_what_the_cli_batch_writes(dataset, cli_batch, cluster, tmp_path):
    with Client(cluster) as client:
        summary = pdask.run_batch("segment", [dataset], tmp_path / "out", client=client,
                                  outputs="all", overrides={"threads": 1}, progress=False)
    assert summary == json.loads((tmp_path / "out" / "summary.json").read_text())
    assert_same_summary(summary, tmp_path / "out", cli_batch)
    assert_same_outputs(cli_batch, tmp_path / "out")
    # The workers did the work: two processes, each with the library in it.
    header = json.loads((tmp_path / "out" / "summary.jsonl").read_text().splitlines()[0])
    assert header["header"]["runner"] == "dask"


def test_a_worker_killed_mid_run_loses_no_frame(dataset, cli_batch, cluster, tmp_path):
    out = tmp_path / "out"
    result = {}
    with Client(cluster) as client:
        pids = client.run(os.getpid)
        assert len(pids) == 2

        def run():
            # 3 frames in flight: the rest are submitted as frames finish, the kill among them.
            result["summary"] = pdask.run_batch("segment", [dataset], out, client=client,
                                                outputs="all", overrides={"threads": 1},
                                                max_in_flight=3, progress=False)

        worker = threading.Thread(target=run)
        worker.start()
        log = out / "summary.jsonl"
        deadline = time.time() + 300
        logged = 0
        while time.time() < deadline:  # kill one worker once the first frame is logged
            if log.exists():
                logged = sum('"frame"' in line for line in log.read_text().splitlines())
            if logged:
                break
            time.sleep(0.005)
        victim = sorted(pids.values())[0]
        os.kill(victim, signal.SIGKILL)
        assert 0 < logged < MOSD + YCB and worker.is_alive(), "the kill came after the run"
        worker.join(timeout=600)
        assert not worker.is_alive()
        rows = [json.loads(line) for line in log.read_text().splitlines()]
        done = [r["frame"] for r in rows if "frame" in r]
        # Every frame logged once: none lost, none doubled.
        assert sorted(done) == sorted(set(done)) and len(done) == MOSD + YCB
        # The nanny restarted the worker; the cluster has two again.
        client.wait_for_workers(2, timeout=120)
        assert victim not in client.run(os.getpid).values()
    assert_same_summary(result["summary"], out, cli_batch)
    assert_same_outputs(cli_batch, out)


def test_recognize_on_the_cluster_equals_the_cli(ycb_db, dataset, cluster, tmp_path):
    ycb = dataset / "ycb"
    run_cli("recognize", "--batch", ycb, "--db", ycb_db, "-o", tmp_path / "cli", "--threads", "1")
    with Client(cluster) as client:
        summary = pdask.run_batch("recognize", [ycb], tmp_path / "dask", db=ycb_db,
                                  client=client,
                                  overrides={"segmentation": {"threads": 1},
                                             "recognition": {"threads": 1}},
                                  progress=False)
    cli_summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert summary["parameters"] == cli_summary["parameters"]
    assert [r["objects"] for r in pdask.frame_rows(tmp_path / "dask")] == \
        [r["objects"] for r in pdask.frame_rows(tmp_path / "cli")]
    assert_same_outputs(tmp_path / "cli", tmp_path / "dask")


def test_the_command_line_entry_point(dataset, cli_batch, tmp_path):
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "--batch",
                        str(dataset / "ycb"), "-o", str(tmp_path / "out"), "--workers", "2",
                        "--threads", "1", "--outputs", "all", "--json"],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["frames_done"] == YCB
    assert "frames/s, ETA" in r.stderr
    for row in pdask.frame_rows(tmp_path / "out"):  # ids relative to the ycb folder here
        for name in row["outputs"]:
            if not name.endswith(".json"):
                assert (tmp_path / "out" / name).read_bytes() == \
                    (cli_batch / "ycb" / name).read_bytes(), name
    # --resume: nothing left to do; the summary still counts every frame.
    r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "--batch",
                        str(dataset / "ycb"), "-o", str(tmp_path / "out"), "--workers", "1",
                        "--threads", "1", "--outputs", "all", "--resume", "--json"],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["frames_done"] == YCB
    assert "2 done before" in r.stderr
    # A damaged line in the log: a warning with its file and line; the line is skipped.
    log = tmp_path / "out" / "summary.jsonl"
    lines = log.read_text().splitlines(keepends=True)
    log.write_text(lines[0] + "garbage\n" + "".join(lines[1:]))
    r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "--batch",
                        str(dataset / "ycb"), "-o", str(tmp_path / "out"), "--workers", "1",
                        "--threads", "1", "--outputs", "all", "--resume", "--json"],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "summary.jsonl:2: damaged line (not JSON); skipped" in r.stderr, r.stderr
    assert json.loads(r.stdout)["frames_done"] == YCB
    # Usage errors exit 2, bad input 1 with the file named.
    r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "-o", "x"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 2
    r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "--batch",
                        str(tmp_path / "none"), "-o", str(tmp_path / "o2")],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 1 and "none: no such file or folder" in r.stderr
    # Settings other than the earlier run's may not resume into its folder.
    r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "--batch",
                        str(dataset / "ycb"), "-o", str(tmp_path / "out"), "--resume",
                        "--set", "voxel_size=0.03", "--threads", "1", "--outputs", "all"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 1 and "voxel_size" in r.stderr, r.stderr


def test_the_several_machine_steps_on_one_machine(dataset, cli_batch, tmp_path):
    """docs/batch.md's steps with every process on this machine: dask-scheduler, dask-worker
    processes (one thread each), and the driver given the scheduler's address."""
    import shutil
    import socket
    scheduler_cmd, worker_cmd = shutil.which("dask-scheduler"), shutil.which("dask-worker")
    assert scheduler_cmd and worker_cmd, "dask-scheduler / dask-worker missing (python3-distributed)"
    with socket.socket() as s:  # a free port on the loopback interface
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ)
    procs = [subprocess.Popen([scheduler_cmd, "--host", "127.0.0.1", "--port", str(port),
                               "--dashboard-address", "127.0.0.1:0"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)]
    try:
        procs.append(subprocess.Popen([worker_cmd, address, "--nworkers", "2", "--nthreads", "1",
                                       "--host", "127.0.0.1", "--dashboard-address",
                                       "127.0.0.1:0"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      env=env))
        with Client(address, timeout=120) as client:
            client.wait_for_workers(2, timeout=120)
        r = subprocess.run([sys.executable, "-m", "proxseg.dask", "segment", "--batch",
                            str(dataset), "-o", str(tmp_path / "out"), "--scheduler", address,
                            "--threads", "1", "--outputs", "all", "--json"],
                           capture_output=True, text=True, env=env, timeout=600)
        assert r.returncode == 0, r.stderr
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            p.wait(timeout=60)
    assert_same_summary(json.loads(r.stdout), tmp_path / "out", cli_batch)
    assert_same_outputs(cli_batch, tmp_path / "out")


def test_the_progress_line_reads_as_the_clis(capsys):
    """Times as the CLI prints them; a failed frame tells no rate (it is often quick)."""
    assert [pdask._human_time(s) for s in (0.0516183, 1.234, 125, 3720)] == \
        ["51.6 ms", "1.23 s", "2 min 05 s", "1 h 02 min"]
    bar = pdask._Progress(3, quiet=False)
    bar.step("broken", failed=True)
    first = capsys.readouterr().err
    assert first.startswith("[1/3] broken (failed)") and "frames/s" not in first
    bar.step("learn0")
    second = capsys.readouterr().err
    assert "[2/3] learn0  " in second and "frames/s, ETA " in second and ":" not in second
