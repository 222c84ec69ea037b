#!/usr/bin/env bash
# Browser tests of the live preview (`cga serve`, web/) and of the 3D
# Tiles viewer (web/src/tiles.html on tilesets `cga generate` writes): the
# pages built from npm packages, driven by Playwright (playwright-core) in
# Debian's Chromium. Playwright's own browser download is not used (and would not
# work on CI machines without outside network).
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -x /usr/bin/chromium ]; then
    # CI runs as root.
    apt-get update -qq
    apt-get install -y -qq chromium
fi
npm ci --prefix web --no-audit --no-fund
npm run build --prefix web
cargo build -p cga-cli
target="${CARGO_TARGET_DIR:-target}"
case "$target" in /*) ;; *) target="$PWD/$target" ;; esac
CGA_BIN="$target/debug/cga" npm test --prefix web
