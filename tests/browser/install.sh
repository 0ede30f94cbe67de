#!/usr/bin/env bash
# Installs the browser test's driver, puppeteer-core at the version pinned in package.json
# and package-lock.json, into tests/browser/node_modules (npm ci: exactly the lock file);
# nothing when that version is there. puppeteer-core downloads no browser: the test drives
# Debian's chromium (.ci/install-deps --browser). Called by tests/all.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
command -v node >/dev/null && command -v npm >/dev/null ||
  { echo "tests/browser/install.sh: node and npm are needed (.ci/install-deps --browser)" >&2; exit 1; }
want=$(node -p "require('$here/package.json').dependencies['puppeteer-core']")
have=$(node -p "require('$here/node_modules/puppeteer-core/package.json').version" 2>/dev/null || true)
[[ $have == "$want" ]] && exit 0
echo "tests/browser/install.sh: installing puppeteer-core $want" >&2
cd "$here"
npm ci --no-audit --no-fund --loglevel=error
