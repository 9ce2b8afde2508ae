# Shared by freecad1-root.sh and ci-fresh.sh (sourced, not run): the Debian mirror this machine's
# apt uses, debootstrap installed on demand, and mounts undone and roots removed safely.
# Everything here writes to standard error: a caller's standard output stays its own.
# The caller defines say() (its own message prefix) before sourcing this file.

# debian_mirror: the mirror this machine's apt uses (deb822 sources first, then the one-line
# format); DEBIAN_MIRROR overrides it. Prints it, or fails with a message.
debian_mirror() {
  local mirror=${DEBIAN_MIRROR:-}
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
    return 1
  fi
  printf '%s\n' "$mirror"
}

# ensure_debootstrap: installs debootstrap with apt when it is missing (apt's output to stderr).
ensure_debootstrap() {
  command -v debootstrap >/dev/null 2>&1 && return 0
  say "installing debootstrap"
  apt-get update >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends debootstrap >&2
}

# mounts_under DIR: the mount points at DIR or below it, deepest first.
mounts_under() {
  findmnt -rn -o TARGET | awk -v d="$1" 'index($0, d "/") == 1 || $0 == d' | sort -r
}

# unmount_under DIR: lazily unmounts whatever is mounted at DIR or below it.
unmount_under() {
  local target
  mounts_under "$1" | while read -r target; do umount -l "$target" || true; done
}

# remove_root DIR: removes a root, never through a mount (a root left mounted by a killed run
# would otherwise take a bind-mounted checkout with it).
remove_root() {
  local dir=$1
  if [ -n "$(mounts_under "$dir")" ]; then
    say "unmounting what a previous run left mounted in $dir"
    unmount_under "$dir"
  fi
  # A bind mount from the same disk would not stop rm --one-file-system: check, then remove.
  if [ -n "$(mounts_under "$dir")" ]; then
    say "error: something is still mounted in $dir; not removing it"
    return 1
  fi
  rm -rf --one-file-system "$dir"
}

# processes_in DIR: the processes whose root directory is DIR (they run chrooted there).
processes_in() {
  local proc
  for proc in /proc/[0-9]*; do
    [ "$(readlink "$proc/root" 2>/dev/null)" = "$1" ] && printf '%s\n' "${proc#/proc/}"
  done
  return 0
}

# end_processes_in DIR WHAT: ends the processes still running chrooted in DIR, naming each
# (WHAT says after what); returns 1 if there were any.
end_processes_in() {
  local pids
  pids=$(processes_in "$1")
  [ -n "$pids" ] || return 0
  say "error: processes left running in $1 after $2:"
  local pid
  for pid in $pids; do   # from /proc: a minbase system has no ps
    printf '  %s %s\n' "$pid" "$(tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null)" >&2
  done
  kill -TERM $pids 2>/dev/null || true
  sleep 2
  pids=$(processes_in "$1")
  [ -z "$pids" ] || kill -KILL $pids 2>/dev/null || true
  return 1
}
