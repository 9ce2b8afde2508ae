"""The FreeCAD 1.0 root's path handed from scripts/freecad1-root.sh to scripts/freecad1-run.sh,
on a machine where nothing was installed: debootstrap is missing, so the root script installs it
with apt-get, then builds the root. Every system command is a stand-in (first on PATH) that
prints chatter on its standard output, as apt-get does; the path must reach freecad1-run.sh
intact and nothing else with it (on a new machine apt-get's lines became the "path":
`/var/cache/waferscan/...run-lock: No such file or directory`)."""

import os
import shutil
import stat
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CHATTER = "Reading package lists... Done\nBuilding dependency tree... Done\n"

# Each stand-in logs its arguments to $STANDIN_LOG and prints chatter on stdout.
STANDINS = {
    "apt-get": f"""
printf '%s\\n' "apt-get $*" >>"$STANDIN_LOG"
printf '{CHATTER}'
echo "Setting up $* ..."
case " $* " in
  *" install "*debootstrap*)   # what apt-get would install: debootstrap (another stand-in)
    cp "$STANDIN_DIR/debootstrap.pending" "$STANDIN_DIR/debootstrap"
    chmod +x "$STANDIN_DIR/debootstrap" ;;
esac
""",
    "debootstrap.pending": """
printf '%s\\n' "debootstrap $*" >>"$STANDIN_LOG"
echo "I: Retrieving InRelease"
echo "I: Base system installed successfully."
target=$3
mkdir -p "$target/etc/ssl" "$target/proc" "$target/dev" "$target/usr/bin"
""",
    "chroot": """
printf '%s\\n' "chroot $*" >>"$STANDIN_LOG"
case "$*" in
  *dpkg-query*) echo "1.0.0+dfsg-1" ;;          # the version the root records as .complete
  *) printf 'chroot chatter\\n'; echo "ran in the root: ${*: -1}" ;;
esac
""",
    "mount": 'printf \'%s\\n\' "mount $*" >>"$STANDIN_LOG"; echo "mount: done"',
    "umount": 'printf \'%s\\n\' "umount $*" >>"$STANDIN_LOG"; echo "umount: done"',
    "id": 'echo 0',
}


@pytest.fixture
def machine(tmp_path):
    """A checkout's scripts/, stand-ins first on PATH, no debootstrap, an empty cache."""
    checkout = tmp_path / "checkout"
    shutil.copytree(REPO / "scripts", checkout / "scripts")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name, body in STANDINS.items():
        path = bin_dir / name
        path.write_text("#!/usr/bin/env bash\n" + body.lstrip())
        if "." not in name:
            path.chmod(path.stat().st_mode | stat.S_IXUSR)
    # A PATH without the machine's own debootstrap: the folders of the few real tools used.
    real = tmp_path / "real"
    real.mkdir()
    for tool in ("bash", "env", "sh", "cat", "cp", "mkdir", "mv", "rm", "sed", "awk", "sort",
                 "head", "cut", "du", "date", "sha256sum", "flock", "findmnt", "chmod", "dirname",
                 "wc", "tr", "readlink", "ls", "grep", "sleep"):
        found = shutil.which(tool)
        assert found, tool
        (real / tool).symlink_to(found)
    log = tmp_path / "standins.log"
    env = {"PATH": f"{bin_dir}:{real}", "HOME": str(tmp_path), "LANG": "C.UTF-8",
           "STANDIN_LOG": str(log), "STANDIN_DIR": str(bin_dir),
           "WAFERSCAN_CACHE": str(tmp_path / "cache"),
           "DEBIAN_MIRROR": "http://mirror.invalid/debian"}
    return checkout, env, log


def test_the_root_script_prints_the_path_alone_after_installing_debootstrap(machine):
    checkout, env, log = machine
    proc = subprocess.run([str(checkout / "scripts" / "freecad1-root.sh")], env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    standins = log.read_text()
    assert "apt-get install -y --no-install-recommends debootstrap" in standins  # the new machine
    assert "debootstrap --variant=minbase trixie" in standins
    (path,) = proc.stdout.splitlines()  # one line, nothing else
    root = Path(path)
    assert root.parent == Path(env["WAFERSCAN_CACHE"]) and root.name.startswith("trixie-freecad1-")
    assert (root / ".complete").read_text() == "1.0.0+dfsg-1\n"
    # The chatter went to stderr, where a person still sees it.
    assert "Reading package lists... Done" in proc.stderr and "Base system installed" in proc.stderr
    # Run again with the root in place: the same path, and apt-get is not asked again.
    again = subprocess.run([str(checkout / "scripts" / "freecad1-root.sh")], env=env,
                           capture_output=True, text=True, timeout=60)
    assert again.returncode == 0 and again.stdout == proc.stdout
    assert log.read_text() == standins


def test_the_run_script_gets_the_path_and_runs_the_command_in_the_root(machine):
    checkout, env, log = machine
    proc = subprocess.run([str(checkout / "scripts" / "freecad1-run.sh"), "echo", "hello"],
                          env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    (root,) = Path(env["WAFERSCAN_CACHE"]).glob("trixie-freecad1-*[!k]")  # not the run-lock
    assert (root / ".complete").exists()
    assert Path(f"{root}.run-lock").exists()
    runs = [line for line in log.read_text().splitlines()
            if line.startswith("chroot ") and "dpkg-query" not in line and "apt-get" not in line]
    (run,) = runs
    assert run.startswith(f"chroot {root} /usr/bin/env -i ") and run.endswith(" echo hello")
    assert "ran in the root: hello" in proc.stdout
    # Every mount made (in the root and, while building, in the partial one) was undone.
    lines = log.read_text().splitlines()
    mounts = {line.split()[-1] for line in lines if line.startswith("mount ")}
    umounts = {word for line in lines if line.startswith("umount ")
               for word in line.split()[1:] if word.startswith("/")}
    assert len(mounts) == 7 and mounts <= umounts


def test_the_run_script_refuses_a_path_with_chatter_in_it(machine):
    """A root script that leaks a line onto stdout (as the old one did) is caught, named and
    refused before any lock, mount or chroot."""
    checkout, env, log = machine
    root_script = checkout / "scripts" / "freecad1-root.sh"
    cache = Path(env["WAFERSCAN_CACHE"])
    fake_root = cache / "trixie-freecad1-fake"
    (fake_root).mkdir(parents=True)
    (fake_root / ".complete").write_text("1.0\n")
    root_script.write_text(f"#!/usr/bin/env bash\necho 'Reading package lists... Done'\n"
                           f"echo '{fake_root}'\n")
    proc = subprocess.run([str(checkout / "scripts" / "freecad1-run.sh"), "true"], env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1
    assert "freecad1-run: error: scripts/freecad1-root.sh printed no finished root's path" in \
        proc.stderr
    assert "Reading package lists... Done" in proc.stderr  # what it got, shown
    assert not log.exists() or "chroot" not in log.read_text()
    assert list(cache.glob("*.run-lock")) == []
    assert os.listdir(fake_root) == [".complete"]
