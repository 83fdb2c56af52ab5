#!/usr/bin/env bash
# Installs every Debian package auvrl needs, if missing, then onnxruntime-node (the ONNX
# runtime of the export tests, from the npm registry, into third_party/node: git-ignored).
# Idempotent; silent when all is there.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

packages=(
  # build
  build-essential cmake pkg-config
  # libraries
  libeigen3-dev libyaml-cpp-dev liblcm-dev libglib2.0-dev cyclonedds-dev
  libcli11-dev libfmt-dev zlib1g-dev libssl-dev
  # signatures made or checked by hand (docs/deployment.md)
  openssl
  # tests and benchmarks; the fuzz build (clang, libFuzzer)
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # LCM tools, Java bindings for lcm-spy, DDS tools
  liblcm-bin liblcm-java libjchart2d-java default-jdk-headless cyclonedds-tools
  # network namespaces (unshare, nsenter, ip), packet loss inside them (nft), process tools;
  # delay and jitter inside them where the kernel has no netem (auv_netdelay: NFQUEUE)
  util-linux iproute2 nftables procps iptables libnetfilter-queue-dev
  # plots
  python3 python3-matplotlib python3-numpy
  # auvrl export --format onnx (scripts/export_onnx.py); node for the export tests' ONNX
  # runtime (scripts/install-onnxruntime-node.sh; npm below)
  python3-onnx nodejs
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$p")
done
# npm: Debian's package, unless the installed nodejs brings its own (NodeSource's does).
command -v npm >/dev/null || missing+=(npm)
# The npm registry may be out of reach where apt's mirror is not: the ONNX export test then
# shows as skipped, and nothing else needs the module.
ort_node() {
  "$here/install-onnxruntime-node.sh" ||
    echo "install-deps: onnxruntime-node not installed: the ONNX export test will be skipped" >&2
}
if [ ${#missing[@]} -eq 0 ]; then ort_node; exit 0; fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo=(sudo)
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
ort_node
