#!/usr/bin/env bash
# Builds and installs the package from this checkout (incremental: the CMake
# build tree lives in build/). A lock keeps concurrent builds from colliding.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=_common.sh
source "$(dirname "$0")/_common.sh"  # repo root, $python, the build lock
"$python" -m pip install -q --disable-pip-version-check --no-build-isolation --no-deps .
"$python" -c "import principled_brdf" >/dev/null
