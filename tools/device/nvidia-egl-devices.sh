#!/usr/bin/env bash
# Which GPU each EGL device index opens, on an NVIDIA machine: the check `reliefkit batch
# --executor ray` relies on (a Ray worker makes its GL context on the EGL device whose index
# is its task's first Ray GPU id, GLCONTEXT_DEVICE_INDEX; Ray numbers GPUs as CUDA does).
# For each index: GL_RENDERER, first with NVIDIA's EGL vendor alone (as prepare.sh sets it),
# then with every vendor glvnd finds (Mesa's llvmpipe too, as on a node with Mesa
# installed): index k should be `nvidia-smi -L`'s GPU k, and Mesa's devices should come
# after NVIDIA's. Needs .gl/ and .whl/ as nvidia-bench.sh does. Writes OUT/egl-devices.txt
# (OUT defaults to out/nvidia).
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT="${OUT:-out/nvidia}"
mkdir -p "$OUT"
# shellcheck source=prepare.sh
. tools/device/prepare.sh || exit 2
probe='
import os, moderngl
for index in range(16):
    os.environ["GLCONTEXT_DEVICE_INDEX"] = str(index)
    try:
        ctx = moderngl.create_context(standalone=True, backend="egl", require=330)
    except Exception as exc:
        print(f"  EGL device {index}: none ({str(exc).splitlines()[0][:80]})")
        break
    renderer = ctx.info["GL_RENDERER"]
    print(f"  EGL device {index}: {renderer}")
    ctx.release()
'
{
    echo "nvidia-smi -L:"; nvidia-smi -L 2>&1 | sed 's/^/  /'
    echo "EGL, NVIDIA's vendor alone (__EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-unset}):"
    "$PY" -c "$probe"
    echo "EGL, every vendor glvnd finds:"
    env -u __EGL_VENDOR_LIBRARY_FILENAMES "$PY" -c "$probe"
} 2>&1 | tee "$OUT/egl-devices.txt"
