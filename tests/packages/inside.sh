#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# Runs inside the clean Debian root made by tests/packages/run (chroot, no network): what
# a PC user does with the packages. Files in /srv/ccomm-test: debs/, wheel/, wheelhouse/
# (numpy), consumer/ (the C and C++ programs), talk.py, local-only.xml.
# Environment: CCOMM_VERSION (the packages' version). Exit 0 if every check passed.
set -uo pipefail
T=/srv/ccomm-test
export DEBIAN_FRONTEND=noninteractive
passed=0 failed=0
check() {  # check "description" command...: counts, and shows the output of a failure
  local what=$1 out
  shift
  if out=$("$@" 2>&1); then
    passed=$((passed + 1)); echo "ok - $what"
  else
    failed=$((failed + 1)); echo "not ok - $what"; sed 's/^/    /' <<<"$out" | tail -25
  fi
}
quiet_ok() { "$@" >/dev/null 2>&1; }

# ---- what the maintainer scripts ask of systemd ------------------------------------------
# No systemd runs in a chroot: deb-systemd-invoke and systemctl are stand-ins that log each
# call, and /run/systemd/system tells the scripts that systemd is running, so what an
# install, a reinstall, dpkg-reconfigure and a removal would do to ccommd is on record.
shim=$T/shim calls=$T/systemd-calls.log
mkdir -p "$shim" /run/systemd/system
printf '#!/bin/sh\necho "deb-systemd-invoke $*" >>%s\n' "$calls" >"$shim/deb-systemd-invoke"
# systemctl: what would act on the running system is only logged; the rest (preset,
# enable, is-enabled: how the postinst enables ccommd.service) runs offline on the files.
cat >"$shim/systemctl" <<EOF
#!/bin/sh
echo "systemctl \$*" >>$calls
case " \$* " in *" daemon-reload "*|*" start "*|*" stop "*|*" restart "*|*" try-restart "*|*" reload "*) exit 0 ;; esac
SYSTEMD_OFFLINE=1 exec /bin/systemctl "\$@"
EOF
chmod 755 "$shim/deb-systemd-invoke" "$shim/systemctl"
# apt runs dpkg with its own PATH (DPkg::Path), so it is given the stand-ins' too.
shim_path=$shim:/usr/sbin:/usr/bin:/sbin:/bin
with_shim() { : >"$calls"; PATH=$shim_path "$@"; }
ccommd_calls() { grep -E 'ccommd\.service' "$calls" | grep -vE 'daemon-reload|is-enabled|enable|unmask|mask' || true; }

# ---- the packages install, offline ------------------------------------------------------
check "apt install ./*.deb (ccommd libccomm0 libccomm-dev python3-ccomm)" \
  with_shim apt-get install -y -q --no-install-recommends -o Debug::NoLocking=1 -o DPkg::Path="$shim_path" "$T"/debs/*.deb
check "the maintainer scripts ran with the stand-ins (systemctl daemon-reload recorded)" grep -q '^systemctl .*daemon-reload' "$calls"
check "a first install does not start ccommd (the default signals.xml is to be edited)" \
  bash -c "! grep -E '(start|restart) .*ccommd' $calls || { cat $calls; false; }"
check "ccomm-board-net.service shipped, not enabled, not started (a PC keeps its network)" bash -c \
  "test -f /lib/systemd/system/ccomm-board-net.service && ! test -e /etc/systemd/system/multi-user.target.wants/ccomm-board-net.service && ! grep -E 'start .*ccomm-board-net' $calls"
for p in ccommd libccomm0 libccomm-dev python3-ccomm; do
  check "$p $CCOMM_VERSION installed" bash -c "dpkg-query -W -f='\${Status} \${Version}' $p | grep -qx 'install ok installed $CCOMM_VERSION'"
done
check "system user and group ccomm (sysusers at configure)" bash -c 'getent passwd ccomm && getent group ccomm'
check "ccommd.service enabled (not started)" test -L /etc/systemd/system/multi-user.target.wants/ccommd.service
check "/etc/ccomm/signals.xml is a conffile" bash -c "dpkg-query -W -f='\${Conffiles}' ccommd | grep -q /etc/ccomm/signals.xml"
check "the installed signals.xml passes ccommd --check" ccommd --check /etc/ccomm/signals.xml
check "man pages ccommd(8), ccomm(1), ccomm-latency(1), ccomm-fmu(1)" \
  test -s /usr/share/man/man8/ccommd.8.gz -a -s /usr/share/man/man1/ccomm.1.gz -a -s /usr/share/man/man1/ccomm-latency.1.gz \
    -a -s /usr/share/man/man1/ccomm-fmu.1.gz
check "ccomm-fmu installed (--help)" bash -c "ccomm-fmu --help | grep -q 'ccomm-fmu run FMU'"
check "ccommd --version says $CCOMM_VERSION" bash -c "ccommd --version | grep -q '$CCOMM_VERSION'"

# ---- ccommd, started directly (no systemd in a chroot) ------------------------------------
ccommd --config "$T/local-only.xml" --node robot --no-rt >"$T/ccommd.log" 2>&1 &
daemon=$!
up() {
  local i
  for i in $(seq 100); do
    ccomm --node robot list >/dev/null 2>&1 && return 0
    kill -0 "$daemon" 2>/dev/null || { cat "$T/ccommd.log"; return 1; }
    sleep 0.1
  done
  cat "$T/ccommd.log"; return 1
}
check "ccommd runs node robot (examples/local-only.xml)" up

# ---- upgrades keep a running ccommd running ------------------------------------------------
# The maintainer scripts must not stop ccommd before an upgrade (preinst) and must restart
# it after one only if it runs: 'try-restart ccommd.service', never 'stop' or 'start'.
upgrade_keeps_running() {  # checks the calls of the last with_shim command
  local c
  c=$(ccommd_calls)
  echo "$c"
  grep -qE '^deb-systemd-invoke( --[a-z-]+)* try-restart .*ccommd\.service' <<<"$c" || { echo "no try-restart"; return 1; }
  ! grep -qE '(^| )(stop|start|restart) ' <<<"$c" || { echo "a stop/start/restart of ccommd"; return 1; }
  ! grep -qE '(start|restart|stop) .*ccomm-board-net' "$calls" || { echo "ccomm-board-net touched"; return 1; }
}
with_shim apt-get install -y -q --reinstall -o Debug::NoLocking=1 -o DPkg::Path="$shim_path" "$T"/debs/ccommd_*.deb >"$T/reinstall.log" 2>&1
check "apt-get install --reinstall ccommd ran the maintainer scripts" grep -q 'Setting up ccommd' "$T/reinstall.log"
check "apt-get install --reinstall ccommd: no stop, a try-restart (a running ccommd keeps running)" upgrade_keeps_running
with_shim dpkg-reconfigure ccommd >"$T/reconfigure.log" 2>&1
check "dpkg-reconfigure ccommd: no stop, a try-restart" upgrade_keeps_running
check "ccommd (started directly) survived the reinstall" kill -0 "$daemon"
check "ccommd still serves node robot after the reinstall" ccomm --node robot list

# ---- the user's C and C++ programs, built against the installed headers -------------------
check "cmake: find_package(ccomm) project configures and builds" bash -c \
  "cmake -S $T/consumer -B $T/build-cmake && cmake --build $T/build-cmake"
check "pkg-config ccomm: C++ program (ccomm.hpp) builds" bash -c \
  "g++ -std=c++17 -Wall -Wextra -Werror -o $T/joint_reader $T/consumer/joint_reader.cpp \$(pkg-config --cflags --libs ccomm)"
check "the find_package(ccomm) program writes joint_pos" "$T/build-cmake/joint_writer" 10
check "the pkg-config program reads it and writes drive_ok" "$T/joint_reader" 10
check "the installed CLI echoes joint_pos" bash -c "ccomm --node robot echo joint_pos --once | grep -q '10'"
check "the programs link the installed libccomm.so.0" bash -c \
  "ldd $T/build-cmake/joint_writer | grep -E 'libccomm.so.0 => /(usr/)?lib/' && ldd $T/joint_reader | grep -E 'libccomm.so.0 => /(usr/)?lib/'"

# ---- Python: the Debian package, then the wheel in a fresh venv ----------------------------
check "python3-ccomm talks to ccommd" \
  python3 "$T/talk.py" --version "$CCOMM_VERSION" --library-under /usr/lib/ --library-under /lib/ --base 10
check "python3 -m venv (no system site packages)" python3 -m venv "$T/venv"
check "pip install ccomm-*.whl (numpy from the local wheelhouse, nothing else)" \
  "$T/venv/bin/pip" install -q --disable-pip-version-check --no-index --find-links "$T/wheelhouse" "$T"/wheel/ccomm-*.whl
check "the wheel's libccomm needs only system libraries" bash -c \
  "! ldd $T/venv/lib/python3*/site-packages/ccomm/_lib/libccomm.so.0 | grep -q 'not found'"
check "the wheel (its own libccomm) talks to ccommd" bash -c \
  "cd / && $T/venv/bin/python $T/talk.py --version $CCOMM_VERSION --library-under $T/venv/ --base 10"

# ---- stop and remove ---------------------------------------------------------------------
kill -TERM "$daemon"
wait "$daemon"
stopped=$?
check "ccommd stops cleanly on SIGTERM (exit 0)" test "$stopped" -eq 0
check "python3-ccomm: a write while ccommd is down tells the caller" \
  python3 "$T/talk.py" --version "$CCOMM_VERSION" --library-under / --base 10 --daemon-stopped
check "the wheel: a write while ccommd is down tells the caller" bash -c \
  "cd / && $T/venv/bin/python $T/talk.py --version $CCOMM_VERSION --library-under / --base 10 --daemon-stopped"
check "apt purge removes the packages" \
  with_shim apt-get purge -y -q -o Debug::NoLocking=1 -o DPkg::Path="$shim_path" ccommd libccomm0 libccomm-dev python3-ccomm
check "the removal stops ccommd (prerm)" bash -c "grep -qE '^deb-systemd-invoke( --[a-z-]+)* stop .*ccommd\.service' $calls || { cat $calls; false; }"
rm -rf /run/systemd/system "$shim"
check "nothing of ccommd left but the user" bash -c "! test -e /etc/ccomm/signals.xml && ! test -e /usr/bin/ccommd"

echo "packages: $passed passed, $failed failed"
[[ $failed -eq 0 ]]
