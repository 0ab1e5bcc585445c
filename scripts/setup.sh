#!/usr/bin/env bash
# Prepare a fresh Debian/Ubuntu machine to build and test inksim.
#
# Expects the Rust toolchain (cargo), a C compiler and python3 to be present.
# Installs what is missing for the HDF5 bindings: the HDF5 C library, its
# high-level library (libhdf5_hl, for dimension scales) and headers come from
# the distribution's packages (Debian/Ubuntu `libhdf5-dev`, which has both),
# found by the build through `pkg-config`; no HDF5 is built from source and
# no cmake is needed. With --with-browser it also installs Chromium (Debian
# package `chromium`), which the test of the study's summary page renders it
# in (without it that test skips). Safe to run repeatedly: it installs
# nothing that is already there.
set -euo pipefail

with_browser=0
for arg in "$@"; do
    case "$arg" in
        --with-browser) with_browser=1 ;;
        *) printf '[setup] error: unknown argument %s (known: --with-browser)\n' "$arg" >&2; exit 2 ;;
    esac
done

say() { printf '[setup] %s\n' "$*"; }

missing=()
for tool in cargo cc python3; do
    command -v "$tool" >/dev/null 2>&1 || missing+=("$tool")
done
if ((${#missing[@]})); then
    say "warning: not found: ${missing[*]} (install the Rust toolchain from https://rustup.rs and gcc/python3 from apt)"
fi

packages=()
if ! command -v pkg-config >/dev/null 2>&1; then
    packages+=(pkg-config)
    say "pkg-config is missing"
fi
if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists hdf5; then
    packages+=(libhdf5-dev)
    say "HDF5 development files (pkg-config module hdf5) are missing"
fi

if command -v pkg-config >/dev/null 2>&1 && pkg-config --exists hdf5; then
    say "HDF5 $(pkg-config --modversion hdf5) found via pkg-config"
fi
if ((with_browser)); then
    if command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; then
        say "Chromium found"
    else
        packages+=(chromium)
        say "Chromium is missing"
    fi
fi

if ((${#packages[@]} == 0)); then
    say "nothing to install"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    say "error: apt-get not found; install ${packages[*]} (HDF5 >= 1.10 with headers and a pkg-config file) with your package manager" >&2
    exit 1
fi

sudo=()
if [[ $(id -u) -ne 0 ]]; then
    if command -v sudo >/dev/null 2>&1; then
        sudo=(sudo)
    else
        say "error: not root and sudo is missing; run as root: apt-get install ${packages[*]}" >&2
        exit 1
    fi
fi

# Passed through `env` because sudo drops the caller's environment.
apt=("${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get)
say "running: ${apt[*]} update"
"${apt[@]}" update
say "running: ${apt[*]} install -y --no-install-recommends ${packages[*]}"
"${apt[@]}" install -y --no-install-recommends "${packages[@]}"

if ((with_browser)) && ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1; then
    say "error: chromium installed but not on PATH" >&2
    exit 1
fi
if pkg-config --exists hdf5; then
    say "HDF5 $(pkg-config --modversion hdf5) installed"
else
    say "error: libhdf5-dev installed but pkg-config still does not find module hdf5" >&2
    exit 1
fi
