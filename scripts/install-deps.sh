#!/usr/bin/env bash
# Installs every Debian package cheval's build, tests and benchmarks need. Safe to run twice: it
# only calls apt when a package is missing.
set -euo pipefail

packages=(
  cmake make g++ pkg-config python3
  libeigen3-dev libceres-dev libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  pybind11-dev python3-dev python3-numpy
  libsqlite3-dev libzstd-dev liblz4-dev libbz2-dev libyaml-cpp-dev  # recordings (src/bag)
  chromium chromium-driver  # the browser test of `cheval report` (tests/report/browser_test.js)
  python3-matplotlib  # cheval.plot, figures for papers (python/cheval/plot.py)
  zlib1g-dev  # deflated members of result zips (src/common/zip.cc, cheval res)
)

# The report's chart library comes from the npm registry at build time: the machine's Node.js and npm
# are used when present; otherwise Debian's.
if ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
