#!/usr/bin/env bash
# Installs what lensfield needs to build and test, from Debian 12's packages.
# Every dependency is listed here and nowhere else, so a fresh machine (and CI)
# gets exactly what the build uses.
set -euo pipefail
PACKAGES=(
  build-essential cmake ninja-build pkg-config zlib1g-dev
  libembree-dev libopenexr-dev libimath-dev libopenimageio-dev openimageio-tools libpng-dev
  libcairo2-dev fonts-dejavu-core
  libnanovdb-dev libblosc-dev libraw-bin
  clang libclang-rt-14-dev
  python3-numpy python3-pytest python3-venv python3-setuptools python3-wheel python3-pip
  chromium nodejs
  slurm-wlm munge
)
# The benchmarks against Blender Cycles (bench/peers/) also need Blender;
# not a build or test dependency, so only with LF_BENCH_DEPS=1.
if [ "${LF_BENCH_DEPS:-0}" = 1 ]; then PACKAGES+=(blender); fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
fi
