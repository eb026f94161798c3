# Sourced by the device scripts (nvidia-bench.sh, nvidia-viewer-bench.sh) from the repository
# root: the GL loaders of .gl/ unpacked with NVIDIA's EGL vendor named (not on a workstation),
# the wheels of .whl/ the image lacks installed into /tmp/site, reliefkit's src/ on the path,
# and the image's numpy, scipy and numba checked to import together. Sets PY (default
# python3); returns 2 with an `error:` line where something is missing.
PY="${PY:-python3}"
if [ -d /usr/local/nvidia ] && [ -d .gl ]; then  # unpack the GL loaders (not on a workstation)
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
    egl_vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    [ -f "$egl_vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$egl_vendor"
fi
if ! "$PY" -c "import moderngl, glcontext, trimesh" 2>/dev/null; then
    [ -d .whl ] || { echo "error: no .whl/ here: run tools/device/fetch-deps.sh first" >&2; return 2; }
    "$PY" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl || return 2
    export PYTHONPATH="/tmp/site${PYTHONPATH:+:$PYTHONPATH}"
fi
export PYTHONPATH="$PWD/src${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
# the image's own numpy, scipy and numba are used: say so if they do not go together
"$PY" -c "import numpy, scipy, numba; print('numpy', numpy.__version__, 'numba', numba.__version__)" \
    || { echo "error: the image's numba/numpy do not import together: add numba and llvmlite" \
              "wheels to .whl/" >&2; return 2; }
command -v nvidia-smi >/dev/null && nvidia-smi -L
return 0
