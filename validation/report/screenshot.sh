#!/usr/bin/env bash
# Regenerates validation/report/screenshot.png, the picture of the report in
# the top-level README, from a report ci/main.sh wrote:
#   validation/report/screenshot.sh OUT/report [OUT.png]
# Headless Chromium draws the page's first 1280 x 1600 pixels; Pillow scales
# them to 640 wide and keeps 64 colours, so the committed PNG stays small.
set -euo pipefail
report="${1:?usage: validation/report/screenshot.sh REPORT_DIR [OUT.png]}"
here="$(cd "$(dirname "$0")" && pwd)"
out="${2:-$here/screenshot.png}"
page="$(cd "$report" && pwd)/index.html"
[ -f "$page" ] || { echo "$page: no report here (run ci/main.sh OUT first)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
/usr/bin/chromium --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --user-data-dir="$work/profile" --hide-scrollbars \
  --window-size=1280,1600 --screenshot="$work/full.png" "file://$page" >/dev/null 2>&1
/usr/bin/python3 - "$work/full.png" "$work/small.png" <<'PY'
import sys
from PIL import Image
im = Image.open(sys.argv[1]).convert("RGB")
im = im.resize((640, im.height * 640 // im.width), Image.LANCZOS)
im.quantize(colors=64, method=Image.Quantize.MEDIANCUT).save(sys.argv[2], optimize=True)
PY
mv "$work/small.png" "$out"
echo "wrote $out ($(stat -c %s "$out") bytes)"
