#!/usr/bin/env bash
# Builds and installs boxplus into the venv (`make install`), showing the
# build's progress: the C++ extension takes minutes on two cores, and a silent
# `pip install -q` looks hung. The full pip/CMake output goes to
# build/install.log; on failure its end is printed.
set -uo pipefail
cd "$(dirname "$0")/.."
PY=${PY:-.venv/bin/python}
LOG=build/install.log
mkdir -p build
echo "install: building the C++ extension and installing boxplus (log: $LOG)"
set -o pipefail
"$PY" -m pip install -v --disable-pip-version-check --no-build-isolation --no-deps . 2>&1 |
  tee "$LOG" |
  while IFS= read -r line; do
    # Ninja's lines "[k/n] Building CXX object …": one progress line a step
    if [[ $line =~ \[([0-9]+)/([0-9]+)\]\ (Building|Linking)\ CXX\ [a-z]+\ (.*) ]]; then
      printf 'install: [%s/%s] %s\n' "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" \
        "$(basename "${BASH_REMATCH[4]}" | sed 's/\.o$//')"
    fi
  done
status=${PIPESTATUS[0]}
if [ "$status" -ne 0 ]; then
  echo "install: FAILED (pip exit $status); the end of $LOG:" >&2
  tail -n 60 "$LOG" >&2
  exit "$status"
fi
echo "install: boxplus $("$PY" -c 'import boxplus; print(boxplus.__version__)') installed"
