#!/usr/bin/env bash
# Set up WaferScan on Debian bookworm: system packages, the project's venv, FreeCAD's modules
# in that venv, and the addon's link in FreeCAD's user Mod folder. Safe to run again: each step
# is skipped when its result is already in place.
set -euo pipefail

cd "$(dirname "$0")/.."
root=$(pwd -P)
# One set-up at a time for this checkout: two at once (make demo and make test started together)
# would build the same venv under each other.
exec 9>"$root/.setup.lock"
flock 9
# WAFERSCAN_VENV: a venv elsewhere (the FreeCAD 1.0 root keeps its own; see freecad1-run.sh).
venv=${WAFERSCAN_VENV:-$root/.venv}
python=/usr/bin/python3        # FreeCAD is built against Debian's Python: the venv must use it too

say() { printf 'setup: %s\n' "$*"; }

# 1. System packages (apt only when something is missing).
missing=()
command -v freecadcmd >/dev/null 2>&1 || missing+=(freecad-python3)
command -v xvfb-run >/dev/null 2>&1 || missing+=(xvfb)
command -v xauth >/dev/null 2>&1 || missing+=(xauth)
# The tests: git (the Addon Manager test clones the addon), strace, debootstrap (to build make
# test-freecad1's root; not inside that root, where freecad1-run.sh sets WAFERSCAN_VENV), and
# the certificate authorities pip needs (a minbase system has none).
command -v git >/dev/null 2>&1 || missing+=(git)
command -v strace >/dev/null 2>&1 || missing+=(strace)   # the test that --store flushes to disk
[ -n "${WAFERSCAN_VENV:-}" ] || command -v debootstrap >/dev/null 2>&1 || missing+=(debootstrap)
[ -s /etc/ssl/certs/ca-certificates.crt ] && dpkg-query -W -f='${Status}' ca-certificates 2>/dev/null |
  grep -q 'install ok installed' || missing+=(ca-certificates)
dpkg-query -W -f='${Status}' python3-venv 2>/dev/null | grep -q 'install ok installed' \
  || missing+=(python3-venv)
if ((${#missing[@]})); then
  say "installing system packages (missing: ${missing[*]})"
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  # apt's own output goes to stderr: nothing a set-up step prints may reach a value another reads.
  "${sudo[@]}" apt-get update >&2
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    "${missing[@]}" >&2
fi

# 2. Ask FreeCAD where its Python modules and its user data folder are (one start-up).
fc_info=$(freecadcmd -c "import os, FreeCAD, Part
print('WS_LIB=' + os.path.dirname(Part.__file__))
print('WS_MOD=' + os.path.join(FreeCAD.getHomePath(), 'Mod'))
print('WS_USER=' + FreeCAD.getUserAppDataDir())" 2>/dev/null) || true
fc_lib=$(sed -n 's/^WS_LIB=//p' <<<"$fc_info")
fc_mod=$(sed -n 's/^WS_MOD=//p' <<<"$fc_info")
fc_user=$(sed -n 's/^WS_USER=//p' <<<"$fc_info")
if [ -z "$fc_lib" ] || [ -z "$fc_mod" ] || [ -z "$fc_user" ]; then
  say "error: freecadcmd did not report its module folder and user folder:" >&2
  printf '%s\n' "$fc_info" >&2
  exit 1
fi

# 3. The venv. --system-site-packages: it sees Debian's PySide2, pivy and FreeCAD's dependencies.
# A venv is whole once .waferscan-venv.created is written: one cut short (Ctrl-C, a full disk)
# is made again rather than used without pip. (A venv made before the marker existed is whole
# if its pip imports.)
if [ -e "$venv" ] && [ ! -e "$venv/.waferscan-venv.created" ]; then
  if "$venv/bin/python" -c "import pip" >/dev/null 2>&1; then
    : >"$venv/.waferscan-venv.created"
  else
    say "removing $venv: its creation did not finish"
    rm -rf "$venv"
  fi
fi
if [ ! -x "$venv/bin/python" ]; then
  say "creating $venv"
  "$python" -m venv --system-site-packages "$venv"
  : >"$venv/.waferscan-venv.created"
fi
site_packages=$("$venv/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")

# 4. The package (editable) with its pinned dependencies; redone only when pyproject.toml changes.
stamp="$venv/.waferscan-install.stamp"
want=$(sha256sum pyproject.toml | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  say "installing waferscan (editable) and its dependencies into the venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -e '.[dev]'
  printf '%s\n' "$want" >"$stamp"
fi

# 5. FreeCAD's modules in the venv's Python: `import FreeCAD, Part` works there, and so do the
#    workbenches' Python packages (PartDesign, Spreadsheet...) that a user's document may need.
#    FreeCAD 1.0's Part imports its PartEnums module (in Mod/Part) when it makes a compound; in
#    plain Python, without that folder on the path, the process exits with status 1, silently.
pth="$site_packages/freecad.pth"
want_pth=$(printf '%s\n%s' "$fc_lib" "$fc_mod")
[ -d "$fc_mod/Part" ] && want_pth=$(printf '%s\n%s' "$want_pth" "$fc_mod/Part")
if [ "$(cat "$pth" 2>/dev/null)" != "$want_pth" ]; then
  say "adding $fc_lib and $fc_mod to the venv ($pth)"
  printf '%s\n' "$want_pth" >"$pth"
fi

# 6. The addon in FreeCAD's user Mod folder, as a link to this checkout.
#    A checkout that is itself that folder (cloned there, as the Addon Manager does) needs none.
link="${fc_user%/}/Mod/WaferScan"
if [ "$(cd "$link" 2>/dev/null && pwd -P)" = "$root" ] && [ ! -L "$link" ]; then
  link="$root"
elif [ "$(readlink "$link" 2>/dev/null)" != "$root" ]; then
  if [ -e "$link" ] && [ ! -L "$link" ]; then
    say "error: $link exists and is not a link; move it away and run again" >&2
    exit 1
  fi
  say "linking $link -> $root"
  mkdir -p "$(dirname "$link")"
  ln -sfn "$root" "$link"
fi

say "ready (venv: $venv, addon: $link)"
