#!/usr/bin/env bash
# Regenerates the gallery (assets/gallery/*.png): runs a small room, the corridor, a 192 m map
# world, the maze and a crowd, and renders each recording as a new user first sees it, with
# the Rerun viewer headless (`rerun FILE --headless --screenshot-to`). Needs the viewer that matches the
# SDK (`pip install rerun-sdk==0.36.3`) and a Vulkan driver (a software one, Debian's
# `mesa-vulkan-drivers`, is enough). Pillow, when installed, halves the screenshots' HiDPI size.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=assets/gallery
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for world in room-two-dividers corridor-obstruction map-arena-200 map-maze crowds/circle-16; do
    name=$(basename "$world")
    echo "gallery: $world"
    # A world whose expectations fail still writes its recording (exit 1): it is shown as it is.
    cargo run --release --locked --quiet -- run "worlds/$world.toml" -o "$tmp/$name.rrd" \
        > /dev/null || [ $? -eq 1 ]
    RUST_LOG=error rerun "$tmp/$name.rrd" --headless --window-size 1400x800 \
        --screenshot-to "$out/$name.png" > /dev/null 2>&1
    python3 - "$out/$name.png" <<'PY' || true
import sys
from PIL import Image
path = sys.argv[1]
image = Image.open(path)
if image.width > 1400:
    image.resize((image.width // 2, image.height // 2), Image.LANCZOS).save(path, optimize=True)
PY
done
ls -l "$out"/*.png
