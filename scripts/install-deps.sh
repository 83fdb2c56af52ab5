#!/usr/bin/env bash
# Installs every Debian package auvrl needs, if missing. Idempotent; silent when all is there.
set -euo pipefail

packages=(
  # build
  build-essential cmake pkg-config
  # libraries
  libeigen3-dev libyaml-cpp-dev liblcm-dev libglib2.0-dev cyclonedds-dev
  libcli11-dev libfmt-dev zlib1g-dev
  # tests and benchmarks; the fuzz build (clang, libFuzzer)
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # LCM tools, Java bindings for lcm-spy, DDS tools
  liblcm-bin liblcm-java libjchart2d-java default-jdk-headless cyclonedds-tools
  # network namespaces (unshare, nsenter, ip), packet loss inside them (nft), process tools;
  # delay and jitter inside them where the kernel has no netem (auv_netdelay: NFQUEUE)
  util-linux iproute2 nftables procps iptables libnetfilter-queue-dev
  # plots
  python3 python3-matplotlib python3-numpy
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo=(sudo)
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
