#!/usr/bin/env bash
# Fetch, on a machine with internet access, what the device scripts need (prepare.sh) on an
# offline NVIDIA machine whose Python (3.12) lacks reliefkit's GL and mesh packages: the GL
# loader packages (Debian, amd64) into .gl/ and the missing wheels into .whl/ (both in
# .gitignore).
set -euo pipefail
cd "$(dirname "$0")/../.."
mkdir -p .gl .whl /tmp/amd64/partial
apt_arch='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
# shellcheck disable=SC2086
apt-get $apt_arch update -qq
# shellcheck disable=SC2086
(cd .gl && apt-get $apt_arch download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
# the packages the target lacks (its image has numpy, scipy, numba, pillow, matplotlib, ...)
for pkg in moderngl==5.13.0 glcontext==3.1.0 trimesh==5.2.0 DracoPy fast-simplification; do
    python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 \
        --implementation cp --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 \
        --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
        --platform manylinux1_x86_64 -d .whl "$pkg"
done
# VIEWER=1: Playwright for Python too (nvidia-viewer-bench.sh), into .whl/viewer/ (~45 MB)
if [ "${VIEWER:-0}" = 1 ]; then
    mkdir -p .whl/viewer
    for pkg in playwright==1.65.3 greenlet pyee typing-extensions; do
        python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 \
            --implementation cp --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 \
            --platform manylinux2014_x86_64 --platform manylinux1_x86_64 --platform any \
            -d .whl/viewer "$pkg"
    done
fi
ls -l .gl .whl
