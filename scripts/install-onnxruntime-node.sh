#!/usr/bin/env bash
# Installs onnxruntime-node, the ONNX runtime the export tests run the exported models with
# (independent of python3-onnx, which writes them), into third_party/node/node_modules
# (git-ignored). Idempotent; silent when the pinned version is there.
#   scripts/install-onnxruntime-node.sh
#
# --ignore-scripts: the package's postinstall script only fetches the CUDA execution
# provider's binaries from a NuGet feed; the CPU binding (prebuilt N-API binaries for linux x64
# and arm64) is in the npm package itself.
set -euo pipefail
version=1.30.0
root=$(cd "$(dirname "$0")/.." && pwd)
prefix=$root/third_party/node
package=$prefix/node_modules/onnxruntime-node/package.json

if [ -f "$package" ] && grep -q "\"version\": \"$version\"" "$package"; then exit 0; fi
command -v npm >/dev/null || { echo "install-onnxruntime-node: npm is missing (apt-get install npm)" >&2; exit 1; }
echo "install-onnxruntime-node: installing onnxruntime-node@$version into $prefix"
mkdir -p "$prefix"
[ -f "$prefix/package.json" ] || echo '{"private": true, "description": "auvrl test dependencies (scripts/install-onnxruntime-node.sh)"}' >"$prefix/package.json"
npm install --prefix "$prefix" --ignore-scripts --no-audit --no-fund --save-exact \
  "onnxruntime-node@$version" >/dev/null
# The CPU binding must load without the postinstall script's downloads.
node -e "const ort = require('$prefix/node_modules/onnxruntime-node'); \
  if (ort.env.versions.node !== '$version') process.exit(1);" ||
  { echo "install-onnxruntime-node: onnxruntime-node@$version does not load here" >&2; exit 1; }
