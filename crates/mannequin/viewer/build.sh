#!/usr/bin/env bash
# Rebuilds dist/viewer.js, the bundle `mannequin view` embeds, from src/ and the pinned packages
# (package-lock.json), and collects their licences into dist/LICENSES.txt. Needs Node and npm;
# users of the binary need neither. Run it after changing src/ and commit dist/.
set -euo pipefail
cd "$(dirname "$0")"
npm ci --silent --no-audit --no-fund
npx esbuild src/main.js --bundle --format=esm --minify --target=es2022 \
  --legal-comments=none --outfile=dist/viewer.js
{
  echo "dist/viewer.js bundles src/ (Mannequin) with these packages, unmodified:"
  for package in three; do
    dir="node_modules/$package"
    version="$(node -p "require('./$dir/package.json').version")"
    echo
    echo "=== $package $version ==="
    cat "$dir/LICENSE"*
  done
} >dist/LICENSES.txt
ls -l dist/
