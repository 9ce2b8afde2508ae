"""Reading a user's text file: one rule for every reader (scenario, parameters.txt, MCS files),
and where the command line may write one."""

from __future__ import annotations

import errno
import os
import stat
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
