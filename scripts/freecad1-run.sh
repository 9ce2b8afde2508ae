#!/usr/bin/env bash
# Runs a command inside the Debian trixie root with FreeCAD 1.0 (scripts/freecad1-root.sh builds
# it on first use), with this checkout mounted at /waferscan, where the command starts.
# Without a command: a shell. `make test-freecad1` runs the test suite this way.
#
# Inside, WAFERSCAN_VENV=/opt/waferscan-venv: scripts/setup.sh makes the venv there (in the
# root, for trixie's Python; the checkout's own .venv is bookworm's) and the addon's Init.py
# adds that venv's packages to FreeCAD. The mounts (/proc, /dev, the checkout) are undone when
# the command ends, whatever way it ends.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd -P)
checkout=$(dirname "$here")
say() { printf 'freecad1-run: %s\n' "$*" >&2; }
# shellcheck source=debian-root.sh
. "$here/debian-root.sh"
# The root's path is freecad1-root.sh's whole standard output; check it is one absolute path to a
# finished root before using it (a message that reached stdout would otherwise become the path).
root=$("$here/freecad1-root.sh")
if [[ $root != /* || $root == *$'\n'* || ! -e $root/.complete ]]; then
  say "error: scripts/freecad1-root.sh printed no finished root's path, but:"
  printf '%s\n' "$root" >&2
  exit 1
fi
inside=/waferscan

# One run at a time in a root: a second checkout mounted at the same place would hide the first.
exec 8>"$root.run-lock"
flock 8
# A run killed outright (SIGKILL) leaves its mounts behind; with the lock held they are no one's.
unmount_under "$root"

mounted=()
cleanup() {
  local i
  # A process the command left running in the root (a stray Xvfb) would hold its files and pile
  # up run after run: end it, name it, and fail the run.
  end_processes_in "$root" "the command" || { [ "$status" -ne 0 ] || status=1; }
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    # -l: a process still holding a file there (a stray Xvfb) must not keep the mount.
    umount "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" || true
  done
}
status=0
# The clean-up runs to its end: a second signal (a double Ctrl-C) would otherwise end the shell
# between two unmounts, and a closed output (a Ctrl-C'd `| tee`) would end it at its first word.
trap 'trap "" INT TERM HUP PIPE; cleanup; exit "$status"' EXIT
trap 'status=130; exit' INT
trap 'status=143; exit' TERM
trap 'status=129; exit' HUP

mount_in() {   # mount_in TARGET MOUNT-ARGS...
  local target="$root$1"
  shift
  mkdir -p "$target"
  mount "$@" "$target"
  mounted+=("$target")
}
mount_in /proc -t proc proc
mount_in /dev --bind /dev
mount_in /dev/shm -t tmpfs shm      # Qt and Xvfb want shared memory
mount_in "$inside" --bind "$checkout"
# The GUI tests' screenshots go to test-artifacts/freecad1/, next to (not over) bookworm's.
mkdir -p "$checkout/test-artifacts/freecad1"
mount_in "$inside/test-artifacts" --bind "$checkout/test-artifacts/freecad1"
# pip inside reaches the package index as the host does: the host's DNS, proxy settings and
# certificate bundle (which may hold a local proxy's authority that trixie's bundle lacks).
cp /etc/resolv.conf "$root/etc/resolv.conf"
pass_env=()
if [ -f /etc/ssl/certs/ca-certificates.crt ]; then
  cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/host-ca-certificates.crt"
  pass_env+=(PIP_CERT=/etc/ssl/host-ca-certificates.crt)
fi
for name in http_proxy https_proxy no_proxy HTTP_PROXY HTTPS_PROXY NO_PROXY HYPOTHESIS_PROFILE; do
  [ -n "${!name:-}" ] && pass_env+=("$name=${!name}")
done

# X displays in the root count from :200 (waferscan/bench/xvfb.py): its /tmp is its own, so
# xvfb-run there cannot see the host's lock files, and a host suite's Xvfb (from :99) running at
# the same time would want the same listening socket (the network namespace is shared).
pass_env+=(WAFERSCAN_XVFB_FIRST=200)

[ $# -gt 0 ] || set -- bash
chroot "$root" /usr/bin/env -i \
  HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  LANG=C.UTF-8 TERM="${TERM:-dumb}" DEBIAN_FRONTEND=noninteractive \
  WAFERSCAN_VENV=/opt/waferscan-venv ${pass_env[@]+"${pass_env[@]}"} \
  /bin/sh -c 'cd "$0" && exec "$@"' "$inside" "$@" || status=$?
exit "$status"
