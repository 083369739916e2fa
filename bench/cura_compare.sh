#!/usr/bin/env bash
# Compare the slicing phase of Lamina with CuraEngine 4.13 (Debian `cura-engine`) on the same
# mesh in one run: a UV sphere of 1,000,000 triangles, radius 50 mm, on z = 0 … 100, sliced every
# 0.1 mm. Both programs cut the same 1000 planes, z = 0.05, 0.15, …, 99.95:
#   Cura:   first plane at layer_height_0 - layer_height/2 = 0.05, then every layer_height;
#   Lamina: --step 0.1 puts planes at H/2, 3H/2, ….
#
# usage: bench/cura_compare.sh [PATH/TO/lamina]
#   The lamina binary is optional: without it (or if it is not executable) the Lamina column
#   says "missing" and only CuraEngine runs.
# environment:
#   REPS=3            runs of each program; the table shows the fastest run and the median
#   WORKDIR=…         scratch folder (default: $TMPDIR/lamina-cura-compare), keeps the STL,
#                     the logs and the definitions extracted from the `cura` package
#   CURA_DEFS=DIR     folder holding fdmprinter.def.json and fdmextruder.def.json
#   CURA_THREADS=N    pass -mN to CuraEngine (default: its own choice, all cores)
#   CURA_WALLS=0      wall_line_count (0: nothing but slicing + layer parts + an empty export)
#   LAMINA_ARGS=…     extra arguments for `lamina slice` (e.g. --serial)
#   MAKE_SPHERE=…     a built make_sphere (default: the build tree's, else compiled here)
#   SEGMENTS=1000 RINGS=501 RADIUS=50   the sphere (triangles = 2*SEGMENTS*(RINGS-1))
#
# Where the Cura definitions come from: CuraEngine ships none. fdmprinter.def.json and
# fdmextruder.def.json are in Debian's `cura` package (the GUI, many Python/Qt dependencies),
# under /usr/share/cura/resources/definitions. If that folder is absent, this script fetches the
# package file with `apt-get download cura` (no root, nothing installed) and unpacks just those
# two files with dpkg-deb into $WORKDIR.
#
# What CuraEngine -v prints that we use (stderr):
#   loading 'FILE' took X seconds          STL parse + vertex welding + face adjacency
#   slice of mesh took X seconds           triangle ∩ planes → segments (serial)
#   slice make polygons took X seconds     segments → closed polygons (OpenMP over layers)
#   Progress: slice accomplished in Xs     the whole slicing stage (the two above + setup)
#   Layer count: N
#   Total time elapsed  X.XXs.
# (-v also prints every setting once as one long [WARNING] line; it is filtered out here.)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
lamina_bin=${1:-}
reps=${REPS:-3}
work=${WORKDIR:-${TMPDIR:-/tmp}/lamina-cura-compare}
segments=${SEGMENTS:-1000}
rings=${RINGS:-501}
radius=${RADIUS:-50}
mkdir -p "$work"
model="$work/sphere_${segments}x${rings}_r${radius}.stl"

die() { echo "cura_compare: $*" >&2; exit 1; }
command -v CuraEngine >/dev/null || die "CuraEngine not found (apt-get install cura-engine)"
[[ -x /usr/bin/time ]] || die "/usr/bin/time not found (apt-get install time): needed for peak RSS"

# ---- 1. the sphere ---------------------------------------------------------------------------
make_sphere=${MAKE_SPHERE:-}
if [[ -z "$make_sphere" ]]; then
  for cand in "${LAMINA_BUILD_DIR:-$root/build}/bench/make_sphere" "$root"/build*/bench/make_sphere; do
    if [[ -x "$cand" ]]; then make_sphere=$cand; break; fi
  done
fi
if [[ -z "$make_sphere" ]]; then
  make_sphere="$work/make_sphere"
  if [[ ! -x "$make_sphere" || "$root/bench/make_sphere.cpp" -nt "$make_sphere" ||
        "$root/tests/support/shapes.hpp" -nt "$make_sphere" ]]; then
    echo "== compiling make_sphere (header-only) into $work"
    g++ -std=c++23 -O2 -I"$root/tests/support" -I"$root/core/include" -I/usr/include/eigen3 \
      "$root/bench/make_sphere.cpp" -o "$make_sphere"
  fi
fi
if [[ ! -s "$model" ]]; then
  "$make_sphere" "$model" --segments "$segments" --rings "$rings" --radius "$radius"
fi
triangles=$(( 2 * segments * (rings - 1) ))

# ---- 2. Cura definitions ---------------------------------------------------------------------
defs=${CURA_DEFS:-}
if [[ -z "$defs" ]]; then
  if [[ -f /usr/share/cura/resources/definitions/fdmprinter.def.json ]]; then
    defs=/usr/share/cura/resources/definitions
  else
    defs="$work/cura-defs"
    if [[ ! -f "$defs/fdmprinter.def.json" ]]; then
      echo "== fetching the Cura definitions: apt-get download cura (nothing is installed)"
      mkdir -p "$work/deb" "$defs"
      (cd "$work/deb" && apt-get download cura >/dev/null 2>"$work/deb/apt.log") ||
        die "apt-get download cura failed (see $work/deb/apt.log; run apt-get update?)"
      debs=("$work"/deb/cura_*.deb)
      deb=${debs[-1]}
      dpkg-deb --fsys-tarfile "$deb" |
        tar -x -C "$work/deb" ./usr/share/cura/resources/definitions/fdmprinter.def.json \
                              ./usr/share/cura/resources/definitions/fdmextruder.def.json
      cp "$work"/deb/usr/share/cura/resources/definitions/fdm*.def.json "$defs/"
    fi
  fi
fi
[[ -f "$defs/fdmprinter.def.json" && -f "$defs/fdmextruder.def.json" ]] ||
  die "no fdmprinter.def.json + fdmextruder.def.json in $defs"

# CuraEngine does not evaluate the definitions' Python "value" formulas, only default_value,
# so derived settings (infill_line_distance, top_layers, …) must be given explicitly.
cura_settings=(
  -s layer_height=0.1 -s layer_height_0=0.1   # planes at 0.05 + 0.1 k
  -s infill_sparse_density=0 -s infill_line_distance=0
  -s top_layers=0 -s bottom_layers=0 -s wall_line_count="${CURA_WALLS:-0}"
  -s adhesion_type=none -s support_enable=false
  -s machine_width=300 -s machine_depth=300 -s machine_height=300
)
cura_cmd=(CuraEngine slice -v -p)
[[ -n "${CURA_THREADS:-}" ]] && cura_cmd+=("-m${CURA_THREADS}")
cura_cmd+=(-j "$defs/fdmprinter.def.json" "${cura_settings[@]}" -l "$model" -o "$work/cura.gcode")

# ---- 3. runs ---------------------------------------------------------------------------------
# Each run appends one line "key=value …" to $work/<prog>.runs.
num() { grep -oE "$1" "$2" | head -1 | grep -oE '[0-9]+(\.[0-9]+)?' | tail -1; }
rss_kb() { grep -E 'Maximum resident set size' "$1" | grep -oE '[0-9]+$'; }
wall_s() { # "Elapsed (wall clock) time (h:mm:ss or m:ss): 0:04.03"
  grep -E 'Elapsed \(wall clock\)' "$1" | awk -F': ' '{print $2}' |
    awk -F: '{ if (NF==3) print $1*3600+$2*60+$3; else print $1*60+$2 }'
}

run_cura() {
  local i=$1 log="$work/cura.$1.log" tv="$work/cura.$1.time"
  /usr/bin/time -v -o "$tv" "${cura_cmd[@]}" >"$work/cura.$i.stdout" 2>"$log" ||
    die "CuraEngine failed (run $i): see $log"
  grep -vE '^\[WARNING\]  -s |^ -s ' "$log" >"$log.short" || true
  echo "load=$(num "loading '.*' took [0-9.]+" "$log") \
slice_mesh=$(num 'slice of mesh took [0-9.]+' "$log") \
make_polygons=$(num 'slice make polygons took [0-9.]+' "$log") \
slice_stage=$(num 'Progress: slice accomplished in [0-9.]+' "$log") \
layers=$(num 'Layer count: [0-9]+' "$log") \
total=$(num 'Total time elapsed +[0-9.]+' "$log") \
wall=$(wall_s "$tv") rss_kb=$(rss_kb "$tv")" >>"$work/cura.runs"
}

lamina_ok=0
if [[ -n "$lamina_bin" && -x "$lamina_bin" ]]; then
  lamina_ok=1
elif [[ -n "$lamina_bin" ]]; then
  echo "cura_compare: lamina binary '$lamina_bin' not found or not executable: Lamina column skipped" >&2
else
  echo "cura_compare: no lamina binary given (\$1): Lamina column skipped" >&2
fi

run_lamina() {
  local i=$1 out="$work/lamina.$1.stdout" tv="$work/lamina.$1.time" json="$work/lamina.$1.json"
  # shellcheck disable=SC2086
  /usr/bin/time -v -o "$tv" "$lamina_bin" slice "$model" --step 0.1 --json "$json" ${LAMINA_ARGS:-} \
    >"$out" 2>"$work/lamina.$i.stderr" || die "lamina failed (run $i): see $work/lamina.$i.stderr"
  # timings: the JSON's last line holds "timing_s":{"read":…,"topology":…,"slice":…}
  local tail_json
  tail_json=$(tail -c 400 "$json" 2>/dev/null || true)
  t() { # key
    local v
    v=$(grep -oE "\"$1\":[0-9.eE+-]+" <<<"$tail_json" | head -1 | cut -d: -f2)
    if [[ -z "$v" ]]; then v=$(grep -oE "$1 [0-9.]+ s" "$out" | head -1 | grep -oE '[0-9.]+'); fi
    echo "${v:-?}"
  }
  local r tp
  r=$(t read) tp=$(t topology)
  echo "read=$r topology=$tp load=$(awk -v a="$r" -v b="$tp" 'BEGIN { if (a + 0 == a && b + 0 == b) print a + b; else print "?" }') \
slice=$(t slice) slices=$(num '\(([0-9]+) slices' "$out") \
wall=$(wall_s "$tv") rss_kb=$(rss_kb "$tv")" >>"$work/lamina.runs"
  # the JSON holds every contour vector (~390 MB here): keep only the last run's
  [[ "$i" == "$reps" || -n "${KEEP_JSON:-}" ]] || rm -f "$json"
}

rm -f "$work/cura.runs" "$work/lamina.runs"
echo "== $reps run(s) each on $model ($triangles triangles), logs in $work"
echo "   ${cura_cmd[*]}"
for ((i = 1; i <= reps; i++)); do
  run_cura "$i"
  ((lamina_ok)) && run_lamina "$i"
done

# ---- 4. table --------------------------------------------------------------------------------
# field FILE KEY → "min / median" over the runs (or the single value, or "-")
stat() {
  [[ -f "$1" ]] || { echo "missing"; return; }
  grep -oE "(^| )$2=[^ ]+" "$1" | cut -d= -f2 | grep -E '^[0-9.]+$' | sort -g |
    awk -v scale="${3:-1}" -v fmt="${4:-%.3f}" '
      { v[NR] = $1 * scale }
      END {
        if (NR == 0) { print "-"; exit }
        med = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
        if (NR == 1) printf fmt "\n", v[1]; else printf fmt " / " fmt "\n", v[1], med
      }'
}
L="$work/lamina.runs"
((lamina_ok)) || L=/nonexistent
row() { printf '%-36s %-24s %-24s\n' "$1" "$2" "$3"; }
echo
echo "CuraEngine $(CuraEngine help 2>&1 | grep -m1 -oE 'version [0-9.]+' || true) vs Lamina — $triangles triangles, step 0.1 mm, $(nproc) cores"
[[ $reps -gt 1 ]] && echo "(min / median of $reps runs; seconds unless noted)"
row "" "CuraEngine" "Lamina"
row "read + weld + adjacency" "$(stat "$work/cura.runs" load)" "$(stat "$L" load)"
row "  lamina: read" "(in load)" "$(stat "$L" read)"
row "  lamina: topology" "(in load)" "$(stat "$L" topology)"
row "slicing phase" "$(stat "$work/cura.runs" slice_stage)" "$(stat "$L" slice)"
row "  cura: triangles -> segments" "$(stat "$work/cura.runs" slice_mesh)" ""
row "  cura: segments -> polygons" "$(stat "$work/cura.runs" make_polygons)" ""
row "slices" "$(stat "$work/cura.runs" layers 1 %d)" "$(stat "$L" slices 1 %d)"
row "process total (self-reported)" "$(stat "$work/cura.runs" total)" ""
row "wall clock (/usr/bin/time)" "$(stat "$work/cura.runs" wall 1 %.2f)" "$(stat "$L" wall 1 %.2f)"
row "peak RSS (MiB)" "$(stat "$work/cura.runs" rss_kb 0.0009765625 %.0f)" "$(stat "$L" rss_kb 0.0009765625 %.0f)"
echo
echo "Cura: 'read + weld + adjacency' is its 'loading … took' line; 'slicing phase' is its"
echo "'Progress: slice accomplished' stage. Its other stages (layer parts, insets, export) are in"
echo "its process total only, and its wall clock also holds ~1 s of loading the definitions."
echo "Lamina: timing_s from its --json report; its wall clock includes writing that JSON."
echo "Raw lines: $work/cura.1.log.short, $work/lamina.1.stdout"
