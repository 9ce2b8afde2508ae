"""Reading a user's text file: one rule for every reader (scenario, parameters.txt, MCS files)."""

from __future__ import annotations

from pathlib import Path

from .errors import InputError


def read_text(path, what=None):
    """A text file's contents as str (a UTF-8 byte-order mark dropped); an InputError naming the
    file otherwise, with the line of the first byte that is not UTF-8. ``what`` names the file
    in the message ("cannot read the scenario: …"), else "cannot read: …"."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        reading = f"cannot read {what}" if what else "cannot read"
        raise InputError(path, None, f"{reading}: {exc.strerror}") from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(path, raw[:exc.start].count(b"\n") + 1, "not UTF-8 text") from None
