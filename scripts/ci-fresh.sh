#!/usr/bin/env bash
# `make ci-fresh`: rehearses CI on a machine where nothing was installed. Runs `.ci/run` from a
# fresh clone of this checkout's HEAD inside a throwaway Debian bookworm root that holds only
# debootstrap's minbase, so a set-up step that works here only because this machine already has
# something (a package, a cache, a venv) fails in the rehearsal and not on a user's machine.
# Needs root (debootstrap, chroot, mount).
#
# - The minbase root is built once and kept in $WAFERSCAN_CACHE (default /var/cache/waferscan),
#   named after a hash of its recipe; each run writes into an overlay over it (a copy where
#   overlayfs is not available), thrown away at the end, so every run starts from minbase.
# - Inside, the machine's own settings come along as a new machine of this kind has them: apt's
#   sources and settings, DNS, certificate authorities, pip's configuration, and this process's
#   environment (proxies, PIP_*, ...). Nothing else: no package, venv or cache of this machine.
# - The clone is of the committed HEAD (uncommitted changes are not rehearsed: commit first),
#   at /work/waferscan with ../shared beside it when this checkout has one.
# - `make test-freecad1` inside builds its trixie root from nothing too (inside the throwaway
#   root). WAFERSCAN_CI_FRESH_TRIXIE=share mounts this machine's cache instead, to rehearse the
#   bookworm side quickly.
# - At the end, any process still running in the root is reported and killed, and the run fails:
#   CI's own machine would keep it.
#
# Prints the time and the tests' closing lines of both FreeCADs; exit status: .ci/run's, or 1
# when processes were left behind.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd -P)
checkout=$(dirname "$here")
cache=${WAFERSCAN_CACHE:-/var/cache/waferscan}
say() { printf 'ci-fresh: %s\n' "$*" >&2; }
# shellcheck source=debian-root.sh
. "$here/debian-root.sh"

if [ "$(id -u)" -ne 0 ]; then
  say "error: needs root (debootstrap, chroot and mount)"
  exit 1
fi
if ! git -C "$checkout" diff --quiet HEAD 2>/dev/null; then
  say "note: uncommitted changes are not part of the rehearsal (it clones HEAD)"
fi

# 1. The minbase root, built once (named after its recipe: the suite, the variant, the mirror).
suite=bookworm
mirror=$(debian_mirror)
key=$(printf '%s minbase %s\n' "$suite" "$mirror" | sha256sum | cut -c1-12)
base="$cache/$suite-minbase-$key"
mkdir -p "$cache"
if [ ! -e "$base/.complete" ]; then
  exec 9>"$cache/.lock"
  flock 9
  if [ ! -e "$base/.complete" ]; then
    ensure_debootstrap
    for old in "$cache"/$suite-minbase-*; do
      [ -d "$old" ] && { say "removing $old"; remove_root "$old"; }
    done
    say "building $base from $mirror ($suite, minbase)"
    started=$(date +%s)
    debootstrap --variant=minbase "$suite" "$base.partial" "$mirror" >&2
    date -u +%FT%TZ >"$base.partial/.complete"
    mv "$base.partial" "$base"
    say "built in $(( $(date +%s) - started )) s, $(du -sh --one-file-system "$base" | cut -f1)"
  fi
  exec 9>&-
fi

# 2. This run's root: an overlay over the minbase root (or a copy of it). Each run holds a lock
#    on its folder while it lives; a folder whose lock is free is a killed run's: removed.
mkdir -p "$cache/ci-fresh-runs"
exec 9>"$cache/.lock"   # no other rehearsal looks at the runs while this one picks its own
flock 9
for old in "$cache"/ci-fresh-runs/run.*; do
  [ -d "$old" ] || continue
  if flock -n "$old/.lock" true 2>/dev/null; then
    say "removing $old (a run that was killed)"
    remove_root "$old"
  fi
done
run=$(mktemp -d "$cache/ci-fresh-runs/run.XXXXXX")
exec 7>"$run/.lock"
flock 7
exec 9>&-
root="$run/root"
mkdir -p "$root" "$run/upper" "$run/work"
status=0
finish() {
  trap - EXIT INT TERM
  # Processes still running in the root (a stray Xvfb, a watcher): they would outlive CI too.
  end_processes_in "$root" ".ci/run" || { [ "$status" -ne 0 ] || status=1; }
  unmount_under "$root"
  if [ -n "${KEEP_ROOT:-}" ]; then say "kept $run (KEEP_ROOT)"; else remove_root "$run"; fi
  exit "$status"
}
trap finish EXIT
trap 'status=130; exit 130' INT
trap 'status=143; exit 143' TERM

if mount -t overlay overlay -o "lowerdir=$base,upperdir=$run/upper,workdir=$run/work" "$root" 2>/dev/null; then
  say "root: overlay over $base at $root"
else
  say "root: overlayfs not available; copying $base to $root"
  cp -a "$base/." "$root/"
fi
rm -f "$root/.complete"

# 3. The machine's own settings, as a new machine of this kind has them: the site's files only,
#    not a package's (apt.conf.d's packagekit hook, say, would fail where packagekit is absent).
for file in /etc/resolv.conf /etc/apt/sources.list /etc/apt/sources.list.d/*.sources \
            /etc/apt/sources.list.d/*.list /etc/apt/apt.conf.d/* /etc/pip.conf \
            /etc/xdg/pip/* /root/.config/pip/pip.conf /usr/local/share/ca-certificates/*; do
  [ -f "$file" ] || continue
  case $file in /etc/apt/apt.conf.d/*) ! dpkg -S "$file" >/dev/null 2>&1 || continue ;; esac
  mkdir -p "$root$(dirname "$file")"
  cp -L "$file" "$root$file"
done
# Until the root's ca-certificates package is installed (by the set-up), the machine's bundle.
if [ -f /etc/ssl/certs/ca-certificates.crt ]; then
  mkdir -p "$root/etc/ssl/certs"
  cp -L /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/ca-certificates.crt"
fi

mount_in() {   # mount_in TARGET MOUNT-ARGS...
  mkdir -p "$root$1"
  local target="$root$1"
  shift
  mount "$@" "$target"
}
mount_in /proc -t proc proc
mount_in /sys --rbind /sys
mount_in /dev --bind /dev
mount_in /dev/pts --bind /dev/pts
mount_in /dev/shm -t tmpfs shm
mount_in /tmp -t tmpfs tmp
if [ "${WAFERSCAN_CI_FRESH_TRIXIE:-}" = share ]; then
  mkdir -p "$cache"
  mount_in /var/cache/waferscan --bind "$cache"
  say "sharing this machine's $cache (the trixie root is not rebuilt)"
fi

# 4. A fresh clone of HEAD, with shared/ beside it, as CI has it.
mkdir -p "$root/work"
git clone --quiet --no-hardlinks "$checkout" "$root/work/waferscan"
if [ -d "$checkout/../shared" ]; then
  cp -a "$checkout/../shared" "$root/work/shared"
fi
say "rehearsing .ci/run at $(git -C "$root/work/waferscan" rev-parse --short HEAD) in $root"

# 5. .ci/run, as CI runs it: CI=true, no standard input, the machine's environment.
log="$run/ci.log"
started=$(date +%s)
chroot "$root" /usr/bin/env CI=true \
  PATH="/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin" HOME=/root \
  /bin/bash -c 'cd /work/waferscan && exec bash .ci/run' </dev/null 2>&1 | tee "$log" || status=${PIPESTATUS[0]}
elapsed=$(( $(date +%s) - started ))

# 6. The figures: time and each test run's closing line.
say "finished in $((elapsed / 60)) min $((elapsed % 60)) s, exit status $status"
grep -E '^[0-9]+ (passed|failed)|^=+ .*(passed|failed).* =+$|[0-9]+ passed' "$log" | tail -n 4 >&2 || true
cp "$log" "$cache/ci-fresh-last.log"
say "log: $cache/ci-fresh-last.log"
