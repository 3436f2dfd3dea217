"""examples/dask_diagnose.py on a 2-worker LocalCluster writes what `jetpipe diagnose DIR --out`
writes on this machine: the same reports and summary rows, a page per recording, and an error
row for a file that cannot be read, while the others go on.

The recordings come from the independent generator (benchgen): a force sensor offset and gain
(a named effect) and the receivers off the jet pipe null (a discovered term), 12 s each, and
the first of them cut in the middle of a row."""

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BIN = ROOT / "target" / "release"

needs_binaries = pytest.mark.skipif(
    not (BIN / "benchgen").exists() or not (BIN / "jetpipe").exists(),
    reason="needs target/release/benchgen and jetpipe (cargo test --release builds them)")


def summary(directory: Path) -> dict[str, dict[str, str]]:
    with (directory / "summary.csv").open() as f:
        return {row["recording"]: row for row in csv.DictReader(f)}


@needs_binaries
def test_the_dask_example_writes_the_reports_and_rows_of_the_local_batch(tmp_path):
    recordings = tmp_path / "recordings"
    (recordings / "hand").mkdir(parents=True)
    for path, args in [(recordings / "sensor.csv", ["--force-sensor-offset", "1.5", "--force-sensor-gain", "1.04"]),
                       (recordings / "hand" / "receivers.csv", ["--undeclared", "receiver_offset"])]:
        subprocess.run([str(BIN / "benchgen"), "--out", str(path), "--duration", "12", "--seed", "5", *args],
                       check=True, capture_output=True)
    text = (recordings / "sensor.csv").read_text()
    (recordings / "cut.csv").write_text(text[: len(text) // 2].rsplit(",", 1)[0] + "\n")

    local, distributed = tmp_path / "local", tmp_path / "dask"
    cli = subprocess.run([str(BIN / "jetpipe"), "diagnose", str(recordings), "--out", str(local), "--jobs", "2"],
                         capture_output=True, text=True)
    assert cli.returncode == 1, cli.stderr
    example = subprocess.run([sys.executable, str(ROOT / "examples" / "dask_diagnose.py"), str(recordings),
                              "--out", str(distributed), "--workers", "2"], capture_output=True, text=True)
    assert example.returncode == 1, example.stderr
    assert "1 failed: cut" in example.stdout

    rows_local, rows_dask = summary(local), summary(distributed)
    assert sorted(rows_dask) == sorted(rows_local) == ["cut", "hand-receivers", "sensor"]
    assert rows_dask["cut"]["verdict"] == rows_local["cut"]["verdict"] == "error"
    assert "cut.csv: row" in rows_dask["cut"]["error"]
    assert rows_dask["cut"]["error"].split("cut.csv: ")[1] == rows_local["cut"]["error"].split("cut.csv: ")[1]
    for name in ["hand-receivers", "sensor"]:
        assert rows_dask[name] == rows_local[name]
        report_local = json.loads((local / f"{name}.json").read_text())
        report_dask = json.loads((distributed / f"{name}.json").read_text())
        assert report_dask == report_local
        page = (distributed / f"{name}.html").read_text()
        assert report_dask["summary"][0].replace("&", "&amp;")[:40] in page
    # Each recording was given its term, so the rows compared are not two empty ones.
    assert rows_local["sensor"]["added"] == "sensor_offset_gain"
    assert rows_local["hand-receivers"]["added"].startswith("jet_pipe/parameter_offset")
    index = (distributed / "index.html").read_text()
    assert 'href="sensor.html"' in index and 'href="hand-receivers.html"' in index and "1 failed" in index
