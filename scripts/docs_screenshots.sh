#!/usr/bin/env bash
# Every page of the built docs site (build/docs, `make docs`) rendered by a real
# headless browser into build/docs-shots/*.png, for a person to look at: what
# sphinx -W cannot see (cut code lines, pictures that do not show, a page that
# reads badly). Needs Debian's chromium (apt-get install -y chromium).
set -euo pipefail
cd "$(dirname "$0")/.."
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
    echo "docs-shots: no chromium; install it with: apt-get install -y chromium" >&2
    exit 1
fi
out=build/docs-shots
rm -rf "$out" && mkdir -p "$out"
n=0
while IFS= read -r page; do
    rel=${page#build/docs/}
    shot="$out/$(echo "${rel%.html}" | tr / _).png"
    timeout 60 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
        --window-size=1400,2400 --screenshot="$PWD/$shot" "file://$PWD/$page" >/dev/null 2>&1
    [ -s "$shot" ] || { echo "docs-shots: $page did not render" >&2; exit 1; }
    n=$((n + 1))
done < <(find build/docs -name '*.html' -not -path '*/_*' -not -name 'genindex.html' \
             -not -name 'search.html' -not -name 'py-modindex.html' | sort)
echo "docs-shots: $n pages in $out"
