#!/usr/bin/env bash
# The readers' worst cases (bench/bench_readers.cpp) before and after issue 16, item 12, in one
# run: the same benchmark source is built against lamina_core of an older commit (extracted with
# `git archive`, only lamina_core built, with the compiler and flags of this tree's build) and
# against this tree's, then both run one after the other and the table puts them side by side.
#
# usage: bench/readers_old_vs_new.sh [BASE]      BASE: the old commit (default 97e9137)
# environment:
#   LAMINA_BUILD_DIR=build      this tree's configured build folder (bench_readers is built there)
#   WORKDIR=…                   scratch folder (default $TMPDIR/lamina-readers-old-vs-new): the old
#                               sources, their build, the two programs and their JSON
#   FILTER=…                    --benchmark_filter for both (default: all)
# The table goes to stdout, the rest to stderr. The old core takes about a minute for its slow
# cases (17 s for one 100,000-corner OBJ face), plus the few minutes it takes to build.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
base=${1:-97e9137}
build=${LAMINA_BUILD_DIR:-$root/build}
work=${WORKDIR:-${TMPDIR:-/tmp}/lamina-readers-old-vs-new}
filter=${FILTER:-.}
mkdir -p "$work"

if [[ ! -f "$work/old-$base/core/CMakeLists.txt" ]]; then
  rm -rf "$work/old-$base"
  mkdir -p "$work/old-$base"
  git -C "$root" archive "$base" | tar -x -C "$work/old-$base"
fi
cmake -S "$work/old-$base" -B "$work/old-build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBUILD_TESTING=OFF \
  -DLAMINA_BUILD_BENCH=OFF >/dev/null
cmake --build "$work/old-build" --target lamina_core -j "$(nproc)" >&2
cmake --build "$build" --target bench_readers -j "$(nproc)" >&2

# The old program: this tree's benchmark source, the old core's headers and library.
"${CXX:-g++}" -std=c++23 -O2 -DNDEBUG -I"$work/old-$base/core/include" -I"$work/old-$base/core/src" \
  -I"$root/tests/core/io" -I/usr/include/eigen3 "$root/bench/bench_readers.cpp" \
  "$work/old-build/core/liblamina_core.a" -lbenchmark -lpthread -lfmt -lpolyclipping -ltbb -lz -o "$work/bench_readers_old"

for side in old new; do
  program="$work/bench_readers_old"
  [[ $side == new ]] && program="$build/bench/bench_readers"
  echo "running the $side readers ($program)" >&2
  "$program" --benchmark_filter="$filter" --benchmark_min_time=0.2 --benchmark_format=json >"$work/$side.json"
done

python3 - "$work/old.json" "$work/new.json" "$base" <<'PY'
import json, sys
old = {b["name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"]}
new = json.load(open(sys.argv[2]))["benchmarks"]
print(f"| case | old ({sys.argv[3]}) | new | old / new |")
print("|---|---:|---:|---:|")
for b in new:
    o = old.get(b["name"])
    t_new = b["real_time"]
    t_old = o["real_time"] if o else float("nan")
    print(f"| {b['name'].replace('/real_time', '')} | {t_old:.3f} ms | {t_new:.3f} ms | {t_old / t_new:.0f}× |")
PY
