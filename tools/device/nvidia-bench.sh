#!/usr/bin/env bash
# The relief bench at full resolution on an NVIDIA machine, in one go: its correctness table
# is the check that the shaders agree with the exact CPU reference there (exact and maxmip
# 0% wrong pixels, robust <= 0.5%), its frame times the NVIDIA figures of docs/benchmarks.md.
# Needs .gl/ and .whl/ from tools/device/fetch-deps.sh beside it (on the device tool: carry
# them). Writes OUT/relief/relief-bench.{md,json,png} and OUT/relief.log; OUT defaults to
# out/nvidia. Extra arguments go to `reliefkit bench relief` (say --quick for a dry run).
# PY picks the Python (default python3).
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT="${OUT:-out/nvidia}"
mkdir -p "$OUT"
# shellcheck source=prepare.sh
. tools/device/prepare.sh || exit 2
"$PY" -c "from reliefkit.gl.context import get_context, gl_info; print(gl_info(get_context()))" \
    || exit 3
"$PY" -c 'import sys; from reliefkit.cli import main; sys.exit(main(sys.argv[1:]))' \
    bench relief --out "$OUT/relief" "$@" 2>&1 | tee "$OUT/relief.log"
