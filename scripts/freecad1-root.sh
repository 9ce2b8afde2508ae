#!/usr/bin/env bash
# Builds (once) a Debian trixie root with FreeCAD 1.0 in it, for `make test-freecad1`, and
# prints its path. Needs root (debootstrap, chroot, mount).
#
# Its standard output is the root's path and nothing else, on one line: every other command's
# output (apt-get, debootstrap, chroot) goes to standard error, so that no install step's
# chatter can become part of the path that scripts/freecad1-run.sh reads.
#
# The root lives outside the clone, in $WAFERSCAN_CACHE (default /var/cache/waferscan), named
# after a hash of this file: change the recipe below and the next run builds a new root (and
# removes the old ones). A root is built in a ".partial" folder and renamed only when complete,
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

say() { printf 'freecad1-root: %s\n' "$*" >&2; }

if [ "$(id -u)" -ne 0 ]; then
  say "error: needs root (debootstrap, chroot and mount)"
  exit 1
fi

key=$(sha256sum "$here/freecad1-root.sh" | cut -c1-12)
root="$cache/$suite-freecad1-$key"
if [ -e "$root/.complete" ]; then
  print_root "$root"
  exit 0
fi

# The Debian mirror this machine's apt uses (deb822 sources first, then the one-line format);
# DEBIAN_MIRROR overrides it.
mirror=${DEBIAN_MIRROR:-}
if [ -z "$mirror" ]; then
  mirror=$(sed -n 's/^URIs:[[:space:]]*\([^[:space:]]*\/debian\)\/\?$/\1/p' \
             /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n1)
fi
if [ -z "$mirror" ]; then
  mirror=$(sed -n 's/^deb[[:space:]]\+\(\[[^]]*\][[:space:]]\+\)\?\([^[:space:]]*\/debian\)\/\?[[:space:]].*/\2/p' \
             /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null | head -n1)
fi
if [ -z "$mirror" ]; then
  say "error: no Debian mirror found in /etc/apt/sources.list*; set DEBIAN_MIRROR"
  exit 1
fi

if ! command -v debootstrap >/dev/null 2>&1; then
  say "installing debootstrap"
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends debootstrap
fi

mkdir -p "$cache"
# One builder at a time (two CI runs on one machine wait for each other).
exec 9>"$cache/.lock"
flock 9
if [ -e "$root/.complete" ]; then   # another run finished it while this one waited
  print_root "$root"
  exit 0
fi

# Removes a root or a partial one. Never through a mount: a root left mounted by a killed
# run would otherwise take the bind-mounted checkout with it.
remove_root() {
  local dir=$1 mounted
  mounted=$(findmnt -rn -o TARGET | awk -v d="$dir" 'index($0, d "/") == 1 || $0 == d' | sort -r)
  if [ -n "$mounted" ]; then
    say "unmounting what a previous run left mounted in $dir"
    while read -r target; do umount -l "$target"; done <<<"$mounted"
  fi
  # A bind mount from the same disk would not stop rm --one-file-system: check, then remove.
  if findmnt -rn -o TARGET | awk -v d="$dir" 'index($0, d "/") == 1 || $0 == d' | grep -q .; then
    say "error: something is still mounted in $dir; not removing it"
    exit 1
  fi
  rm -rf --one-file-system "$dir"
}

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
