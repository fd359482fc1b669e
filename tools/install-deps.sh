#!/usr/bin/env bash
# Installs what lensfield needs to build and test, from Debian 12's packages.
# Every dependency is listed here and nowhere else, so a fresh machine (and CI)
# gets exactly what the build uses.
set -euo pipefail
PACKAGES=(
  build-essential cmake ninja-build pkg-config zlib1g-dev
  libembree-dev libopenexr-dev libimath-dev libopenimageio-dev openimageio-tools
  clang libclang-rt-14-dev
  chromium nodejs
  slurm-wlm munge
)
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
