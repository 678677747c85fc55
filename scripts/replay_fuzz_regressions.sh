#!/usr/bin/env bash
# Runs every input of tests/data/fuzz_regressions through a sanitizer build of
# boxplus-g2o (`make sanitize-ci`): each must end with the tool's own exit code
# (0 solved, 1 the solver failed, 2 bad input), never with a sanitizer's report.
set -uo pipefail
cd "$(dirname "$0")/.."
tool=${1:?usage: replay_fuzz_regressions.sh path/to/boxplus-g2o}
export ASAN_OPTIONS=detect_leaks=0:exitcode=86:abort_on_error=0
export UBSAN_OPTIONS=halt_on_error=1:exitcode=86:print_stacktrace=1
export OPENBLAS_NUM_THREADS=1
failed=0
n=0
for f in tests/data/fuzz_regressions/*.g2o; do
  n=$((n + 1))
  out=$("$tool" -q -i 5 -t 1 "$f" 2>&1 >/dev/null)
  code=$?
  if [ "$code" -gt 2 ] || grep -q "Sanitizer" <<<"$out"; then
    echo "replay_fuzz_regressions: $f: exit $code" >&2
    echo "$out" | tail -n 30 >&2
    failed=1
  fi
done
echo "replay_fuzz_regressions: $n inputs, $([ $failed -eq 0 ] && echo 'no sanitizer report' || echo FAILED)"
exit $failed
