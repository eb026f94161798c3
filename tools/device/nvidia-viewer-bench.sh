#!/usr/bin/env bash
# `reliefkit bench viewer` at 1920x1080 on an NVIDIA machine: the viewer page's frame time per
# kind with Chromium's WebGL2 on the GPU (--browser gpu: ANGLE on the EGL driver, NVIDIA's as
# prepare.sh names it), against the issue's target of 60 fps for every demo asset; writes
# OUT/viewer/viewer.{md,json} and OUT/viewer.log (OUT defaults to out/nvidia). Extra arguments
# go to the bench (say --quick for a dry run). PY picks the Python (default python3).
#
# NOT RUN ON A GPU: written when no device was lent (issue 32). A --quick dry run on the
# 2-core machine without a GPU went through (llvmpipe drew, and the warning below said so).
# What it needs there, besides prepare.sh's .gl/ and .whl/ (tools/device/fetch-deps.sh):
# - Chromium. It cannot travel with the device tool: Debian's chromium .deb alone is 81 MB
#   (290 MB installed, with ~40 libraries the image lacks: GTK, NSS, ...), over the 64 MiB the
#   tool carries. So this runs only on a machine whose image has a Chromium (`chromium` on the
#   PATH, or RELIEFKIT_CHROMIUM naming one), and otherwise stops with one line saying so.
# - Playwright for Python: in the image, or its wheels in .whl/viewer/ (VIEWER=1
#   tools/device/fetch-deps.sh).
# The report's "WebGL renderer" line says which device drew: SwiftShader or llvmpipe there
# means Chromium fell back to the CPU, and the figures are not the GPU's (this script says so).
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT="${OUT:-out/nvidia}"
mkdir -p "$OUT"
# shellcheck source=prepare.sh
. tools/device/prepare.sh || exit 2
if ! "$PY" -c "import playwright.sync_api" 2>/dev/null && [ -d .whl/viewer ]; then
    "$PY" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/viewer/*.whl || exit 2
    case ":${PYTHONPATH:-}:" in *:/tmp/site:*) ;; *) export PYTHONPATH="$PYTHONPATH:/tmp/site" ;; esac
fi
# Chromium and Playwright found (or one line saying what is missing) before anything is baked
"$PY" -c "from reliefkit.viewer.browser import chromium_path, require_playwright
require_playwright(); print('chromium', chromium_path())" || exit 2
"$PY" -c 'import sys; from reliefkit.cli import main; sys.exit(main(sys.argv[1:]))' \
    bench viewer --browser gpu --size 1920x1080 --out "$OUT/viewer" "$@" 2>&1 \
    | tee "$OUT/viewer.log"
status=${PIPESTATUS[0]}
if grep -qiE "WebGL renderer .*(swiftshader|llvmpipe)" "$OUT/viewer/viewer.md" 2>/dev/null; then
    echo "warning: Chromium drew on the CPU, not the GPU: these are not the NVIDIA figures" >&2
fi
exit "$status"
