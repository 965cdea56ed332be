#!/usr/bin/env bash
# Installs ParcelScope's build and test dependencies from Debian 12 packages.
# Idempotent: packages already present are left as they are; apt lists are
# refreshed only when a package is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libvtk9-dev libvtk9-qt-dev qtbase5-dev libqt5opengl5-dev libfreetype-dev
  libopenmpi-dev openmpi-bin
  libgoogle-perftools-dev
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libgeographiclib-dev
  libgdal-dev gdal-bin libsqlite3-dev libssl-dev zlib1g-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  libx11-dev xvfb xauth libgl1-mesa-dri
  clang-format
)

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

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
