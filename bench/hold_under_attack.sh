#!/usr/bin/env bash
# The operator's hold under attack (issue 16, item 8): while a job cuts on lamina-sim, 100 TCP
# peers without a token each send a MiB of '[' over and over and 128 idle connections sit on the
# Unix socket; an operator connects and holds/resumes 100 times. Prints the hold's latency
# percentiles. Usage: bench/hold_under_attack.sh [BUILD_DIR] [HOLDS] [STRANGERS] [IDLE]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
holds=${2:-100}
strangers=${3:-100}
idle=${4:-128}
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
port=$((20000 + $$ % 20000))
rig_tcp="127.0.0.1:$port"
source "$root/bench/cell_rig.sh"
echo "attack: $("$build/bench/daemon_attack" "$LAMINA_SOCKET" "$port" "$holds" "$strangers" "$idle")"
"$lamina" cancel "$id" > /dev/null || true
