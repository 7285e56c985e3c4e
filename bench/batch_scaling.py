"""Scaling of `lidarshop batch`: scans per minute for 1 and 2 local Dask workers (and --serial), and the
scheduler's overhead per task.

    PYTHONPATH=build/release/python python3 bench/batch_scaling.py [--scans 20] [--work DIR]

The scans are the built-in mailbox scene at half resolution (400 x 250) with different noise seeds; the
pipeline has two steps: fill the mailbox's cells (default gradient method), then convert to PLY.
Each mode starts from an empty output folder; its time includes starting the local cluster.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import lidarshop


def noop(x):
    return x


def scheduler_overhead(tasks=400):
    """Seconds per task of a no-op task on a local cluster of one worker process (submit to result)."""
    from distributed import Client, LocalCluster, wait

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            wait(client.map(noop, range(20), pure=False))  # warm up
            start = time.monotonic()
            wait(client.map(noop, range(tasks), pure=False))
            batched = (time.monotonic() - start) / tasks
            start = time.monotonic()
            for i in range(50):
                client.submit(noop, i, pure=False).result()
            one_by_one = (time.monotonic() - start) / 50
    return batched, one_by_one


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scans", type=int, default=20)
    parser.add_argument("--work", default=None)
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="lidarshop_batch_bench_")
    scans_dir = os.path.join(work, "scans")
    os.makedirs(scans_dir, exist_ok=True)
    paths = []
    for index in range(args.scans):
        scene = lidarshop.builtin_scene("mailbox")
        scene["scanner"].update(columns=400, rows=250, seed=index + 1)
        scan = lidarshop.scan_scene(scene)
        name = f"mailbox{index:02d}"
        lidarshop.write_scan(scan, os.path.join(scans_dir, name + ".e57"))
        lidarshop.write_image(os.path.join(scans_dir, name + "_mask.png"),
                              lidarshop.grow_hole((scan.label == 2).astype("uint8"), 2))
        paths.append(os.path.join(scans_dir, name + ".e57"))
    pipeline = os.path.join(work, "pipeline.json")
    with open(pipeline, "w") as stream:
        json.dump({"steps": [{"command": "fill", "mask": "{name}_mask.png", "output": "{name}_filled.e57"},
                             {"command": "convert", "output": "{name}.ply"}]}, stream)
    rows = []
    for mode in (["--serial"], ["--workers", "1"], ["--workers", "2"]):
        out = os.path.join(work, "out_" + "_".join(m.strip("-") for m in mode))
        shutil.rmtree(out, ignore_errors=True)
        subprocess.run([sys.executable, "-m", "lidarshop_batch", "--quiet", pipeline] + paths + ["--out", out] + mode,
                       check=True)
        with open(os.path.join(out, "summary.json")) as stream:
            summary = json.load(stream)
        rows.append((" ".join(mode), summary["seconds"], summary["scans_per_minute"], summary["done"]))
    batched, one_by_one = scheduler_overhead()
    print(f"| mode | seconds | scans per minute | done |\n|---|---|---|---|")
    for mode, seconds, per_minute, done in rows:
        print(f"| `{mode}` | {seconds:.1f} | {per_minute:.0f} | {done} |")
    print(f"\nscheduler overhead per no-op task (1 worker process): {batched * 1000:.2f} ms mapped, "
          f"{one_by_one * 1000:.2f} ms submitted one at a time")
    if not args.work:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
