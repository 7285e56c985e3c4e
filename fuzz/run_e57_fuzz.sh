#!/bin/bash
# Kept for the commands in docs/e57.md and bench/results/e57.md: fuzzes the E57 reader only.
#   fuzz/run_e57_fuzz.sh [seconds=300]
exec "$(dirname "$0")/../scripts/fuzz.sh" "${1:-300}" e57
