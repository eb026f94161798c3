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
PY="${PY:-python3}"
OUT="${OUT:-out/nvidia}"
mkdir -p "$OUT"
if [ -d /usr/local/nvidia ] && [ -d .gl ]; then  # unpack the GL loaders (not on a workstation)
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
    egl_vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    [ -f "$egl_vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$egl_vendor"
fi
if ! "$PY" -c "import moderngl, glcontext, trimesh" 2>/dev/null; then
    [ -d .whl ] || { echo "error: no .whl/ here: run tools/device/fetch-deps.sh first" >&2; exit 2; }
    "$PY" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl || exit 2
    export PYTHONPATH="/tmp/site${PYTHONPATH:+:$PYTHONPATH}"
fi
export PYTHONPATH="$PWD/src${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
# the image's own numpy, scipy and numba are used: say so if they do not go together
"$PY" -c "import numpy, scipy, numba; print('numpy', numpy.__version__, 'numba', numba.__version__)" \
    || { echo "error: the image's numba/numpy do not import together: add numba and llvmlite" \
              "wheels to .whl/" >&2; exit 2; }
command -v nvidia-smi >/dev/null && nvidia-smi -L
"$PY" -c "from reliefkit.gl.context import get_context, gl_info; print(gl_info(get_context()))" \
    || exit 3
"$PY" -c 'import sys; from reliefkit.cli import main; sys.exit(main(sys.argv[1:]))' \
    bench relief --out "$OUT/relief" "$@" 2>&1 | tee "$OUT/relief.log"
