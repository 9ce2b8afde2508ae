#!/usr/bin/env bash
# Builds (once) a Debian trixie root with FreeCAD 1.0 in it, for `make test-freecad1`, and
# prints its path. Needs root (debootstrap, chroot, mount).
#
# Its standard output is the root's path and nothing else, on one line: every other command's
# output (apt-get, debootstrap, chroot) goes to standard error, so that no install step's
# chatter can become part of the path that scripts/freecad1-run.sh reads.
#
# The root lives outside the clone, in $WAFERSCAN_CACHE (default /var/cache/waferscan), named
# after a hash of its recipe (the suite, the packages, ROOT_RECIPE_VERSION): change the recipe
# and the next run builds a new root (and removes the old ones); editing the rest of the
# script does not. A root is built in a ".partial" folder and renamed only when complete,
# so a run that was interrupted leaves no root that looks finished; the next run throws the
# partial one away and starts again. Safe to run again: with the root in place it only prints it.
set -euo pipefail

# From here on, standard output is standard error; the path alone is printed on fd 3.
exec 3>&1 1>&2
print_root() { printf '%s\n' "$1" >&3; }

here=$(cd "$(dirname "$0")" && pwd -P)
cache=${WAFERSCAN_CACHE:-/var/cache/waferscan}
suite=trixie
# What the tests need inside the root: FreeCAD 1.0, a venv for pin, a display for the GUI
# tests, git for the Addon Manager test (it clones the addon), certificates for pip.
packages=(freecad-python3 python3-venv xvfb xauth git ca-certificates)
# Raise it when the way the root is built changes in a way the suite and packages do not show.
ROOT_RECIPE_VERSION=1

say() { printf 'freecad1-root: %s\n' "$*" >&2; }
# shellcheck source=debian-root.sh
. "$here/debian-root.sh"

if [ "$(id -u)" -ne 0 ]; then
  say "error: needs root (debootstrap, chroot and mount)"
  exit 1
fi

key=$(printf '%s\n' "$suite" "${packages[*]}" "$ROOT_RECIPE_VERSION" | sha256sum | cut -c1-12)
root="$cache/$suite-freecad1-$key"
if [ -e "$root/.complete" ]; then
  print_root "$root"
  exit 0
fi

mirror=$(debian_mirror)
ensure_debootstrap

mkdir -p "$cache"
# One builder at a time (two CI runs on one machine wait for each other).
exec 9>"$cache/.lock"
flock 9
if [ -e "$root/.complete" ]; then   # another run finished it while this one waited
  print_root "$root"
  exit 0
fi

partial="$root.partial"
# Anything else here is a root of another recipe, or one an interrupted run left unfinished.
for old in "$cache"/$suite-freecad1-*; do
  if [ -d "$old" ]; then
    say "removing $old"
    remove_root "$old"
  elif [ -e "$old" ]; then
    rm -f "$old"   # an old root's run lock
  fi
done

started=$(date +%s)
say "building $root from $mirror ($suite, minbase)"
debootstrap --variant=minbase "$suite" "$partial" "$mirror"

# apt inside the root: /proc and /dev for the maintainer scripts; the host's DNS for the mirror.
cp /etc/resolv.conf "$partial/etc/resolv.conf"
mount -t proc proc "$partial/proc"
mount --bind /dev "$partial/dev"
trap 'umount -l "$partial/dev" "$partial/proc" 2>/dev/null || true' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
say "installing ${packages[*]}"
chroot "$partial" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive \
  sh -c "apt-get update && apt-get install -y --no-install-recommends ${packages[*]} && apt-get clean"
umount "$partial/dev" "$partial/proc"
trap - EXIT

chroot "$partial" dpkg-query -W -f='${Version}\n' freecad-python3 >"$partial/.complete"
mv "$partial" "$root"
say "built in $(( $(date +%s) - started )) s: FreeCAD $(cat "$root/.complete"), $(du -sh --one-file-system "$root" | cut -f1)"
print_root "$root"
