#!/usr/bin/env bash
# Set up (install missing packages, build) and run the whole test suite
# (GoogleTest under ctest). Tests that need ../shared/data skip cleanly when
# it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cd build
ctest --output-on-failure --timeout 900 -j"$(nproc)"
