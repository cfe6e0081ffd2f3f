#!/usr/bin/env bash
# Installs every Debian package Tilth needs to build, test and run. Idempotent: when
# everything is present it only checks and returns.
set -euo pipefail

packages=(
  # build
  build-essential cmake ninja-build ccache pkg-config clang-format
  # framework and SDK
  libtbb-dev nlohmann-json3-dev libboost-dev libboost-filesystem-dev
  libopencv-dev libeigen3-dev
  # the tools' command lines
  libcli11-dev
  # cameras (GigE Vision) and the camera simulator used by the tests
  libaravis-dev aravis-tools libusb-1.0-0-dev iproute2
  # tilth doctor's test: packet loss caused in the simulated cameras' network
  nftables
  # machine outputs and their real peers in tests
  libmodbus-dev mbpoll python3-pymodbus python3-serial python3-serial-asyncio
  # recordings
  libzstd-dev liblz4-dev zlib1g-dev libdeflate-dev nodejs
  # running as a systemd service; the packages (cpack) and their test in a bare root
  libsystemd-dev systemd dpkg-dev file debootstrap
  # the live view's web server
  libcpp-httplib-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev graphviz
  # the fuzz targets: clang with libFuzzer and its sanitizer runtimes
  clang libclang-rt-14-dev
  # the CNN segmenter's training (tilth train-segmenter --model cnn) and its tests
  python3-torch python3-torchvision python3-onnx python3-pil
  # independent readers in tests
  python3-opencv python3-numpy
  # tilth ab tests: statistics recomputed independently, the report opened in a browser
  python3-scipy chromium
  # the fleet's job files: a real single-node Slurm cluster, the manifests read as YAML
  slurmctld slurmd slurm-client munge python3-yaml
  # the live view's test drives Chromium over its DevTools protocol
  python3-websocket
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# Node.js builds that bundle npm (NodeSource) conflict with Debian's npm package.
command -v npm >/dev/null 2>&1 || missing+=(npm)

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The npm packages of the tests, pinned by their package-lock.json: the independent MCAP
# reader (@mcap/core) and the Kubernetes API's schemas (kubernetes-models).
for tests in tests/mcap/js tests/ab/kubernetes; do
  path="$(dirname "$0")/../$tests"
  if [ ! -d "$path/node_modules" ]; then
    echo "setup: installing the npm packages of $tests"
    (cd "$path" && npm ci --no-audit --no-fund --silent)
  fi
done
