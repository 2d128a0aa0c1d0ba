#!/bin/bash
# Usage: scripts/serve_passes.sh SCENE (from the repository root, after cargo build --release).
# Starts `smoothtrace serve SCENE` on a free port and prints the server's timing
# (X-Render-Stats) of the 1/8, 1/4, 1/2 and full-resolution passes of the starting view.
set -euo pipefail
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
S=$1; B=${BIN:-target/release/smoothtrace}
$B serve "$S" --port 0 > "$T/out.txt" 2>/dev/null & PID=$!
for _ in $(seq 100); do grep -q http "$T/out.txt" && break; sleep 0.1; done
U=$(grep -o 'http://[^ ]*' "$T/out.txt")
for s in 8 4 2 1; do
  curl -s ${U}api/scene | python3 -c "import json,sys; v=json.load(sys.stdin)['view']; v['scale']=$s; print(json.dumps(v))" > "$T/view.json"
  curl -s -D - -o /dev/null -X POST --data @"$T/view.json" ${U}api/render | grep X-Render-Stats
done
kill -INT $PID; wait $PID
