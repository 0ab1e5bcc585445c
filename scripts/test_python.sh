#!/usr/bin/env bash
# Test the Python package (python/) against the real CLI.
#
# Creates (or reuses) the virtual environment .venv in the repository root
# (ignored by git), installs the package as a user would (`pip install
# ./python`) with pytest and Mitsuba 3 (which loads the exported BSDF in
# python/tests/test_mitsuba.py), and runs its tests with INKSIM_BIN pointing at
# target/release/inksim (built here with `cargo build --release` if missing;
# set INKSIM_BIN yourself to test another binary). Extra arguments go to
# pytest, e.g. `bash scripts/test_python.sh -k study`.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

say() { printf '[test_python] %s\n' "$*"; }

python=${PYTHON:-python3}
if ! command -v "$python" >/dev/null 2>&1; then
    say "error: $python not found (install python3 >= 3.9)" >&2
    exit 1
fi

if [[ ! -x .venv/bin/python ]]; then
    say "creating .venv with $($python --version 2>&1)"
    if ! "$python" -m venv .venv; then
        rm -rf .venv
        # Debian/Ubuntu ship venv separately.
        if command -v apt-get >/dev/null 2>&1 && [[ $(id -u) -eq 0 ]]; then
            say "venv failed; installing python3-venv"
            DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3-venv \
                || { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3-venv; }
            "$python" -m venv .venv
        else
            say "error: '$python -m venv' failed; install python3-venv (Debian/Ubuntu) and retry" >&2
            exit 1
        fi
    fi
fi

say "installing ./python, pytest and mitsuba (the BSDF export's check) into .venv"
.venv/bin/python -m pip install --quiet --disable-pip-version-check ./python pytest "mitsuba>=3.5"

if [[ -z ${INKSIM_BIN:-} ]]; then
    INKSIM_BIN=$PWD/target/release/inksim
    if [[ ! -x $INKSIM_BIN ]]; then
        say "no $INKSIM_BIN yet; building it (cargo build --release)"
        cargo build --release
    fi
fi
export INKSIM_BIN
say "INKSIM_BIN=$INKSIM_BIN"
export MPLBACKEND=Agg

.venv/bin/python -m pytest python/tests -q -p no:cacheprovider "$@"
