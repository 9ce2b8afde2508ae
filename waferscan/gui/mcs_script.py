"""The MCS link driven from a script or a macro: what the MCS link panel's buttons record
(``mcs_panel``), as lines of ``waferscan.gui.commands`` that replay without the panel's
questions. ``start_mcs_link`` opens the panel when it is not open (``open_mcs_panel``);
the others act on the panel open on the document, or, for ``save_mcs_parameters``, write the
file without it."""

from __future__ import annotations

from pathlib import Path

import FreeCAD as App

from ..cad.reader import read_layout
from ..core.errors import InputError
from ..core.files.mcs import PARAMETERS, apply_parameters, parse_parameters
from ..core.files.text_files import atomic_write_text
from .dialogs import show_results_dialogs
from .mcs_panel import McsTaskPanel

__all__ = ["open_mcs_panel", "start_mcs_link", "stop_mcs_link", "store_mcs_scans",
           "save_mcs_parameters"]


def open_mcs_panel(doc, folder=None):
    """The MCS link's task panel on ``doc``, on ``folder`` (None: the preferences' folder).
    Returns the panel. (Here, not in ``dialogs``: the panel plays scans through ``playback``,
    which shows its results through ``dialogs``.)"""
    from .session import check_no_other_task_panel, show_task_panel

    check_no_other_task_panel()
    return show_task_panel(McsTaskPanel(doc, folder, show_results_dialogs))


def _open_panel(doc):
    """The MCS link's panel open on ``doc``, or None."""
    from .session import session

    panel = session.task_panel
    if isinstance(panel, McsTaskPanel) and panel.is_open() and panel.doc is doc:
        return panel
    return None


def _folder(folder):
    if not str(folder).strip():
        raise InputError("folder", None, "no MCS folder given")
    return Path(str(folder)).expanduser()


def start_mcs_link(doc, folder, store=False):
    """Watch ``folder``'s commands.txt for ``doc`` in the MCS link's panel (opened when it is
    not), as its Start watching does (and records): each new command carried out and answered
    in results.txt; with ``store``, each scan answered kept in the document as Run scan keeps
    it. Raises InputError when the folder cannot be watched (not there, held by another link);
    the panel says so too. Returns the panel."""
    folder = _folder(folder)
    panel = _open_panel(doc)
    if panel is None:
        panel = open_mcs_panel(doc, folder)
    elif panel.folder_path() != folder:
        panel.set_folder(folder)
    panel.store.setChecked(bool(store))
    if not panel.start():
        raise InputError(str(folder), None, f"not watching: {panel.state.text()}")
    return panel


def stop_mcs_link(doc):
    """Stop the MCS link watching for ``doc`` (its panel's Stop watching, which records this);
    new commands wait for the next start. Returns whether it was watching."""
    panel = _open_panel(doc)
    if panel is None or not panel.watching:
        App.Console.PrintMessage(f"WaferScan: the MCS link is not watching for {doc.Label}\n")
        return False
    panel.stop()
    return True


def store_mcs_scans(doc, store=True):
    """Whether each scan the MCS link answers for ``doc`` is also kept in the document, as Run
    scan keeps it (one undo step each): its panel's Store in document, clicked while watching,
    records this. Raises InputError when no MCS link panel is open on ``doc``."""
    panel = _open_panel(doc)
    if panel is None:
        raise InputError(doc.Label, None, "no MCS link panel is open on it: start_mcs_link("
                                          "..., store=True) opens one")
    panel.store.setChecked(bool(store))
    return panel


def save_mcs_parameters(doc, folder, text):
    """Write ``text`` as ``folder``'s parameters.txt (atomically, a last newline added), as the
    MCS link panel's Save does (and records), once it is checked as the link reads it: every
    line, then against ``doc``'s layout. Raises InputError (naming the line) when it is not
    valid or cannot be written; nothing is written then. An open panel on the folder shows the
    text saved. Returns the path written."""
    folder = _folder(folder)
    panel = _open_panel(doc)
    if panel is not None and panel.folder_path() == folder:
        if panel.editor.toPlainText() != text:
            panel._show_text(text)
        if not panel.save_parameters():
            raise InputError(str(folder / PARAMETERS), None, panel.check.text())
        return folder / PARAMETERS
    try:
        layout = read_layout(doc)
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 (a closed document)
        raise InputError("layout", None, f"the document cannot be read ({exc})") from None
    apply_parameters(layout, parse_parameters(text, str(folder / PARAMETERS)))
    if not folder.is_dir():
        raise InputError(str(folder), None, "no such folder")
    if text and not text.endswith("\n"):
        text += "\n"  # the link takes a last line without its newline as still being written
    try:
        atomic_write_text(folder / PARAMETERS, text)
    except OSError as exc:
        raise InputError(str(folder / PARAMETERS), None,
                         f"cannot write: {exc.strerror or exc}") from None
    App.Console.PrintMessage(f"WaferScan: wrote {folder / PARAMETERS}\n")
    return folder / PARAMETERS
