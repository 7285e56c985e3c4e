"""lidarshop batch: a pipeline of lidarshop commands over many scans, locally or on a Dask cluster.

    lidarshop batch PIPELINE.json SCANS... --out DIR [--workers N | --scheduler ADDRESS | --serial] [--shard i/N]
    python3 -m lidarshop_batch PIPELINE.json SCANS... --out DIR ...          (the same; build/release/python)

PIPELINE.json:
    {"steps": [{"command": "remove", "options": {"margin_cells": 2}, "strokes": "{name}.json",
                "output": "{name}_removed.e57"},
               {"command": "convert", "output": "{name}.ply"}]}

Each step runs the `lidarshop` command of that name on the last scan an earlier step wrote (the first step on
the scan file; an output that is not a scan file, such as a `render` step's PNG, is a side result the next step
does not take): `lidarshop COMMAND INPUT -o OUTPUT --options OPTIONS.json --KEY VALUE...` (`convert` takes its output
as the second positional argument). `options` is the command's options as JSON, the same form as the CLI's
--options files (docs/options.md): checked by the command itself, with its messages. Every other key of a
step becomes a flag (`"strokes": ...` -> `--strokes ...`, `true` -> a bare flag); `{name}` is the scan's file
stem, and a relative value holding `{name}` is a per-scan input next to the scan file. `output` is relative to
--out; a step without one writes to DIR/.work/.

One scan is one task: its steps run one after the other in one `lidarshop steps` process (the argv's of the
steps in a JSON file; it stops at the first step that fails and reports each step's exit code, seconds and last
line on stderr); its record DIR/records/NAME.json (status, per-step seconds, error, and the key of what it was
made from) is written last and atomically. A scan is skipped
(resume) only when its record says "ok" and its key still holds: the same steps with the same options and
flags, the same input files (the scan and its per-scan inputs, by size and modification time in ns), and its
outputs as the run left them; anything else redoes it. A failed scan is recorded and the others go on (it is
retried on the next run). A step's options go to DIR/.batch/stepI_options_HASH.json, named by their content,
so that a file there always describes the options of the runs that used it. At the end
DIR/summary.json (and one line on stderr): counts, failures, seconds, scans per minute. Exit 0 when every scan
is done, 1 when any failed, 2 for a bad pipeline or arguments.

Why one CLI process per scan: any command works with exactly its flags, checks and JSON options (`steps` runs
each through the same dispatch as `lidarshop COMMAND`); the process starts once per scan, not once per step (its
libraries, OpenCV's plugin on the first picture); a crash or memory blow-up of one scan fails that scan, not the
worker (a step that ends the process fails there, with the process's exit code); the library stays free of Dask.
"""
import argparse
import ctypes
import glob
import hashlib
import json
import os
import re
import signal
import shutil
import subprocess
import sys
import tempfile
import time

# What lidarshop's --max-memory takes (util/memory_budget.cc ParseMemorySize; it has the last word).
MEMORY_SIZE = re.compile(r"[0-9]+(\.[0-9]+)?([KMGT](I?B)?|B)?", re.IGNORECASE)

# Commands whose output is their second positional argument instead of -o.
POSITIONAL_OUTPUT = {"convert"}
# What lidarshop reads as a scan (io/scan_io.h): a step's output with one of these extensions is the next step's
# input; any other output (a render's PNG, a segment's mask) is a side result and the scan goes on unchanged.
SCAN_EXTENSIONS = {".ptx", ".e57", ".ply", ".pcd", ".las", ".laz", ".xyz", ".pts"}
# Commands whose output is a picture, not a scan: a step of theirs without an `output` writes a PNG to .work/.
PICTURE_OUTPUT = {"render", "segment"}
STEP_KEYS = {"command", "options", "output"}


class PipelineError(ValueError):
    """A pipeline file that cannot be run; the message names the file and the step."""


def load_pipeline(path):
    try:
        with open(path) as stream:
            pipeline = json.load(stream)
    except OSError as error:
        raise PipelineError(f"{path}: {error.strerror}") from None
    except json.JSONDecodeError as error:
        raise PipelineError(f"{path}: line {error.lineno}: {error.msg}") from None
    if not isinstance(pipeline, dict) or not isinstance(pipeline.get("steps"), list) or not pipeline["steps"]:
        raise PipelineError(f'{path}: expected {{"steps": [{{"command": ...}}, ...]}} with at least one step')
    unknown = set(pipeline) - {"steps", "description"}
    if unknown:
        raise PipelineError(f"{path}: unknown key '{sorted(unknown)[0]}' (keys: steps, description)")
    for index, step in enumerate(pipeline["steps"]):
        where = f"{path}: steps[{index}]"
        if not isinstance(step, dict) or not isinstance(step.get("command"), str) or not step["command"]:
            raise PipelineError(f"{where}: field 'command': expected a lidarshop command name")
        if step["command"] in ("batch", "serve", "demo"):
            raise PipelineError(f"{where}: field 'command': '{step['command']}' cannot be a batch step")
        if "options" in step and not isinstance(step["options"], dict):
            raise PipelineError(f"{where}: field 'options': expected an object (the command's JSON options)")
        if "output" in step and (not isinstance(step["output"], str) or "{name}" not in step["output"]):
            raise PipelineError(f"{where}: field 'output': expected a file name holding {{name}}")
        for key, value in step.items():
            if key not in STEP_KEYS and not isinstance(value, (str, int, float, bool)):
                raise PipelineError(f"{where}: field '{key}': expected a string, number or true/false")
    return pipeline


def scan_name(scan_path):
    return os.path.splitext(os.path.basename(scan_path))[0]


def step_outputs(pipeline, name, out_dir, scan_path):
    """The output file of every step for the scan `name` (absolute paths)."""
    outputs = []
    extension = os.path.splitext(scan_path)[1]
    for index, step in enumerate(pipeline["steps"]):
        if "output" in step:
            outputs.append(os.path.join(out_dir, step["output"].replace("{name}", name)))
        else:
            step_extension = ".png" if step["command"] in PICTURE_OUTPUT else extension
            outputs.append(os.path.join(out_dir, ".work", f"{name}.step{index}{step_extension}"))
    return outputs


def is_scan_file(path):
    return os.path.splitext(path)[1].lower() in SCAN_EXTENSIONS


def record_path(out_dir, name):
    return os.path.join(out_dir, "records", name + ".json")


def canonical_hash(value):
    """A short hash of a JSON value that does not depend on key order."""
    text = json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def options_path(options_dir, index, step):
    return os.path.join(options_dir, f"step{index}_options_{canonical_hash(step['options'])}.json")


def file_stamp(path):
    """What identifies a file's content cheaply: its size and modification time (ns); None when missing."""
    try:
        status = os.stat(path)
    except OSError:
        return None
    return [status.st_size, status.st_mtime_ns]


def per_scan_inputs(pipeline, name, scan_path):
    """The scan file and every per-scan input the steps name ({name} values, next to the scan file)."""
    paths = [scan_path]
    for step in pipeline["steps"]:
        for key, value in step.items():
            if key in STEP_KEYS or not isinstance(value, str) or "{name}" not in value:
                continue
            text = value.replace("{name}", name)
            paths.append(text if os.path.isabs(text) else os.path.join(os.path.dirname(scan_path), text))
    return paths


def scan_key(pipeline, scan_path):
    """What a scan's outputs are made from: the steps (commands, options, flags) and its input files."""
    name = scan_name(scan_path)
    return {"steps": canonical_hash(pipeline["steps"]),
            "inputs": [[path, file_stamp(path)] for path in per_scan_inputs(pipeline, name, scan_path)]}


def kept_outputs(pipeline, name, out_dir, scan_path):
    """The outputs a run keeps (steps with an `output`) and their stamps now."""
    return [[path, file_stamp(path)] for path, step in zip(step_outputs(pipeline, name, out_dir, scan_path),
                                                          pipeline["steps"]) if "output" in step]


def is_done(pipeline, scan_path, out_dir):
    """True when the scan's record says "ok" for these steps and these inputs, and its outputs are the ones that
    run wrote (none missing or replaced since)."""
    name = scan_name(scan_path)
    try:
        with open(record_path(out_dir, name)) as stream:
            record = json.load(stream)
    except (OSError, ValueError):
        return False
    outputs = kept_outputs(pipeline, name, out_dir, scan_path)
    return (isinstance(record, dict) and record.get("status") == "ok"
            and record.get("key") == scan_key(pipeline, scan_path)
            and all(stamp is not None for _, stamp in outputs) and record.get("outputs") == outputs)


def write_json_atomic(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    temporary = f"{path}.tmp{os.getpid()}"
    with open(temporary, "w") as stream:
        json.dump(data, stream, indent=1)
        stream.flush()
        os.fsync(stream.fileno())
    os.replace(temporary, path)


def step_argv(lidarshop, step, index, input_path, output_path, name, scan_dir, options_dir, max_memory=None):
    argv = [lidarshop, step["command"], input_path]
    if step["command"] in POSITIONAL_OUTPUT:
        argv.append(output_path)
    else:
        argv += ["-o", output_path]
    if "options" in step:
        argv += ["--options", options_path(options_dir, index, step)]
    if max_memory:
        argv += ["--max-memory", max_memory]
    for key, value in step.items():
        if key in STEP_KEYS:
            continue
        flag = "--" + key.replace("_", "-")
        if value is True:
            argv.append(flag)
        elif value is False:
            continue
        else:
            text = str(value)
            if "{name}" in text:
                text = text.replace("{name}", name)
                if not os.path.isabs(text):
                    text = os.path.join(scan_dir, text)
            argv += [flag, text]
    return argv


def die_with_parent():
    """In the scan's process: be killed when the worker that started it dies (Linux), so that no step of a
    lost task keeps writing while its re-run elsewhere writes the same files."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def remove_stale_temporaries(output):
    """Temporary files of lidarshop's atomic writes (util/atomic_file.cc: DIR/.STEM.tmpPID-N.EXT) left by an
    earlier attempt of this scan that was killed while writing."""
    stem, extension = os.path.splitext(os.path.basename(output))
    for path in glob.glob(os.path.join(glob.escape(os.path.dirname(output)), f".{glob.escape(stem)}.tmp*{extension}")):
        try:
            os.remove(path)
        except OSError:
            pass


def last_line(text):
    """The last line of a command's stderr that is not blank, as a failed scan's error gives it."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1] if lines else "no message"


def run_steps(lidarshop, argvs):
    """Runs the steps (argv's without the executable) in one `lidarshop steps` process. Returns one
    (exit code, seconds, message) per step that ran, the last the one that failed if any."""
    with tempfile.TemporaryDirectory(prefix="lidarshop_steps_") as folder:
        steps_path, report_path = os.path.join(folder, "steps.json"), os.path.join(folder, "report.json")
        with open(steps_path, "w") as stream:
            json.dump({"steps": argvs}, stream)
        start = time.monotonic()
        try:
            process = subprocess.run([lidarshop, "steps", steps_path, "--json", report_path, "--quiet"],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, preexec_fn=die_with_parent)
            returncode, stderr = process.returncode, process.stderr
        except OSError as error:
            returncode, stderr = -1, f"{lidarshop}: {error.strerror}".encode()
        seconds = time.monotonic() - start
        try:
            with open(report_path) as stream:
                entries = json.load(stream)["steps"]
        except (OSError, ValueError, KeyError, TypeError):
            entries = []  # the process did not start, or ended before its first step
    if not entries:
        return [(returncode or -1, seconds, last_line(stderr.decode(errors="replace")))]
    results = []
    for entry in entries:
        if entry["exit"] is None:  # the process ended in this step (a crash, a kill): its code and last words
            spent = max(seconds - sum(result[1] for result in results), 0.0)
            words = stderr[entry["stderr_offset"]:].decode(errors="replace")
            results.append((returncode if returncode != 0 else -1, spent, last_line(words)))
            break
        results.append((entry["exit"], entry["seconds"], entry["message"] or "no message"))
    if len(results) < len(argvs) and results[-1][0] == 0:  # it ended between two steps (its report unwritable)
        spent = max(seconds - sum(result[1] for result in results), 0.0)
        results.append((returncode if returncode != 0 else -1, spent, last_line(stderr.decode(errors="replace"))))
    return results


def run_scan(job):
    """One task: every step for one scan, in one `lidarshop steps` process. Returns the record (also written to
    DIR/records/NAME.json)."""
    pipeline, scan_path, out_dir, lidarshop = job["pipeline"], job["scan"], job["out"], job["lidarshop"]
    name = scan_name(scan_path)
    start = time.monotonic()
    # Taken before the first step: an input changed while the steps run makes the next run redo the scan.
    record = {"scan": scan_path, "name": name, "status": "ok", "steps": [], "host": os.uname().nodename,
              "pid": os.getpid(), "key": scan_key(pipeline, scan_path)}
    outputs = step_outputs(pipeline, name, out_dir, scan_path)
    for output in outputs:
        remove_stale_temporaries(output)
    argvs = []
    input_path = scan_path
    for index, (step, output) in enumerate(zip(pipeline["steps"], outputs)):
        os.makedirs(os.path.dirname(output), exist_ok=True)
        argvs.append(step_argv(lidarshop, step, index, input_path, output, name, os.path.dirname(scan_path),
                               os.path.join(out_dir, ".batch"), job.get("max_memory"))[1:])
        if is_scan_file(output):  # the last scan goes on: a picture in the middle is a side result
            input_path = output
    for index, (returncode, seconds, message) in enumerate(run_steps(lidarshop, argvs)):
        step = pipeline["steps"][index]
        record["steps"].append({"command": step["command"], "output": outputs[index], "seconds": round(seconds, 3)})
        if returncode != 0:
            record.update(status="failed", failed_step=index,
                          error=f"steps[{index}] ({step['command']}) exit {returncode}: {message}")
            break
    if record["status"] == "ok":
        record["outputs"] = kept_outputs(pipeline, name, out_dir, scan_path)
    else:
        # The outputs of the failed step and those after it are from an earlier run (other options or other
        # inputs): left there, they would pass for results of this one.
        for output, step in list(zip(outputs, pipeline["steps"]))[record["failed_step"]:]:
            if "output" in step and os.path.exists(output):
                os.remove(output)
                record.setdefault("removed_stale_outputs", []).append(output)
    record["seconds"] = round(time.monotonic() - start, 3)
    write_json_atomic(record_path(out_dir, name), record)
    return record


def parse_shard(text):
    try:
        index, count = (int(part) for part in text.split("/"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--shard: expected i/N (e.g. 0/4), got '{text}'") from None
    if count < 1 or not 0 <= index < count:
        raise argparse.ArgumentTypeError(f"--shard: expected 0 <= i < N, got '{text}'")
    return index, count


def default_lidarshop():
    if os.environ.get("LIDARSHOP_CLI"):
        return os.environ["LIDARSHOP_CLI"]
    beside = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lidarshop")  # build/<preset>/
    if os.path.exists(beside):
        return os.path.abspath(beside)
    return shutil.which("lidarshop") or "lidarshop"


def run_dask(jobs, scheduler, workers, log):
    from distributed import Client, LocalCluster, as_completed  # only batch runs need Dask

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        # pure=False: a task is never merged with another; a task on a worker that dies is re-run elsewhere
        # (its outputs are rewritten atomically and its record comes last, so nothing is half-written).
        futures = client.map(run_scan, jobs, pure=False, key=[f"scan-{scan_name(job['scan'])}" for job in jobs])
        records = []
        for future in as_completed(futures):
            try:
                records.append(future.result())
            except Exception as error:  # a task lost more often than the scheduler allows
                records.append({"name": "?", "status": "failed", "error": f"task lost: {error}"})
            log(records[-1])
        return records
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv=None):
    parser = argparse.ArgumentParser(prog="lidarshop batch", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("pipeline", help="PIPELINE.json")
    parser.add_argument("scans", nargs="+", help="scan files (their stems must differ)")
    parser.add_argument("--out", required=True, help="output folder (records/, summary.json, the step outputs)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--workers", type=int, default=None,
                       help="worker processes of a local Dask cluster (default: the number of CPUs)")
    where.add_argument("--serial", action="store_true", help="no Dask: one scan after the other here")
    parser.add_argument("--shard", type=parse_shard, default=(0, 1),
                        help="i/N: only the scans whose index in the sorted list is i modulo N (Slurm arrays)")
    parser.add_argument("--lidarshop", default=None, help="the lidarshop executable (default: the build's)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no line per scan and no summary line on stderr (errors still print)")
    parser.add_argument("--max-memory", metavar="SIZE", default=None,
                        help="memory budget of every step (e.g. 4G; lidarshop's --max-memory): larger requests "
                             "fail up front")
    args = parser.parse_args(argv)

    try:
        pipeline = load_pipeline(args.pipeline)
    except PipelineError as error:
        print(f"lidarshop batch: {error}", file=sys.stderr)
        return 2
    scans = sorted(os.path.abspath(path) for path in args.scans)
    names = [scan_name(path) for path in scans]
    duplicates = sorted({name for name in names if names.count(name) > 1})
    if duplicates:
        print(f"lidarshop batch: two scans named '{duplicates[0]}': outputs are named by the file stem",
              file=sys.stderr)
        return 2
    missing = [path for path in scans if not os.path.isfile(path)]
    if missing:
        print(f"lidarshop batch: {missing[0]}: no such file", file=sys.stderr)
        return 2
    if args.max_memory is not None and not MEMORY_SIZE.fullmatch(args.max_memory):
        print(f"lidarshop batch: --max-memory: '{args.max_memory}' is not a memory size (e.g. 512M, 8G)",
              file=sys.stderr)
        return 2
    if args.workers is not None and args.workers < 1:
        print("lidarshop batch: --workers: expected a number >= 1", file=sys.stderr)
        return 2
    shard_index, shard_count = args.shard
    scans = [path for index, path in enumerate(scans) if index % shard_count == shard_index]
    out_dir = os.path.abspath(args.out)
    lidarshop = os.path.abspath(args.lidarshop) if args.lidarshop else default_lidarshop()

    os.makedirs(os.path.join(out_dir, ".batch"), exist_ok=True)
    for index, step in enumerate(pipeline["steps"]):
        if "options" in step:  # named by content: rewriting one never changes what an earlier run used
            write_json_atomic(options_path(os.path.join(out_dir, ".batch"), index, step), step["options"])

    start = time.monotonic()
    todo = [path for path in scans if not is_done(pipeline, path, out_dir)]
    skipped = len(scans) - len(todo)
    jobs = [{"pipeline": pipeline, "scan": path, "out": out_dir, "lidarshop": lidarshop,
             "max_memory": args.max_memory} for path in todo]

    def log(record):
        if not args.quiet:
            detail = f" ({record.get('error')})" if record["status"] != "ok" else ""
            print(f"lidarshop batch: {record['name']}: {record['status']} {record.get('seconds', 0):.2f} s{detail}",
                  file=sys.stderr)

    workers = 1 if args.serial else args.workers or os.cpu_count() or 1
    if args.serial or not jobs:
        records = []
        for job in jobs:
            records.append(run_scan(job))
            log(records[-1])
    else:
        records = run_dask(jobs, args.scheduler, workers, log)
    seconds = time.monotonic() - start
    failures = [{"name": r["name"], "scan": r.get("scan"), "error": r.get("error")} for r in records
                if r["status"] != "ok"]
    done = len(records) - len(failures)
    summary = {"scans": len(scans), "done": done, "skipped": skipped, "failed": len(failures),
               "failures": sorted(failures, key=lambda f: f["name"]), "seconds": round(seconds, 3),
               "scans_per_minute": round(60.0 * len(records) / seconds, 2) if records and seconds > 0 else None,
               "shard": f"{shard_index}/{shard_count}",
               "mode": "serial" if args.serial else (f"scheduler {args.scheduler}" if args.scheduler
                                                     else f"local cluster of {workers} workers")}
    summary_name = "summary.json" if shard_count == 1 else f"summary.shard{shard_index}of{shard_count}.json"
    write_json_atomic(os.path.join(out_dir, summary_name), summary)
    if not args.quiet:
        print(f"lidarshop batch: {len(scans)} scans: {done} done, {skipped} skipped, {len(failures)} failed, "
              f"{seconds:.1f} s ({summary['mode']}); {os.path.join(out_dir, summary_name)}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
