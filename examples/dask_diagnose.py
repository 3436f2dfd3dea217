"""`jetpipe diagnose --out` for many recordings, on a dask.distributed cluster.

usage:
    python examples/dask_diagnose.py RECORDING_OR_DIR... --out OUT
                                     [--jetpipe target/release/jetpipe] [--scheduler tcp://HOST:8786]
                                     [--workers 2] [--jobs-per-task 1] [--params p.json] [--calibrate]

Writes what `jetpipe diagnose RECORDINGS --out OUT` writes: OUT/NAME.json and OUT/NAME.html
per recording, OUT/summary.csv and OUT/index.html. A directory stands for the .csv files in it
and its subdirectories, named by their path from it with '/' written '-', as the CLI names
them. Each task diagnoses one recording with the `jetpipe` executable on a worker
(`jetpipe diagnose NAME.csv --out TMP --jobs J`) and returns the report and the page; a
recording that cannot be diagnosed comes back as OUT/NAME.error.txt. At the end
`jetpipe diagnosis-index OUT` writes the summary and the index from what came back.

Without --scheduler a LocalCluster on the loopback interface is started with --workers worker
processes of one thread each. With --scheduler the tasks go to that cluster: the executable
is sent to the workers as bytes, scattered once (so the workers must be Linux on the same
architecture as this machine, with a glibc at least as new as the build's), and each
recording as bytes with its task; no shared file system is needed.

--jobs-per-task is the cores one diagnosis uses (its candidate fits run in parallel); set it
to the cores of a worker divided by its threads.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import os
import stat
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
ERROR_SUFFIX = ".error.txt"  # jetpipe_cli::batch::ERROR_SUFFIX

# ----------------------------------------------------------------------------------------
# Worker side.
# ----------------------------------------------------------------------------------------

_EXECUTABLES: dict[str, str] = {}
_EXECUTABLES_LOCK = threading.Lock()


def _executable(digest: str, data: bytes) -> str:
    """The `jetpipe` executable with this SHA-256, written once per worker process."""
    with _EXECUTABLES_LOCK:
        if digest not in _EXECUTABLES:
            directory = tempfile.mkdtemp(prefix="jetpipe-dask-diagnose-")
            path = os.path.join(directory, "jetpipe")
            with open(path, "wb") as f:
                f.write(data)
            os.chmod(path, stat.S_IRWXU)
            _EXECUTABLES[digest] = path
        return _EXECUTABLES[digest]


def diagnose_task(name: str, recording: bytes, digest: str, executable: bytes, jobs: int,
                  params: bytes | None, calibrate: bool) -> dict:
    """Diagnose one recording on this worker: its report and page as text, or its error."""
    jetpipe = _executable(digest, executable)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="jetpipe-dask-task-") as work:
        work = Path(work)
        (work / f"{name}.csv").write_bytes(recording)
        command = [jetpipe, "diagnose", str(work / f"{name}.csv"), "--out", str(work / "out"), "--jobs", str(jobs)]
        if params is not None:
            (work / "params.json").write_bytes(params)
            command += ["--params", str(work / "params.json")]
        if calibrate:
            command.append("--calibrate")
        run = subprocess.run(command, capture_output=True, text=True)
        result = {"name": name, "wall_s": time.perf_counter() - started}
        report, page = work / "out" / f"{name}.json", work / "out" / f"{name}.html"
        if run.returncode == 0 and report.is_file() and page.is_file():
            result["report"] = report.read_text()
            result["page"] = page.read_text()
        else:
            # The batch's own row says why; without it (no summary written), its last words.
            summary = work / "out" / "summary.csv"
            rows = list(csv.DictReader(summary.open())) if summary.is_file() else []
            error = rows[0]["error"] if rows else (run.stderr.strip().splitlines() or ["no output"])[-1]
            result["error"] = error.replace(str(work / f"{name}.csv"), f"{name}.csv")
        return result


# ----------------------------------------------------------------------------------------
# Client side.
# ----------------------------------------------------------------------------------------

def recordings_of(inputs: list[Path]) -> list[tuple[str, Path]]:
    """(name, path) of every recording the inputs stand for, named as `jetpipe diagnose` names them."""
    found: list[tuple[str, Path]] = []
    for given in inputs:
        if given.is_dir():
            paths = sorted(p for p in given.rglob("*") if p.is_file() and p.suffix.lower() == ".csv")
            if not paths:
                raise SystemExit(f"dask_diagnose: {given}: the directory holds no .csv recording")
            found += [("-".join(p.relative_to(given).with_suffix("").parts), p) for p in paths]
        elif given.is_file():
            found.append((given.stem, given))
        else:
            raise SystemExit(f"dask_diagnose: cannot read {given}: no such file or directory")
    names = [name for name, _ in found]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise SystemExit(f"dask_diagnose: two recordings would both be written as {twice[0]}.json")
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("recordings", nargs="+", type=Path)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--jetpipe", type=Path, default=REPO / "target" / "release" / "jetpipe")
    parser.add_argument("--scheduler")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--jobs-per-task", type=int, default=1)
    parser.add_argument("--params", type=Path)
    parser.add_argument("--calibrate", action="store_true")
    args = parser.parse_args()
    if args.workers < 1 or args.jobs_per_task < 1:
        parser.error("--workers and --jobs-per-task must be at least 1")
    if not args.jetpipe.is_file():
        parser.error(f"--jetpipe {args.jetpipe}: no such file (cargo build --release --bin jetpipe)")

    from dask.distributed import Client, LocalCluster, as_completed

    recordings = recordings_of(args.recordings)
    args.out.mkdir(parents=True, exist_ok=True)
    executable = args.jetpipe.read_bytes()
    digest = hashlib.sha256(executable).hexdigest()
    params = args.params.read_bytes() if args.params else None

    if args.scheduler:
        client = Client(args.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None)
        client = Client(cluster)
    started = time.perf_counter()
    try:
        # Run as a script this file is __main__, whose functions cloudpickle sends by value with
        # the globals they use (a lock among them, which does not pickle); the uploaded module,
        # imported by name, is sent by reference.
        client.upload_file(__file__)
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        import dask_diagnose as module

        executable_ref = client.scatter(executable, broadcast=True)
        futures = [
            client.submit(module.diagnose_task, name, path.read_bytes(), digest, executable_ref, args.jobs_per_task,
                          params, args.calibrate, key=f"diagnose-{name}-{digest[:8]}", pure=False)
            for name, path in recordings
        ]
        failed = []
        for future in as_completed(futures):
            result = future.result()
            name = result["name"]
            for stale in (f"{name}.json", f"{name}.html", f"{name}{ERROR_SUFFIX}"):
                (args.out / stale).unlink(missing_ok=True)
            if "error" in result:
                failed.append(name)
                (args.out / f"{name}{ERROR_SUFFIX}").write_text(result["error"] + "\n")
                print(f"[{time.perf_counter() - started:6.1f} s] {name}: {result['error']}", file=sys.stderr)
            else:
                (args.out / f"{name}.json").write_text(result["report"])
                (args.out / f"{name}.html").write_text(result["page"])
                print(f"[{time.perf_counter() - started:6.1f} s] {name}: done ({result['wall_s']:.1f} s)", file=sys.stderr)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    wall = time.perf_counter() - started
    workers = "the scheduler's workers" if args.scheduler else f"{args.workers} workers"
    subprocess.run([str(args.jetpipe), "diagnosis-index", str(args.out), "--timing",
                    f"{wall:.1f} s wall on {workers} with dask"], check=True)
    print(f"{len(recordings)} recordings in {wall:.1f} s; {len(failed)} failed{': ' + ', '.join(failed) if failed else ''}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
