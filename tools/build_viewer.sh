#!/bin/sh
# Rebuild src/jourdain/io/viewer/three_bundle.js: three.js and its OrbitControls (the exports of
# tools/viewer/entry.js) as one minified IIFE script defining the global JD3, from the versions
# pinned in tools/viewer/package-lock.json (npm ci), with three.js's MIT license in its header.
# Needs node and npm; the bundle is committed, so installing or testing jourdain needs neither.
# Usage: tools/build_viewer.sh   (or: make viewer-assets)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
out="$root/src/jourdain/io/viewer/three_bundle.js"
cd "$here/viewer"
npm ci --no-audit --no-fund --loglevel=error
version=$(node -p "JSON.parse(require('fs').readFileSync('node_modules/three/package.json')).version")
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
./node_modules/.bin/esbuild entry.js --bundle --format=iife --global-name=JD3 --minify \
  --legal-comments=none --target=es2020 --log-level=warning --outfile="$tmp"
{
  printf '/*! three.js %s (https://threejs.org), OrbitControls included; bundled for jourdain by\n' "$version"
  printf ' * tools/build_viewer.sh with esbuild. License of three.js:\n *\n'
  sed 's/^/ * /; s/ *$//' node_modules/three/LICENSE
  printf ' */\n'
  cat "$tmp"
} > "$out"
echo "wrote $out ($(wc -c < "$out") bytes, three.js $version)"
