#!/bin/sh
# Renders a scene written by `visgate export mitsuba` with Mitsuba 3, one EXR per sensor:
#   bench/mitsuba.sh DIR/scene.xml OUT_DIR [SEED]
# Sets Mitsuba up in a virtual environment on first use (bench/.venv; `pip install mitsuba`).
# Its LLVM variant is used when Dr.Jit finds an LLVM it can run: on Debian 12, install
# `libllvm19` and the script points DRJIT_LIBLLVM_PATH at it (Mesa's LLVM 15 would be loaded
# otherwise and abort at the first kernel); without it, the scalar variant renders (slower).
# Optional: not part of the tests or CI.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
venv=${VISGATE_MITSUBA_VENV:-$here/.venv}
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet mitsuba
fi
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
    for f in /usr/lib/llvm-19/lib/libLLVM.so.1 /usr/lib/x86_64-linux-gnu/libLLVM-19.so.1 /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1; do
        if [ -e "$f" ]; then export DRJIT_LIBLLVM_PATH="$f"; break; fi
    done
fi
exec "$venv/bin/python" "$here/render_mitsuba.py" "$@"
