#!/usr/bin/env bash
# fire devices --sys-root (and --dev-root, --rig) on made-up /sys trees laid out as the kernel lays them out: each
# step missed named on one line, in the order of docs/hardware.md, no hidapi at all. The exit is the command's:
# 1 when a remote found cannot be used (the kernel's driver, permissions), else 0, also when none is found.
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
# adapter ROOT NAME SOFT_BLOCK: a Bluetooth adapter in class/bluetooth with its rfkill switch, and one of its links
adapter() {
  local dev="$PWD/$1/devices/pci0000:00/usb1/1-1/1-1:1.0/bluetooth/$2"
  mkdir -p "$dev/rfkill0" "$dev/$2:11" "$1/class/bluetooth"
  echo "$3" >"$dev/rfkill0/soft"
  echo 0 >"$dev/rfkill0/hard"
  ln -s "$dev" "$1/class/bluetooth/$2"
  ln -s "$dev/$2:11" "$1/class/bluetooth/$2:11"
}
# rig FILE ADDRESS:ROLE...: a rig file's "remotes" member (all fire devices reads of it)
rig() {
  local f="$1" sep="" entries=""
  shift
  for e in "$@"; do entries+="$sep{\"address\": \"${e%%=*}\", \"role\": \"${e#*=}\"}"; sep=", "; done
  echo "{\"remotes\": [$entries]}" >"$f"
}
# run NAME EXPECTED_EXIT [OPTION...]: fire devices --sys-root NAME [OPTION...], output in NAME.out
run() {
  local name="$1" want="$2" rc=0
  shift 2
  $as_user "$bin" devices --sys-root "$PWD/$name" "$@" >"$name.out" 2>"$name.err" || rc=$?
  [ "$rc" = "$want" ] || fail "$name: exit $rc, expected $want: $(cat "$name.out" "$name.err")"
}
expect() { grep -qF -- "$2" "$1.out" || fail "$1: no \"$2\" in: $(cat "$1.out")"; }
refuse() { if grep -qF -- "$2" "$1.out"; then fail "$1: \"$2\" in: $(cat "$1.out")"; fi; }
# line NAME TEXT: the number of the first line of NAME.out that holds TEXT
line() { grep -nF -- "$2" "$1.out" | head -1 | cut -d: -f1; }
# in_order NAME TEXT...: each TEXT on a later line than the one before
in_order() {
  local name="$1" last=0 n
  shift
  for t in "$@"; do
    n=$(line "$name" "$t")
    [ -n "$n" ] && [ "$n" -gt "$last" ] || fail "$name: \"$t\" not after line $last: $(cat "$name.out")"
    last=$n
  done
}
# Every case but the permission ones runs as whoever runs this; root may open any node, so those run as nobody (below).
as_user=""
bin="$fire"

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
run pro 0
expect pro "0005:057E:0330.0007 (00:1F:32:AA:BB:07): \"Nintendo RVL-CNT-01-UC\" has a Wii Remote's ids but is another product: left alone"
expect pro "no Wii Remote found, and no Bluetooth adapter"
refuse pro "bind"

# No remote: what the adapters say, as the one step missed; nothing found is not a failure.
sysfs empty
run empty 0
[ "$(cat empty.out)" = "steps missed, in the order of docs/hardware.md:
  no Wii Remote found, and no Bluetooth adapter (none in $PWD/empty/class/bluetooth): plug in a Bluetooth Classic adapter (docs/hardware.md section 1), then pair and connect the remotes (docs/hardware.md section 5)" ] ||
  fail "empty: $(cat empty.out)"
sysfs blocked
adapter blocked hci0 1
run blocked 0
expect blocked "no Wii Remote found: the Bluetooth adapter hci0 is switched off (rfkill blocks it): rfkill unblock bluetooth"
sysfs unpaired
adapter unpaired hci0 0
run unpaired 0
expect unpaired "no Wii Remote found: none is connected: pair and connect them; a paired and trusted remote reconnects when you press a button on it (docs/hardware.md section 5)"

# With a rig: its remote that is not there, and the one there that it does not list (the pad, off while calibrating).
# Neither stops a session, so the exit stays 0.
sysfs rigged Y
adapter rigged hci0 0
device rigged $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 hid-generic hidraw5
device rigged 0005:057E:0306.0005 "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:03 hid-generic hidraw7
rig rigged.json 00:1F:32:AA:BB:01=camera0 00:1F:32:AA:BB:02=camera1
run rigged 0 --rig rigged.json
in_order rigged "steps missed, in the order of docs/hardware.md:" \
  "  camera1 00:1F:32:AA:BB:02 (rigged.json) is not connected: press a button on it to reconnect it" \
  "  00:1F:32:AA:BB:03: not in the \"remotes\" of rigged.json, so fire app --live leaves it alone: if it is the pad (switched off while calibrating), add {\"address\": \"00:1F:32:AA:BB:03\", \"role\": \"pad\"} to that list (docs/hardware.md section 7)"
refuse rigged "camera0 00:1F:32:AA:BB:01 (rigged.json) is not connected"
[ "$(wc -l <rigged.out)" = 5 ] || fail "rigged: not two remotes and two steps under a heading: $(cat rigged.out)"

# Without a rig, three remotes: the roles go by address order, the pad must be off while aiming and calibrating.
sysfs three Y
device three $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 hid-generic hidraw5
device three 0005:057E:0306.0004 "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:02 hid-generic hidraw6
device three 0005:057E:0306.0005 "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:03 hid-generic hidraw7
run three 0
expect three "3 Wii Remotes and no rig file, so the roles go by address order: 00:1F:32:AA:BB:01 camera0, 00:1F:32:AA:BB:02 camera1, 00:1F:32:AA:BB:03 pad: switch the pad off while you aim and calibrate"

# --dev-root: a node the user may not open is named with the udev rule and the group, and the remote cannot be used.
# Run as root, these cases run as nobody, from a folder and a copy of the binary that nobody can reach wherever
# the checkout lies (a clone under /root, or in a folder of mode 700, is out of nobody's reach).
if [ "$(id -u)" = 0 ]; then
  stage=$(mktemp -d /tmp/fire_devices_sysfs.XXXXXX)
  trap 'rm -rf "$stage"' EXIT
  chmod 755 "$stage"
  cp "$fire" "$stage/fire"
  cd "$stage"
  as_user="setpriv --reuid=nobody --regid=nogroup --clear-groups"
  bin="$stage/fire"
fi
sysfs denied Y
device denied $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 hid-generic hidraw5
device denied 0005:057E:0306.0004 "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:02 hid-generic hidraw6
mkdir -p dev
touch dev/hidraw5 dev/hidraw6
chmod 000 dev/hidraw5
chmod 666 dev/hidraw6
run denied 0
refuse denied "permission denied"
run denied 1 --dev-root "$PWD/dev"
expect denied "  camera0 00:1F:32:AA:BB:01: permission denied on $PWD/dev/hidraw5: install FIRE's udev rule (sudo install -m 644 platform/wiimote/99-fire-wiimote.rules /etc/udev/rules.d/"
expect denied "sudo usermod -aG plugdev \$USER, and log in again (docs/hardware.md section 6; details: docs/wiimote.md section 3)"
refuse denied "on $PWD/dev/hidraw6"

# Every step it can see at once, in the guide's order, not the remotes': the rig's pad not connected (section 5),
# hid-wiimote on the second remote (6), the udev rule for the first (6), a remote the rig does not list (7).
sysfs all N
adapter all hci0 0
device all $id "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:01 hid-generic hidraw5
device all 0005:057E:0306.0004 "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:02 wiimote hidraw6
device all 0005:057E:0306.0005 "Nintendo RVL-CNT-01" 00:1f:32:aa:bb:04 hid-generic hidraw7
touch dev/hidraw7
chmod 666 dev/hidraw7
rig all.json 00:1F:32:AA:BB:01=camera0 00:1F:32:AA:BB:02=camera1 00:1F:32:AA:BB:03=pad
run all 1 --rig all.json --dev-root "$PWD/dev"
in_order all "steps missed, in the order of docs/hardware.md:" \
  "  pad 00:1F:32:AA:BB:03 (all.json) is not connected" \
  "  0005:057E:0306.0004 (00:1F:32:AA:BB:02): held by the kernel's hid-wiimote driver" \
  "  camera0 00:1F:32:AA:BB:01: permission denied on $PWD/dev/hidraw5" \
  "  00:1F:32:AA:BB:04: not in the \"remotes\" of all.json, so fire app --live leaves it alone: the pad there is 00:1F:32:AA:BB:03"
[ "$(grep -c "(docs/hardware.md section" all.out)" = 4 ] || fail "all: not four steps, each naming its section: $(cat all.out)"

"$fire" devices --help >help.out || fail "devices --help failed"
expect help "--sys-root"
expect help "test hook: read this folder instead of /sys"
expect help "test hook, with --sys-root: the folder of the hidraw nodes"
echo "fire devices --sys-root: unbound, hid-wiimote (N and Y), hid-generic, mixed, Pro Controller, no remote (no adapter," \
  "blocked, none connected), a rig's remote missing and one unlisted, three without a rig, a node denied, all at once: as expected"
