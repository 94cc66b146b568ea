# shellcheck shell=bash
# Sourced (not run) by scripts/build-wheel.sh and scripts/dev-install.sh, right
# after their `set -euo pipefail` (which stays in each script, so that a missing
# or failing _common.sh stops it too): pip's root warning off, the working
# directory set to the repository root, $python (the PYTHON to build for,
# default python3), and the build lock taken (held on fd 9 until the script
# exits), so that concurrent builds in build/ wait for each other.
export PIP_ROOT_USER_ACTION=ignore
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit
# shellcheck disable=SC2034  # used by the scripts that source this file
python=${PYTHON:-python3}
exec 9>"${TMPDIR:-/tmp}/principled-brdf-build.lock"
flock 9
