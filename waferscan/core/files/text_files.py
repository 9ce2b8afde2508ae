"""Reading a user's text file: one rule for every reader (scenario, parameters.txt, MCS files),
and where the command line may write one."""

from __future__ import annotations

import errno
import os
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path

from ..errors import InputError

# A scenario, a parameters.txt or a TOL.toml is kilobytes; a layout of 10,000 wafers written
# as a scenario is a few megabytes. More is not one of them (and /dev/zero never ends).
MAX_TEXT_BYTES = 64 << 20

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISSOCK, "a socket"), (stat.S_ISLNK, "a symbolic link"))


def kind_of(mode):
    """What a file of this st_mode is, in words ("a FIFO (named pipe)"), or "not a regular
    file"."""
    return next((words for test, words in _KINDS if test(mode)), "not a regular file")


def read_text(path, what=None, limit=MAX_TEXT_BYTES):
    """A text file's contents as str (a UTF-8 byte-order mark dropped); an InputError naming the
    file otherwise, with the line of the first byte that is not UTF-8. Only a regular file (a
    symlink to one is followed) of at most ``limit`` bytes is read: a FIFO is refused without
    waiting for a writer, a device without reading it. ``what`` names the file in the message
    ("cannot read the scenario: …"), else "cannot read: …"."""
    path = Path(path)
    reading = f"cannot read {what}" if what else "cannot read"
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as exc:
        raise InputError(path, None, f"{reading}: {exc.strerror}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise InputError(path, None, f"{reading}: {kind_of(mode)}, not a regular file")
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise InputError(path, None, f"{reading}: {exc.strerror}") from None
    finally:
        os.close(fd)
    if size > limit:
        raise InputError(path, None, f"{reading}: larger than {limit:,} bytes")
    raw = b"".join(chunks)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(path, raw[:exc.start].count(b"\n") + 1, "not UTF-8 text") from None


def check_output_path(path, option="--out"):
    """InputError unless ``path`` is a new path in an existing folder or a regular file (not
    followed through a symlink): writing replaces the file by rename, and a device node, a FIFO
    or a symlink must never be replaced by a regular file (as root, ``--out /dev/null`` would
    have replaced the system's node)."""
    path = Path(path)
    try:
        st = os.stat(path, follow_symlinks=False)
    except FileNotFoundError:
        if not path.parent.is_dir():
            raise InputError(path, None, f"cannot write: no folder {path.parent}") from None
        return
    except OSError as exc:
        raise InputError(path, None, f"{option}: {exc.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(path, None, f"{kind_of(st.st_mode)}, not a regular file: {option} "
                                     "writes a regular file or a new path (- for the standard "
                                     "output)")


def remove_stale_temporaries(folder, prefix, suffix):
    """Delete ``folder/prefix<pid>.*suffix`` files whose process <pid> is gone: the temporary
    files of a writer killed between writing and renaming (the real file was never touched by
    them). Another live writer's are left alone."""
    try:
        names = os.listdir(folder)
    except OSError:
        return
    for name in names:
        if not (name.startswith(prefix) and name.endswith(suffix)):
            continue
        pid = name[len(prefix):].split(".", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            os.kill(int(pid), 0)
            continue  # alive: its own
        except ProcessLookupError:
            pass
        except OSError as exc:
            if exc.errno != errno.ESRCH:
                continue  # alive, another user's
        try:
            os.unlink(Path(folder) / name)
        except OSError:
            pass

def flush_to_disk(path):
    """fsync a folder, after a rename in it (one that cannot be opened or flushed, on some
    shares, is left to the system)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextmanager
def replacing(path, prefix=None, suffix=".tmp", mode=None, sync_folder=True, remove_stale=True,
              create=True):
    """The one way a file is written here, whole or not at all: yields a temporary path beside
    ``path`` to write (``prefix`` + pid + a random part + ``suffix``; a writer that names the
    format by the suffix, as matplotlib and FreeCAD do, gets it), and when the block ends
    without an error flushes it to disk, gives it ``mode`` and renames it over ``path``, so that
    a reader sees the old file or the new one, never half of one; then flushes the folder
    (``sync_folder``; False: the caller does). On an error the temporary is removed and ``path``
    is as it was. The pid in the name: a writer killed before its rename leaves a file the next
    writer of this path removes (``remove_stale_temporaries``), never one a live writer still
    uses. ``create`` False: the temporary does not exist yet when yielded (a writer that would
    keep a backup of a file it finds there)."""
    path = Path(path)
    prefix = f".{path.name}." if prefix is None else prefix
    if remove_stale:
        remove_stale_temporaries(path.parent, prefix, suffix)
    fd, tmp = tempfile.mkstemp(prefix=f"{prefix}{os.getpid()}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    if not create:
        tmp.unlink()
    try:
        yield tmp
        if mode is not None:
            try:
                os.chmod(tmp, mode)
            except OSError:
                pass  # a share without Unix modes (CIFS, vfat): it has none to keep
        # the new file whole on disk before it takes the name (a failure here is the write's)
        fd = os.open(tmp, os.O_RDONLY | os.O_CLOEXEC)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    if sync_folder:
        flush_to_disk(path.parent)  # and the rename itself


def _mode_for(path):
    """The permission bits a file written by ``atomic_write_text`` gets: those of the regular
    file it replaces (not a symlink's), or for a new file what ``open`` would give (0666 less
    the umask)."""
    try:
        st = os.stat(path, follow_symlinks=False)
        if stat.S_ISREG(st.st_mode):  # not a symlink's 0777
            return stat.S_IMODE(st.st_mode)
        raise FileNotFoundError(path)
    except OSError:
        umask = os.umask(0o022)
        os.umask(umask)
        return 0o666 & ~umask


def atomic_write_text(path, text, sync_folder=True, remove_stale=True):
    """Replace ``path`` with ``text`` so that a reader sees the old file or the new one, never
    half of one (``replacing``).
    ``sync_folder``: flush the folder too (False: the caller does, as the MCS link does to
    report a failure of its own)."""
    path = Path(path)
    with replacing(path, mode=_mode_for(path), sync_folder=sync_folder,
                   remove_stale=remove_stale) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as handle:
            handle.write(text)
