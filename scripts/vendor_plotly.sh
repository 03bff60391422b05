#!/usr/bin/env bash
# Re-vendors plotly.js's gl3d bundle (the 3-D animation in reports) from the npm registry:
# the pinned version, checked against its SHA-256, copied with its licence into
# src/jointlock/data/.  Run by hand when upgrading (change both pins); the package ships the
# committed copy, so neither installing jointlock nor its tests need npm or a network.
set -euo pipefail
VERSION=4.1.1
SHA256=aab04dcd9c103a92b18723f8c837712fe820f325d0bcd2421e415e8124a75b9f
here="$(cd "$(dirname "$0")/.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && npm pack --silent "plotly.js-gl3d-dist-min@${VERSION}" >/dev/null && tar xzf ./*.tgz)
echo "${SHA256}  $tmp/package/plotly-gl3d.min.js" | sha256sum -c -
cp "$tmp/package/plotly-gl3d.min.js" "$here/src/jointlock/data/plotly-gl3d.min.js"
cp "$tmp/package/LICENSE" "$here/src/jointlock/data/plotly-gl3d.LICENSE"
echo "vendored plotly.js-gl3d-dist-min ${VERSION}"
