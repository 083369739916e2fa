#!/usr/bin/env bash
# Stream every sheet of the demo knob (grblhal post, defaults) to lamina-sim at --time-scale 1,
# as a real grblHAL would run it (dwells Idle, answered after the dwell), and check that each
# completes and that the execution log equals the program line for line.
#   bench/stream_knob_sheets.sh [BUILD_DIR] [PROTOCOL] [STATUS_HZ]
# Defaults: build grbl 5. Takes the programs' own time (the knob: about 8 minutes); prints one
# line per sheet and exits non-zero when a sheet does not complete or its log differs.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
protocol=${2:-grbl}
hz=${3:-5}
lamina=$build/daemon/lamina
sim=$build/simulators/lamina-sim
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT

"$lamina" plan "$root/examples/knob.stl" --out "$work/plan" > "$work/plan.log" 2>&1
status=0
for nc in "$work"/plan/sheet-*.nc; do
  name=$(basename "$nc" .nc)
  "$sim" --link "$work/cnc" --log "$work/$name.jsonl" --time-scale 1 > "$work/sim.out" 2>&1 &
  sim_pid=$!
  for _ in $(seq 100); do [[ -e "$work/cnc" ]] && break; sleep 0.05; done
  start=$(date +%s.%N)
  summary=$("$lamina" stream "$nc" --port "$work/cnc" --protocol "$protocol" --status-hz "$hz" --json 2> "$work/$name.err" < /dev/null || true)
  took=$(echo "$(date +%s.%N) - $start" | bc)
  kill "$sim_pid"; wait "$sim_pid" 2>/dev/null || true
  rm -f "$work/cnc"
  # The program as the CLI streams it (blank lines dropped, CR stripped) against the log.
  same=$(python3 - "$nc" "$work/$name.jsonl" <<'EOF'
import json, sys
program = [l.rstrip('\r\n') for l in open(sys.argv[1]) if l.strip()]
log = [json.loads(l) for l in open(sys.argv[2]) if l.strip()]
ran = [r['line'] for r in log if 'seq' in r and 'event' not in r and r.get('completed', True)]
print('equal' if ran == program else f'differs: {len(ran)} of {len(program)} lines ran')
EOF
)
  state=$(python3 -c 'import json,sys; s=json.loads(sys.argv[1]); print(s["state"], s.get("reason",{}).get("message",""))' "$summary")
  printf '%s %s %sHz: %s, %s lines, log %s, %.1f s\n' "$name" "$protocol" "$hz" "$state" \
    "$(grep -c . "$nc")" "$same" "$took"
  [[ $state == completed* && $same == equal ]] || status=1
done
exit $status
