"""lidarshop batch: pipelines over many scans, on a local Dask cluster, resumable, sharded."""
import glob
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import lidarshop
from conftest import small_scene

CLI = os.environ.get("LIDARSHOP_CLI")
DRIVER = [sys.executable, "-m", "lidarshop_batch"]
PIPELINE = {"steps": [
    {"command": "fill", "options": {"method": "laplace", "poisson": {"solver": "direct"}},
     "mask": "{name}_mask.png", "output": "{name}_filled.e57"},
    {"command": "convert", "output": "{name}.ply"},
]}

pytestmark = pytest.mark.skipif(not CLI, reason="LIDARSHOP_CLI (set by ctest) names the lidarshop executable")


@pytest.fixture(scope="module")
def scans(tmp_path_factory):
    """20 small synthetic scans (different noise seeds) with a hole mask each: the box's cells."""
    folder = tmp_path_factory.mktemp("scans")
    paths = []
    for index in range(20):
        scene = small_scene(columns=48, rows=32)
        scene["scanner"]["seed"] = index + 1
        scan = lidarshop.scan_scene(scene)
        name = f"scan{index:02d}"
        lidarshop.write_scan(scan, str(folder / f"{name}.ptx"))
        lidarshop.write_image(str(folder / f"{name}_mask.png"), scan.label == 2)
        paths.append(str(folder / f"{name}.ptx"))
    return paths


def write_pipeline(folder, pipeline=PIPELINE):
    path = os.path.join(folder, "pipeline.json")
    with open(path, "w") as stream:
        json.dump(pipeline, stream)
    return path


def run(args, **kwargs):
    return subprocess.run(DRIVER + ["--lidarshop", CLI, "--quiet"] + args, capture_output=True, text=True,
                          timeout=600, **kwargs)


def summary(out, name="summary.json"):
    with open(os.path.join(out, name)) as stream:
        return json.load(stream)


def records(out):
    result = {}
    for path in glob.glob(os.path.join(out, "records", "*.json")):
        with open(path) as stream:
            result[os.path.basename(path)[:-5]] = json.load(stream)
    return result


def check_complete(out, names):
    found = records(out)
    assert sorted(found) == sorted(names)
    assert all(record["status"] == "ok" for record in found.values())
    for name in names:
        filled = lidarshop.read_scan(os.path.join(out, f"{name}_filled.e57"))
        assert filled.synthesized is not None and (filled.synthesized > 0).sum() > 0
        assert os.path.getsize(os.path.join(out, f"{name}.ply")) > 0
    # Nothing half-written: no temporary file of an atomic write is left.
    leftovers = [p for p in glob.glob(os.path.join(out, "**", "*"), recursive=True) if ".tmp" in os.path.basename(p)]
    assert leftovers == []


def names_of(paths):
    return [os.path.splitext(os.path.basename(p))[0] for p in paths]


def test_two_step_pipeline_on_a_local_cluster_with_a_killed_worker(scans, tmp_path):
    import psutil

    out = str(tmp_path / "out")
    driver = subprocess.Popen(DRIVER + ["--lidarshop", CLI, "--quiet", write_pipeline(str(tmp_path))] + scans
                              + ["--out", out, "--workers", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    killed = None
    deadline = time.monotonic() + 300
    while driver.poll() is None and time.monotonic() < deadline:
        done = len(glob.glob(os.path.join(out, "records", "*.json")))
        if killed is None and done >= 3:
            # A worker process in the middle of a scan: a lidarshop step is running under it.
            try:
                busy = [p for p in psutil.Process(driver.pid).children(recursive=True)
                        if "spawn_main" in " ".join(p.cmdline())
                        and any(child.name() == "lidarshop" for child in p.children())]
            except psutil.NoSuchProcess:
                busy = []
            if busy:
                killed = busy[0].pid
                os.kill(killed, signal.SIGKILL)
        time.sleep(0.05)
    stdout, stderr = driver.communicate(timeout=60)
    assert killed is not None, "the run ended before a worker could be killed"
    assert driver.returncode == 0, stderr
    result = summary(out)
    assert (result["scans"], result["done"], result["failed"], result["skipped"]) == (20, 20, 0, 0)
    assert result["mode"] == "local cluster of 2 workers"
    check_complete(out, names_of(scans))


def test_resume_redoes_only_what_is_missing(scans, tmp_path):
    subset = scans[:6]
    out = str(tmp_path / "out")
    pipeline = write_pipeline(str(tmp_path))
    # An interrupted run: the driver and the command it runs killed after two scans, as an interrupt from the
    # terminal kills the process group. (Killing the driver alone once made the third run redo one scan too
    # many in CI; the likeliest cause, not proven, is its CLI child writing an output after the resume.)
    driver = subprocess.Popen(DRIVER + ["--lidarshop", CLI, "--quiet", pipeline] + subset + ["--out", out, "--serial"],
                              start_new_session=True)
    while len(glob.glob(os.path.join(out, "records", "*.json"))) < 2 and driver.poll() is None:
        time.sleep(0.01)
    os.killpg(driver.pid, signal.SIGKILL)
    driver.wait()
    first = records(out)
    assert 2 <= len(first) < 6
    stamps = {name: os.path.getmtime(os.path.join(out, f"{name}.ply")) for name in first}
    again = run([pipeline] + subset + ["--out", out, "--serial"])
    assert again.returncode == 0, again.stderr
    result = summary(out)
    assert result["skipped"] == len(first) and result["done"] == 6 - len(first)
    check_complete(out, names_of(subset))
    for name, stamp in stamps.items():  # the scans done before were not redone
        assert os.path.getmtime(os.path.join(out, f"{name}.ply")) == stamp
    # A missing output makes its scan redone, and only it.
    os.remove(os.path.join(out, "scan01.ply"))
    third = run([pipeline] + subset + ["--out", out, "--serial"])
    assert third.returncode == 0 and (summary(out)["done"], summary(out)["skipped"]) == (1, 5)
    check_complete(out, names_of(subset))


def test_shards_cover_every_scan_once(scans, tmp_path):
    subset = scans[:7]
    pipeline = write_pipeline(str(tmp_path))
    seen = []
    for index in range(3):
        out = str(tmp_path / f"shard{index}")
        result = run([pipeline] + subset + ["--out", out, "--serial", "--shard", f"{index}/3"])
        assert result.returncode == 0, result.stderr
        assert summary(out, f"summary.shard{index}of3.json")["shard"] == f"{index}/3"
        seen += list(records(out))
    assert sorted(seen) == sorted(names_of(subset))  # each scan once, none missing


def test_failures_are_recorded_and_the_others_go_on(scans, tmp_path):
    folder = tmp_path / "inputs"
    folder.mkdir()
    for path in scans[:3]:
        for source in (path, path.replace(".ptx", "_mask.png")):
            os.symlink(source, folder / os.path.basename(source))
    os.remove(folder / "scan01_mask.png")
    inputs = sorted(str(p) for p in folder.glob("*.ptx"))
    out = str(tmp_path / "out")
    result = run([write_pipeline(str(tmp_path))] + inputs + ["--out", out, "--serial"])
    assert result.returncode == 1
    report = summary(out)
    assert (report["done"], report["failed"]) == (2, 1)
    assert report["failures"][0]["name"] == "scan01"
    assert "steps[0] (fill) exit 1" in report["failures"][0]["error"]
    assert "scan01_mask.png" in report["failures"][0]["error"]
    assert records(out)["scan01"]["status"] == "failed"


def test_bad_pipelines_and_arguments(scans, tmp_path):
    bad = write_pipeline(str(tmp_path), {"steps": [{"options": {}}]})
    result = run([bad, scans[0], "--out", str(tmp_path / "out")])
    assert result.returncode == 2 and "steps[0]: field 'command'" in result.stderr
    result = run([write_pipeline(str(tmp_path)), scans[0], "--out", str(tmp_path / "out"), "--shard", "3/2"])
    assert result.returncode == 2 and "--shard" in result.stderr
    # Options are checked by the command with its own message.
    wrong = write_pipeline(str(tmp_path), {"steps": [{"command": "fill", "options": {"patch_radius": 0},
                                                      "mask": "{name}_mask.png", "output": "{name}_f.e57"}]})
    result = run([wrong, scans[0], "--out", str(tmp_path / "out2"), "--serial"])
    assert result.returncode == 1
    assert "patch_radius" in summary(str(tmp_path / "out2"))["failures"][0]["error"]


def test_the_cli_runs_the_driver(scans, tmp_path):
    out = str(tmp_path / "out")
    result = subprocess.run([CLI, "batch", write_pipeline(str(tmp_path))] + scans[:2] + ["--out", out, "--serial"],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "2 scans: 2 done" in result.stderr
    check_complete(out, names_of(scans[:2]))


def test_an_existing_cluster_through_scheduler(scans, tmp_path):
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        out = str(tmp_path / "out")
        result = run([write_pipeline(str(tmp_path))] + scans[:4] + ["--out", out, "--scheduler",
                                                                     cluster.scheduler_address])
        assert result.returncode == 0, result.stderr
        assert summary(out)["mode"] == f"scheduler {cluster.scheduler_address}"
        check_complete(out, names_of(scans[:4]))


def test_resume_redoes_a_scan_whose_inputs_or_steps_changed(scans, tmp_path):
    """A record holds for the steps and the input files it was made from: changing a step's options (even to
    invalid ones), replacing an input scan or an output redoes the scans concerned, and only them."""
    folder = tmp_path / "inputs"
    folder.mkdir()
    for path in scans[:2]:
        for source in (path, path.replace(".ptx", "_mask.png")):
            with open(source, "rb") as stream, open(folder / os.path.basename(source), "wb") as copy:
                copy.write(stream.read())
    inputs = sorted(str(p) for p in folder.glob("*.ptx"))
    out = str(tmp_path / "out")

    def go(pipeline):
        result = run([write_pipeline(str(tmp_path), pipeline)] + inputs + ["--out", out, "--serial"])
        report = summary(out)
        return result, (report["done"], report["skipped"], report["failed"])

    def stamp(name):
        return os.stat(os.path.join(out, f"{name}_filled.e57")).st_mtime_ns

    result, counts = go(PIPELINE)
    assert result.returncode == 0 and counts == (2, 0, 0), result.stderr
    assert go(PIPELINE)[1] == (0, 2, 0)  # nothing changed: nothing redone
    before = {name: stamp(name) for name in ("scan00", "scan01")}

    # An input scan replaced by another one (same name): that scan alone is redone.
    with open(scans[5], "rb") as stream, open(folder / "scan00.ptx", "wb") as copy:
        copy.write(stream.read())
    assert go(PIPELINE)[1] == (1, 1, 0)
    assert stamp("scan00") != before["scan00"] and stamp("scan01") == before["scan01"]

    # Other options for a step: every scan is redone, with an options file that describes them.
    changed = json.loads(json.dumps(PIPELINE))
    changed["steps"][0]["options"]["patch_radius"] = 5
    assert go(changed)[1] == (2, 0, 0)
    used = {path: json.load(open(path)) for path in glob.glob(os.path.join(out, ".batch", "step0_options_*.json"))}
    assert len(used) == 2 and all(options in used.values() for options in
                                  (PIPELINE["steps"][0]["options"], changed["steps"][0]["options"]))
    assert go(changed)[1] == (0, 2, 0)

    # Options a step refuses: every scan fails, and no output of earlier options is left to pass for a result.
    invalid = json.loads(json.dumps(PIPELINE))
    invalid["steps"][0]["options"]["method"] = "nope"
    result, counts = go(invalid)
    assert result.returncode == 1 and counts == (0, 0, 2)
    assert not glob.glob(os.path.join(out, "*_filled.e57")) and not glob.glob(os.path.join(out, "*.ply"))
    assert all(record["status"] == "failed" for record in records(out).values())

    # Back to the first options: redone (the outputs were removed), then skipped; a replaced output is redone.
    assert go(PIPELINE)[1] == (2, 0, 0)
    with open(os.path.join(out, "scan01.ply"), "ab") as stream:
        stream.write(b"\n")
    assert go(PIPELINE)[1] == (1, 1, 0)
    check_complete(out, ["scan00", "scan01"])


def logging_cli(tmp_path):
    """A lidarshop that logs its arguments (and the steps of `lidarshop steps`), then runs the real one."""
    log, steps = tmp_path / "argv.log", tmp_path / "steps.log"
    wrapper = tmp_path / "lidarshop"
    wrapper.write_text(f'#!/bin/sh\necho "$@" >> "{log}"\n'
                       f'if [ "$1" = steps ]; then cat "$2" >> "{steps}"; echo >> "{steps}"; fi\n'
                       f'exec "{CLI}" "$@"\n')
    wrapper.chmod(0o755)
    return wrapper, log, steps


def test_max_memory_reaches_every_step(scans, tmp_path):
    wrapper, log, steps = logging_cli(tmp_path)
    out = str(tmp_path / "out")
    result = run([write_pipeline(str(tmp_path))] + scans[:1] + ["--out", out, "--serial", "--max-memory", "3G",
                                                              "--lidarshop", str(wrapper)])
    assert result.returncode == 0, result.stderr
    argvs = [" ".join(argv) for line in steps.read_text().splitlines() for argv in json.loads(line)["steps"]]
    assert len(argvs) == 2 and all(argv.endswith("--max-memory 3G") or "--max-memory 3G " in argv for argv in argvs)
    result = run([write_pipeline(str(tmp_path))] + scans[:1] + ["--out", out, "--serial", "--max-memory", "lots"])
    assert result.returncode == 2 and "--max-memory" in result.stderr


THREE_STEPS = {"steps": [
    {"command": "fill", "options": {"method": "laplace", "poisson": {"solver": "direct"}},
     "mask": "{name}_mask.png", "output": "{name}_filled.e57"},
    {"command": "render", "output": "{name}_filled.png"},
    {"command": "convert", "output": "{name}.ply"},
]}


def test_one_process_per_scan_runs_all_its_steps(scans, tmp_path):
    wrapper, log, steps = logging_cli(tmp_path)
    out = str(tmp_path / "out")
    result = run([write_pipeline(str(tmp_path), THREE_STEPS)] + scans[:3] + ["--out", out, "--serial",
                                                                            "--lidarshop", str(wrapper)])
    assert result.returncode == 0, result.stderr
    # One `lidarshop steps` per scan, holding the scan's three steps, each fed the last scan written.
    invocations = log.read_text().splitlines()
    assert len(invocations) == 3 and all(line.startswith("steps ") for line in invocations)
    for line in steps.read_text().splitlines():
        argvs = json.loads(line)["steps"]
        assert [argv[0] for argv in argvs] == ["fill", "render", "convert"]
        assert argvs[1][1] == argvs[2][1] == argvs[0][argvs[0].index("-o") + 1]
    found = records(out)
    assert sorted(found) == names_of(scans[:3])
    for name, record in found.items():
        assert record["status"] == "ok"
        assert [step["command"] for step in record["steps"]] == ["fill", "render", "convert"]
        assert [os.path.basename(step["output"]) for step in record["steps"]] == [
            f"{name}_filled.e57", f"{name}_filled.png", f"{name}.ply"]
        assert all(step["seconds"] > 0 for step in record["steps"])
        assert os.path.getsize(os.path.join(out, f"{name}_filled.png")) > 0
    check_complete(out, names_of(scans[:3]))


def test_a_failing_middle_step_is_reported_as_the_command_says_it(scans, tmp_path):
    out = str(tmp_path / "out")
    assert run([write_pipeline(str(tmp_path), THREE_STEPS)] + scans[:1] + ["--out", out, "--serial"]).returncode == 0
    name = names_of(scans[:1])[0]
    failing = json.loads(json.dumps(THREE_STEPS))
    failing["steps"][1]["channel"] = "nope"
    result = run([write_pipeline(str(tmp_path), failing)] + scans[:1] + ["--out", out, "--serial"])
    assert result.returncode == 1
    record = records(out)[name]
    # What the command alone says for the same arguments, as its last line on stderr.
    alone = subprocess.run([CLI, "render", os.path.join(out, f"{name}_filled.e57"), "-o",
                            os.path.join(out, f"{name}_filled.png"), "--channel", "nope"],
                           capture_output=True, text=True, timeout=60)
    assert alone.returncode == 2
    said = alone.stderr.strip().splitlines()[-1]
    assert said.startswith("lidarshop render: ") and "nope" in said
    assert record["status"] == "failed" and record["failed_step"] == 1
    assert record["error"] == f"steps[1] (render) exit 2: {said}"
    assert [step["command"] for step in record["steps"]] == ["fill", "render"]
    assert sorted(record) == sorted(["scan", "name", "status", "steps", "host", "pid", "key", "failed_step", "error",
                                     "removed_stale_outputs", "seconds"])
    # The outputs of the failed step and after it, from the first run, are gone; the fill's stays.
    assert record["removed_stale_outputs"] == [os.path.join(out, f"{name}_filled.png"), os.path.join(out, f"{name}.ply")]
    assert os.path.exists(os.path.join(out, f"{name}_filled.e57"))
    assert summary(out)["failures"] == [{"name": name, "scan": scans[0], "error": record["error"]}]


def test_a_step_that_ends_the_process_fails_its_scan_as_the_command_alone(scans, tmp_path):
    """A step killed in the middle (here by the file size limit, SIGXFSZ, when the fill writes its scan) ends the
    scan's process: the scan fails at that step with the signal, the steps before it as done, the next scan goes
    on; the error is what the command alone ends with, not the earlier step's last line."""
    limited = tmp_path / "lidarshop"
    limited.write_text(f'#!/bin/sh\nulimit -f 24\nexec "{CLI}" "$@"\n')  # 12 or 24 KB: a PNG fits, an E57 not
    limited.chmod(0o755)
    pipeline = {"steps": [{"command": "render", "output": "{name}.png"}] + THREE_STEPS["steps"][:1]
                + THREE_STEPS["steps"][2:]}
    out = str(tmp_path / "out")
    result = run([write_pipeline(str(tmp_path), pipeline)] + scans[:2] + ["--out", out, "--serial",
                                                                         "--lidarshop", str(limited)])
    assert result.returncode == 1
    options = glob.glob(os.path.join(out, ".batch", "step1_options_*.json"))
    alone = subprocess.run([str(limited), "fill", scans[0], "-o", str(tmp_path / "alone.e57"), "--options",
                            options[0], "--mask", scans[0].replace(".ptx", "_mask.png")], capture_output=True,
                           text=True, timeout=60)
    assert alone.returncode == -signal.SIGXFSZ
    lines = [line for line in alone.stderr.strip().splitlines() if line.strip()]
    found = records(out)
    assert sorted(found) == names_of(scans[:2])
    for name, record in found.items():
        assert record["status"] == "failed" and record["failed_step"] == 1
        assert record["error"] == f"steps[1] (fill) exit {-signal.SIGXFSZ}: " + (lines[-1] if lines else "no message")
        assert [step["command"] for step in record["steps"]] == ["render", "fill"]
        assert os.path.getsize(os.path.join(out, f"{name}.png")) > 0
