#!/usr/bin/env bash
# The Debian package as a cell PC receives it: built by CPack from this build tree, then read
# back with dpkg-deb (never installed here: its scripts would create a system user). Checks the
# control fields, that every piece laminad needs is in it, the conffile, stripped programs, and
# that the packaged laminad runs: --version and --check-config on the packaged configuration.
#   check_deb.sh BUILD_DIR EXPECTED_VERSION
set -euo pipefail
build=$1 version=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cpack --config "$build/CPackConfig.cmake" -B "$work/out" >"$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; fail "cpack"; }
deb=$(ls "$work"/out/*.deb)
[[ $(basename "$deb") == "lamina_${version}_$(dpkg --print-architecture).deb" ]] || fail "package file name $(basename "$deb")"
[[ $(dpkg-deb -f "$deb" Package) == lamina ]] || fail "Package field"
[[ $(dpkg-deb -f "$deb" Version) == "$version" ]] || fail "Version $(dpkg-deb -f "$deb" Version), expected $version"
for dep in systemd libmodbus5 libsqlite3-0 libsystemd0 libserialport0; do
  dpkg-deb -f "$deb" Depends | grep -q "\b$dep\b" || fail "Depends lacks $dep: $(dpkg-deb -f "$deb" Depends)"
done

dpkg-deb -c "$deb" | awk '{print $6}' >"$work/files"
for f in ./usr/sbin/laminad ./usr/bin/lamina ./usr/bin/lamina-sim ./usr/lib/systemd/system/laminad.service \
         ./usr/lib/systemd/system/laminad.socket ./usr/lib/sysusers.d/lamina.conf ./usr/lib/tmpfiles.d/lamina.conf \
         ./etc/lamina/lamina.toml; do
  grep -qx "$f" "$work/files" || fail "$f is not in the package"
done
# The web console, when this build made it (-DLAMINA_BUILD_WEB, on by default).
if [[ -f "$build/web/index.html" ]]; then
  for f in ./usr/share/lamina/web/index.html ./usr/share/lamina/web/app.js ./usr/share/lamina/web/style.css; do
    grep -qx "$f" "$work/files" || fail "$f is not in the package"
  done
fi
# The STEP module, when this build made it (core/step): packaged beside the programs' bin/, where
# the packaged lamina looks for it (checked below by reading a STEP file with it).
step_module=false
if [[ -f "$build/lib/lamina/liblamina_step.so" ]]; then
  step_module=true
  grep -qx ./usr/lib/lamina/liblamina_step.so "$work/files" || fail "./usr/lib/lamina/liblamina_step.so is not in the package"
fi
dpkg-deb -e "$deb" "$work/control"
grep -qx /etc/lamina/lamina.toml "$work/control/conffiles" || fail "/etc/lamina/lamina.toml is not a conffile"
for s in postinst prerm postrm; do [[ -x "$work/control/$s" ]] || fail "$s is missing or not executable"; done

dpkg-deb -x "$deb" "$work/root"
for exe in usr/sbin/laminad usr/bin/lamina; do
  if readelf -S "$work/root/$exe" | grep -q '\.debug_info'; then fail "$exe is not stripped"; fi
done
out=$("$work/root/usr/sbin/laminad" --version)
[[ $out == "laminad $version" ]] || fail "laminad --version says '$out'"
"$work/root/usr/sbin/laminad" --check-config --config "$work/root/etc/lamina/lamina.toml" \
  || fail "the packaged configuration does not pass laminad --check-config"
if $step_module; then
  knob=$(cd "$(dirname "$0")/../../examples" && pwd)/knob.step
  "$work/root/usr/bin/lamina" check "$knob" >"$work/step.log" 2>&1 \
    || { cat "$work/step.log"; fail "the packaged lamina cannot read $knob through its STEP module"; }
fi
echo "ok: $(basename "$deb"), $(du -h "$deb" | cut -f1), $(wc -l <"$work/files") entries"
