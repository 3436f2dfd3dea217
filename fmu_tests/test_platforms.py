"""The binaries that dist/JetPipeActuator.fmu ships (issue 21): linux64 linked against glibc 2.17
at most (manylinux2014 class: RHEL 7+, Ubuntu 14.04+, Debian 8+ load it), built by
scripts/package.sh with cargo-zigbuild."""

from __future__ import annotations

import re
import zipfile
from pathlib import Path


REPO = Path(__file__).resolve().parents[1]
GLIBC_MAX = (2, 17)


def glibc_versions(binary: bytes) -> set[tuple[int, ...]]:
    """The GLIBC symbol versions an ELF file names (its version-needed strings)."""
    return {tuple(int(x) for x in m.group(1).split(b".")) for m in re.finditer(rb"GLIBC_(\d+(?:\.\d+)+)\x00", binary)}


def test_linux64_needs_glibc_2_17_at_most(fmu_path):
    with zipfile.ZipFile(fmu_path) as zf:
        binary = zf.read("binaries/linux64/JetPipeActuator.so")
    versions = glibc_versions(binary)
    assert versions, "no GLIBC symbol versions found: not a dynamically linked glibc library?"
    highest = max(versions)
    print(f"highest GLIBC symbol version of binaries/linux64: {'.'.join(map(str, highest))}")
    assert highest <= GLIBC_MAX, f"binaries/linux64 needs GLIBC_{'.'.join(map(str, highest))} > 2.17"


def test_the_check_sees_a_newer_glibc():
    """The same check on the host build (linked against this machine's glibc) finds a newer
    version: the scan is not vacuous."""
    host = REPO / "target" / "release" / "libjetpipe.so"
    assert host.is_file(), f"{host} not built (scripts/test.sh builds it: cargo build --release --lib -p jetpipe-fmu -p jetpipe-cli)"
    assert max(glibc_versions(host.read_bytes())) > GLIBC_MAX
