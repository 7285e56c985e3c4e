#!/usr/bin/env bash
# The editor's front end (web/): TypeScript built with Vite from npm packages pinned in web/package-lock.json.
#   scripts/web.sh build   npm ci (when the lock file changed), type-check, build web/dist, copy it beside the
#                          lidarshop executable (build/release/web) so `lidarshop serve` finds it
#   scripts/web.sh test    lint (ESLint; Prettier's formatting), unit tests (Vitest), then end to end in Debian's chromium (playwright-core) against
#                          build/release/lidarshop (e2e/editor.mjs, a site's stations: e2e/stations.mjs, and a
#                          16 M-ray station within the browser's point budget, its bytes counted: e2e/station.mjs
#                          on a 4000 x 4000 grid, about 2 minutes); screenshots in build/e2e/
set -euo pipefail
cd "$(dirname "$0")/.."
command -v npm >/dev/null || { echo "web: npm is not installed (Node.js 20 from the machine's packages)"; exit 1; }
stamp=web/node_modules/.lock-installed
if [[ ! -f $stamp ]] || ! cmp -s web/package-lock.json "$stamp"; then
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
  cp web/package-lock.json "$stamp"
fi
case ${1:-build} in
  build)
    (cd web && npm run --silent build >/dev/null)
    rm -rf build/release/web
    mkdir -p build/release
    cp -r web/dist build/release/web
    echo "web: built web/dist -> build/release/web"
    ;;
  test)
    (cd web && npm run --silent lint)
    (cd web && npx vitest run)
    (cd web && node e2e/editor.mjs ../build/release/lidarshop ../build/e2e "${@:2}")
    (cd web && node e2e/stations.mjs ../build/release/lidarshop ../build/e2e "${@:2}")
    (cd web && node e2e/station.mjs ../build/release/lidarshop ../build/e2e/station16m --rows 4000 --columns 4000)
    ;;
  *)
    echo "usage: scripts/web.sh build|test [--docs]"
    exit 2
    ;;
esac
