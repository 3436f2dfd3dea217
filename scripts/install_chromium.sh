#!/usr/bin/env bash
# Headless Chromium for crates/cli/tests/html_reports.rs, which renders the diagnosis pages in
# it: Debian's package, installed only when `chromium` is not already on PATH.
set -euo pipefail
if command -v chromium >/dev/null 2>&1; then
    exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
    echo "install_chromium.sh: chromium is missing; run as root, or: sudo apt-get install -y chromium" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get install -y chromium || { apt-get update && apt-get install -y chromium; }
