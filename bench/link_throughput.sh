#!/usr/bin/env bash
# Machine-link benchmark (issue 6), against lamina-sim at an emulated 115200 baud:
#  1. throughput: a 20,000-line 5-axis program streamed by character counting to a machine
#     running 50× real time (the link is the bottleneck): link utilisation from `lamina stream`;
#  2. starvation: 0.2 mm segments at 3000 mm/min in real time (4 ms per block): the simulator's
#     starvation count must stay 0;
#  3. real-time latency: request → bytes handed to the port, from the stream summary.
# Usage: bench/link_throughput.sh [BUILD_DIR]   (default build/)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
sim=$build/simulators/lamina-sim
lamina=$build/daemon/lamina
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT

program() {  # program LINES STEP_MM FEED_MM_PER_MIN
  awk -v n="$1" -v step="$2" -v f="$3" 'BEGIN {
    print "G21G90G94"; print "(CONTOUR 0 L1-1 OUTLINE 0 PASS 0 FREES)"; print "G0X300Y300Z10A0C0"; print "Z0"; print "M3";
    x = 300; y = 300;
    for (i = 1; i <= n; i++) {
      x += step * cos(i * 0.002); y += step * sin(i * 0.002);
      if (i % 4 == 0) printf "G93G1X%.3fY%.3fA%.3fC%.3fF%.0f\nG94\n", x, y, 10 * sin(i * 0.001), 0.05 * i, f / step;
      else if (i % 4 == 1) printf "G1X%.3fY%.3fF%.0f\n", x, y, f;
      else printf "X%.3fY%.3f\n", x, y;
    }
    print "M5"; print "G0Z10"; print "M30";
  }'
}

run() {  # run NAME PROGRAM TIME_SCALE
  local link=$work/cnc-$1
  "$sim" --link "$link" --log "$work/$1.jsonl" --control 127.0.0.1:0 --time-scale "$3" > "$work/$1.ready" &
  for _ in $(seq 50); do [[ -s $work/$1.ready ]] && break; sleep 0.1; done
  local control; control=$(sed -n 's/.*"control_port":\([0-9]*\).*/\1/p' "$work/$1.ready")
  "$lamina" stream "$2" --port "$link" --protocol grbl --json > "$work/$1.json" 2> "$work/$1.err" || true
  local status; status=$(exec 3<>/dev/tcp/127.0.0.1/"$control"; echo status >&3; head -1 <&3)
  kill %% 2>/dev/null || true
  wait 2>/dev/null || true
  echo "== $1: $(wc -l < "$2") lines, $(wc -c < "$2") bytes"
  echo "   stream: $(cat "$work/$1.json")"
  grep -v "\[info\]" "$work/$1.err" | head -5 || true
  echo "   sim:    $(echo "$status" | grep -o '"starvation":[0-9]*'), $(echo "$status" | grep -o '"executed_blocks":[0-9]*')"
}

program 16000 0.5 6000 > "$work/throughput.nc"
program 4000 0.2 3000 > "$work/starvation.nc"
run throughput "$work/throughput.nc" 50
run starvation "$work/starvation.nc" 1
