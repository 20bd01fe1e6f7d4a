#!/usr/bin/env bash
# Install what the viewer's browser test needs on a fresh Debian machine: headless Chromium and its
# WebDriver from Debian's packages (never a browser download from elsewhere).  Idempotent and quiet:
# does nothing when both are already there.  Needs root (CI machines run as root) or sudo.
set -euo pipefail

have() { command -v "$1" >/dev/null 2>&1; }

if have chromium && have chromedriver; then
    exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    if have sudo; then SUDO="sudo"; else
        echo "install-browser: chromium/chromedriver missing and not root; install the Debian packages chromium and chromium-driver" >&2
        exit 1
    fi
fi

export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends chromium chromium-driver fonts-liberation; } >"$log" 2>&1; then
    echo "install-browser: apt-get failed:" >&2
    tail -n 20 "$log" >&2
    exit 1
fi
echo "install-browser: $(chromium --version 2>/dev/null | head -n1); $(chromedriver --version 2>/dev/null | head -n1)"
