#!/usr/bin/env bash
# Rebuilds three.bundle.min.js from three.js on the npm registry (README.md here says when).
# Usage: cli/assets/three/build.sh [VERSION]   (default: the version in VERSION)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
version="${1:-$(cat "$here/VERSION")}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
npm init -y >/dev/null
npm install --no-audit --no-fund "three@$version" esbuild@0.28.2 >/dev/null
cp "$here/entry.js" .
npx esbuild entry.js --bundle --minify --format=iife --global-name=THREE \
  --legal-comments=none --target=es2020 \
  --banner:js="/* three.js $version (npm three@$version) with OrbitControls: MIT License, Copyright 2010-2026 Three.js Authors (LICENSE beside this file). Bundled by cli/assets/three/build.sh. */" --outfile="$here/three.bundle.min.js"
cp node_modules/three/LICENSE "$here/LICENSE"
echo "$version" > "$here/VERSION"
ls -l "$here/three.bundle.min.js"
