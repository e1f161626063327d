#!/usr/bin/env bash
# Every test: TypeScript types, vitest unit tests, pytest training tests, browser end-to-end tests.
# Runs them all even when one fails, then exits non-zero if any failed.
set -uo pipefail
cd "$(dirname "$0")/.."
passed=0; failed=0; failures=()
run() {
  local name=$1; shift
  echo; echo "==> $name: $*"
  if "$@"; then passed=$((passed + 1)); else failed=$((failed + 1)); failures+=("$name"); fi
}
run typecheck npx tsc --noEmit
run unit npx vitest run
run python bash -c 'bash scripts/ensure-venv.sh && .venv/bin/python -m pytest -q tests/python'
run e2e npm run --silent test:e2e
echo
[ "$failed" -eq 0 ] || echo "failed suites: ${failures[*]}"
echo "suites: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
