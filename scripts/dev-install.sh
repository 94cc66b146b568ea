#!/usr/bin/env bash
# Builds and installs the package from this checkout (incremental: the CMake
# build tree lives in build/). A lock keeps concurrent builds from colliding.
set -euo pipefail
export PIP_ROOT_USER_ACTION=ignore
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
exec 9>"${TMPDIR:-/tmp}/principled-brdf-build.lock"
flock 9
"$python" -m pip install -q --disable-pip-version-check --no-build-isolation --no-deps ".[test,plot]"
"$python" -c "import principled_brdf" >/dev/null
