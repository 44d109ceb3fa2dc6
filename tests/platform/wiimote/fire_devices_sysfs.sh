#!/usr/bin/env bash
# fire devices --sys-root on made-up /sys trees (laid out as the kernel lays them out): one line per
# remote naming the step it misses, exit 1 unless every Wii Remote is ready, no hidapi at all.
#   fire_devices_sysfs.sh FIRE_BINARY WORK_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"

# sysfs ROOT [PARAMETER]: an empty tree; PARAMETER is ignore_special_drivers' content, none if not given.
sysfs() {
  mkdir -p "$1/bus/hid/devices" "$1/bus/hid/drivers/wiimote" "$1/bus/hid/drivers/hid-generic"
  if [ $# -gt 1 ]; then mkdir -p "$1/module/hid/parameters" && echo "$2" >"$1/module/hid/parameters/ignore_special_drivers"; fi
}
# device ROOT HID_ID NAME ADDRESS DRIVER HIDRAW (DRIVER, HIDRAW: "" for none)
device() {
  local root="$PWD/$1"
  local dev="$root/devices/virtual/misc/uhid/$2"
  mkdir -p "$dev"
  ln -s "$dev" "$root/bus/hid/devices/$2"
  printf 'HID_ID=0005:0000057E:00000306\nHID_NAME=%s\nHID_UNIQ=%s\n' "$3" "$4" >"$dev/uevent"
  if [ -n "$5" ]; then ln -s "$root/bus/hid/drivers/$5" "$dev/driver"; fi
  if [ -n "$6" ]; then mkdir -p "$dev/hidraw/$6"; fi
}
# run NAME EXPECTED_EXIT: fire devices --sys-root NAME, output in NAME.out
run() {
  local rc=0
  "$fire" devices --sys-root "$PWD/$1" >"$1.out" 2>"$1.err" || rc=$?
  [ "$rc" = "$2" ] || fail "$1: exit $rc, expected $2: $(cat "$1.out" "$1.err")"
}
expect() { grep -qF -- "$2" "$1.out" || fail "$1: no \"$2\" in: $(cat "$1.out")"; }
refuse() { if grep -qF -- "$2" "$1.out"; then fail "$1: \"$2\" in: $(cat "$1.out")"; fi; }

id=0005:057E:0306.0003
set_it="echo 1 | sudo tee /sys/module/hid/parameters/ignore_special_drivers"
bind="echo -n $id | sudo tee /sys/bus/hid/drivers/hid-generic/bind"
unbind="echo -n $id | sudo tee /sys/bus/hid/drivers/wiimote/unbind"

sysfs unbound N
device unbound $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 "" ""
run unbound 1
expect unbound "$id (00:1F:32:AA:BB:01): no HID driver is bound"
expect unbound "1. set hid.ignore_special_drivers: $set_it"
expect unbound "2. $bind"
expect unbound "blacklisting hid_wiimote"

sysfs wiimote N
device wiimote $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 wiimote hidraw3
run wiimote 1
expect wiimote "$id (00:1F:32:AA:BB:01): held by the kernel's hid-wiimote driver"
expect wiimote "1. set hid.ignore_special_drivers: $set_it"
expect wiimote "2. $unbind; $bind"

sysfs wiimote_after_y Y
device wiimote_after_y $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 wiimote hidraw3
run wiimote_after_y 1
expect wiimote_after_y "although hid.ignore_special_drivers is set"
expect wiimote_after_y "$unbind; $bind (or reconnect it: bluetoothctl disconnect 00:1F:32:AA:BB:01"
refuse wiimote_after_y "$set_it"

sysfs generic Y
device generic $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 hid-generic hidraw5
device generic 0005:057E:0330.0004 "Nintendo RVL-CNT-01-TR" 00:1f:32:aa:bb:02 hid-generic hidraw6
run generic 0
expect generic "$id (00:1F:32:AA:BB:01): ready: hid-generic holds it, /dev/hidraw5"
expect generic "0005:057E:0330.0004 (00:1F:32:AA:BB:02): ready: hid-generic holds it, /dev/hidraw6"
[ "$(wc -l <generic.out)" = 2 ] || fail "generic: not one line per remote: $(cat generic.out)"

# One ready, one not: the command fails and names the one that is not.
sysfs mixed N
device mixed $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 hid-generic hidraw5
device mixed 0005:057E:0330.0004 "Nintendo RVL-CNT-01-TR" 00:1f:32:aa:bb:02 wiimote hidraw6
run mixed 1
expect mixed "0005:057E:0330.0004 (00:1F:32:AA:BB:02): held by the kernel's hid-wiimote driver"

sysfs pro N
device pro 0005:057E:0330.0007 "Nintendo RVL-CNT-01-UC" 00:1f:32:aa:bb:07 wiimote hidraw7
run pro 1
expect pro "0005:057E:0330.0007 (00:1F:32:AA:BB:07): \"Nintendo RVL-CNT-01-UC\" has a Wii Remote's ids but is another product: left alone"
expect pro "no Wii Remote found under $PWD/pro/bus/hid/devices (pair and connect one first: docs/wiimote.md)"
refuse pro "bind"

sysfs empty
run empty 1
[ "$(cat empty.out)" = "no Wii Remote found under $PWD/empty/bus/hid/devices (pair and connect one first: docs/wiimote.md)" ] ||
  fail "empty: $(cat empty.out)"

"$fire" devices --help >help.out || fail "devices --help failed"
expect help "--sys-root"
expect help "test hook: read this folder instead of /sys"
echo "fire devices --sys-root: unbound, hid-wiimote (N and Y), hid-generic, mixed, Pro Controller and empty trees as expected"
