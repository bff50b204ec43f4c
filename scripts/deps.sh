#!/usr/bin/env bash
# Installs the Debian packages lamina's build, tests and reports need, when missing.
# Idempotent and quick when everything is present; non-interactive.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libfmt-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  librandom123-dev libpcg-cpp-dev libomp-dev libpng-dev libopenexr-dev
  libhwy-dev                                 # the SIMD kernel (Google Highway)
  libcerf-dev                                # Faddeeva's function: Gaussian integrals (models)
  libopenmpi-dev openmpi-bin                 # mpirun -n K lamina simulate|study (docs/scaling.md)
  python3 python3-numpy python3-matplotlib   # lamina figures (scripts/figures.py)
  python3-dev pybind11-dev python3-pybind11  # the Python module `import lamina` (docs/python.md)
  python3-pytest zlib1g-dev                  # its tests; .npz exports (docs/formats.md)
  python3-mypy                               # the Python stubs' type check (tests/python)
  chromium fonts-dejavu-core                 # the explorer's browser test (tests/report)
)

# One dpkg-query for all of them (one per package took over a second on every `make demo`).
installed=$(dpkg-query -W -f='${Package} ${Status}\n' "${packages[@]}" 2>/dev/null |
  awk '$2 == "install" && $3 == "ok" && $4 == "installed" {print $1}' || true)
missing=()
for p in "${packages[@]}"; do
  if ! grep -qx -- "$p" <<<"$installed"; then
    missing+=("$p")
  fi
done

# Node.js and npm: Debian's packages, unless a node with npm is already on the PATH (another
# distribution of Node, e.g. one that bundles npm, would conflict with Debian's npm package).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi

if [ ${#missing[@]} -gt 0 ]; then
  echo "lamina: installing missing packages: ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The npm packages of package.json (Plotly for the explorer page, playwright-core for its browser
# test), pinned by package-lock.json, into ./node_modules. Never a browser download: the test drives
# Debian's chromium.
cd "$(dirname "$0")/.."
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  echo "lamina: installing npm packages (npm ci)" >&2
  PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error
fi
