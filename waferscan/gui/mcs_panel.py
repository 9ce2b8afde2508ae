"""The MCS link task panel: the folder of the three files, parameters.txt seen and edited with
validation, and watching commands.txt with the log of the commands carried out. The link itself,
and when it is polled, is ``link_watch.LinkWatch``'s: the headless link, so results.txt is
written exactly as ``waferscan watch`` writes it.

Once a scan is answered (an SCF, an SCS, a CAL's check scan), it is shown as Run scan shows
one: the results table and the slot code, and the arm animated through the scan in the 3D view
only (the document is not moved, so the next command reads it as the headless link does); with
"Store in document" checked, the results are also kept in the document as Run scan keeps them
(one undo step). The answer is written first: nothing shown holds it up. Of several answers
given in one poll, the last scan is shown (and stored): each would replace the one before.

Start watching, Stop watching, Save and Store in document while watching are recorded lines
(``mcs_script``: ``start_mcs_link``, ``stop_mcs_link``, ``save_mcs_parameters``,
``store_mcs_scans``): the
Python console shows them and a macro replays them without the panel's questions (the folder is
in the line); a started link's line opens the panel when it is not open. Another folder chosen,
or the panel closed, while watching stops the link as ``stop_mcs_link`` does, and records it.
From layout and Reload only fill the editor, and are not recorded."""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

import FreeCAD as App
from PySide import QtCore, QtGui

from ..addon import icon_path
from ..cad.reader import read_layout
from ..core.errors import InputError
from ..core.files.mcs import (
    COMMANDS,
    PARAMETERS,
    apply_parameters,
    format_parameters,
    parse_parameters,
)
from ..core.files.mcs_link import LockLost
from ..core.files.text_files import atomic_write_text
from . import preferences
from .inputs import folder_row
from .link_watch import LinkWatch
from .qt import ClosableTaskPanel
from .session import doc_ref, record

__all__ = ["McsTaskPanel"]

LOG_COLUMNS = ("Time", "Seq", "Command", "Status", "Code / message")


class _FittedTable(QtGui.QTableWidget):
    """A table whose last column takes what the others leave of its width, never more: no
    sideways scrolling in a narrow task panel (the full text is in each cell's tooltip)."""

    def resizeEvent(self, event):  # noqa: N802 (Qt's name)
        super().resizeEvent(event)
        self.fit_last_column()

    def fit_last_column(self):
        header = self.horizontalHeader()
        last = header.count() - 1
        others = sum(header.sectionSize(c) for c in range(last) if not header.isSectionHidden(c))
        header.resizeSection(last, max(header.minimumSectionSize(),
                                       self.viewport().width() - others))


class McsTaskPanel(ClosableTaskPanel):
    """Folder, parameters, start/stop watching, and the log of the commands carried out."""

    def __init__(self, doc, folder=None, show_results=None):
        self.doc = doc
        # How a scan answered is shown as Run scan shows it (``dialogs.show_results_dialogs``,
        # given by ``mcs_script.open_mcs_panel``, which opens this panel); None: not shown.
        self.show_results = show_results
        self.link = None  # the LinkWatch while watching
        self._polling = False
        # The text the panel last put in the editor, and the file's text as last seen.
        self._text_put_in_editor, self._text_in_folder = None, None
        self._folder = None
        self.form = QtGui.QWidget()
        self.form.setWindowTitle("WaferScan MCS link")
        self.form.setWindowIcon(QtGui.QIcon(icon_path("WaferScan_McsLink.svg")))
        folder_browse_row = self._folder_row(folder)
        parameters = self._parameters_box()
        watching = self._watching_box()
        layout = QtGui.QVBoxLayout(self.form)
        layout.addWidget(QtGui.QLabel(f"Layout: <b>{doc.Label}</b>"))
        layout.addWidget(QtGui.QLabel("Folder"))
        layout.addLayout(folder_browse_row)
        layout.addWidget(parameters)
        layout.addWidget(watching, 1)
        self.animation = None  # the last answered scan's animation (ScanAnimation)
        self._folder = self.folder.text()
        self.load_parameters()
        self._buttons()
        self.follow_document(doc)

    # --- building the panel ----------------------------------------------------------------

    def _folder_row(self, folder):
        """The MCS folder's field (the preferences' folder unless ``folder``) and Browse…."""
        self.folder = QtGui.QLineEdit(str(folder or preferences.mcs_folder()))
        self.folder.setToolTip("The folder where the MCS writes parameters.txt and commands.txt "
                               "and reads results.txt")
        self.folder.editingFinished.connect(self._folder_edited)
        return folder_row(self.folder, self.form, self._folder_chosen)

    def _parameters_box(self):
        """parameters.txt: its editor, what is wrong with it, and From layout, Reload, Save."""
        self.editor = QtGui.QPlainTextEdit()
        self.editor.setFont(QtGui.QFontDatabase.systemFont(QtGui.QFontDatabase.FixedFont))
        self.editor.setToolTip("parameters.txt: key = value, one per line; # starts a comment. "
                               "A key left out keeps the layout's value.")
        self.editor.setFixedHeight(110)
        self.editor.textChanged.connect(self.validate)
        self.check = QtGui.QLabel("")
        self.check.setWordWrap(True)
        self.save_button = QtGui.QPushButton("Save")
        self.save_button.setToolTip("Write parameters.txt (atomically) into the folder")
        self.save_button.clicked.connect(self._record_save)
        reload_button = QtGui.QPushButton("Reload")
        reload_button.setToolTip("Read parameters.txt again from the folder")
        reload_button.clicked.connect(self.load_parameters)
        from_layout = QtGui.QPushButton("From layout")
        from_layout.setToolTip("Fill in every parameter with the layout's own value")
        from_layout.clicked.connect(self.fill_from_layout)
        # Two buttons a row at most: the panel fits FreeCAD's default combo view (264 px).
        parameter_buttons = QtGui.QGridLayout()
        for index, button in enumerate((from_layout, reload_button, self.save_button)):
            parameter_buttons.addWidget(button, index // 2, index % 2)
        parameters = QtGui.QGroupBox("parameters.txt")
        parameters_box = QtGui.QVBoxLayout(parameters)
        parameters_box.addWidget(self.editor)
        parameters_box.addWidget(self.check)
        parameters_box.addLayout(parameter_buttons)
        return parameters

    def _watching_box(self):
        """commands.txt: start and stop watching, the link's state, and the log."""
        self.start_button = QtGui.QPushButton("Start watching")
        self.start_button.setToolTip("Carry out each new command of commands.txt and answer it "
                                     "in results.txt")
        self.stop_button = QtGui.QPushButton("Stop watching")
        self.stop_button.setToolTip("Stop carrying out commands; new ones wait for the next start")
        self.start_button.clicked.connect(self._record_start)
        self.stop_button.clicked.connect(self._record_stop)
        self.state = QtGui.QLabel("not watching")
        self.alive_while_shown = self.state
        self.state.setWordWrap(True)
        self.log = self._log_table()
        self.store = QtGui.QCheckBox("Store in document")
        self.store.setObjectName("store")
        self.store.setToolTip("Keep each scan the MCS asks for in the document's ScanResults "
                              "spreadsheet, as Run scan does (one undo step each); off: the "
                              "document is left as it is")
        self.store.clicked.connect(self._record_store)  # the user's clicks, not setChecked
        watch_buttons = QtGui.QVBoxLayout()
        watch_buttons.addWidget(self.start_button)
        watch_buttons.addWidget(self.stop_button)
        watching = QtGui.QGroupBox("commands.txt")
        watching_box = QtGui.QVBoxLayout(watching)
        watching_box.addLayout(watch_buttons)
        watching_box.addWidget(self.state)
        watching_box.addWidget(self.store)
        watching_box.addWidget(self.log)
        return watching

    def _log_table(self):
        """The commands carried out, one a row, fitted to a 264 px combo view."""
        log = _FittedTable(0, len(LOG_COLUMNS))
        log.setHorizontalHeaderLabels(list(LOG_COLUMNS))
        log.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
        log.verticalHeader().setVisible(False)
        log.verticalHeader().setDefaultSectionSize(20)
        log.horizontalHeader().setStretchLastSection(True)
        # The short columns as wide as their text, the message in what is left (its full text
        # in its tooltip): no sideways scrolling in a 264 px combo view.
        header = log.horizontalHeader()
        header.setDefaultSectionSize(40)  # first: Qt keeps a stretched section at least this wide
        for column in range(len(LOG_COLUMNS) - 1):
            header.setSectionResizeMode(column, QtGui.QHeaderView.ResizeToContents)
        header.setMinimumSectionSize(24)
        # Narrow headers and no time column on screen (each row's time is in its tooltips).
        log.horizontalHeaderItem(2).setText("Cmd")
        log.horizontalHeaderItem(2).setToolTip("Command")
        log.setColumnHidden(0, True)
        log.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarAlwaysOff)
        log.setWordWrap(False)
        log.setMinimumHeight(150)
        return log

    # --- the folder and parameters.txt -----------------------------------------------------

    def folder_path(self):
        return Path(self.folder.text().strip()).expanduser()

    def _ask_folder(self, why):
        """The folder field is empty: ask for a folder (FreeCAD's working directory is no
        place for the MCS files). True when one was chosen; the editor's text is kept."""
        chosen = QtGui.QFileDialog.getExistingDirectory(self.form, f"MCS folder: {why}", "")
        if not chosen:
            return False
        self.folder.setText(chosen)
        self._folder = self.folder.text()
        return True

    def set_folder(self, folder):
        """Another folder: watching stops (start again to watch the new one), its
        parameters.txt is shown."""
        if self.link is not None:
            self.stop()
        self.folder.setText(str(folder))
        self._folder = self.folder.text()
        self.load_parameters()

    def _folder_edited(self):
        # editingFinished also fires when the field merely loses focus: only a change counts.
        if self.folder.text() != self._folder:
            self._folder_chosen(self.folder.text())

    def _folder_chosen(self, folder):
        """The user chose another folder (typed, or Browse…): watching stops, as the recorded
        line ``stop_mcs_link`` says."""
        if self.link is not None:
            self._record_stop()
        self.set_folder(folder)

    def load_parameters(self):
        """Show the folder's parameters.txt; with none, the layout's values (not yet saved)."""
        path = self.folder_path() / PARAMETERS
        self._text_in_folder = None
        if self.folder.text().strip() and path.is_file():
            try:
                self._text_in_folder = path.read_bytes().decode("utf-8-sig")
                self._show_text(self._text_in_folder)
                return
            except (OSError, UnicodeDecodeError) as exc:
                self._show_check(False, f"{path}: cannot read: {exc}")
                return
        self.fill_from_layout()

    def _layout(self):
        """The document's layout now; an InputError when the document cannot be read (bad
        settings, or closed)."""
        try:
            return read_layout(self.doc)
        except InputError:
            raise
        except Exception as exc:  # the document was closed or its objects deleted
            raise InputError("layout", None, f"the document cannot be read any more "
                                             f"({type(exc).__name__}: {exc})") from None

    def fill_from_layout(self):
        try:
            self._show_text(format_parameters(self._layout()))
        except InputError as exc:
            self._show_check(False, str(exc))

    def _show_text(self, text):
        self._text_put_in_editor = text
        self.editor.setPlainText(text)

    def validate(self):
        """Check the text as the link will read it: every line, then against the layout. Marks
        the line of an error; returns the error, or None when the text is valid."""
        source = str(self.folder_path() / PARAMETERS)
        try:
            apply_parameters(self._layout(),
                             parse_parameters(self.editor.toPlainText(), source))
        except InputError as exc:
            self._show_check(False, str(exc), exc.line)
            return exc
        self._show_check(True, "valid: the next SCF or SCS will scan with these values")
        return None

    def _show_check(self, ok, message, line=None):
        self.check.setText(message)
        self.check.setStyleSheet("color: #1d7a2e;" if ok else "color: #c01010;")
        self.save_button.setEnabled(ok)
        marks = []
        if line is not None:
            mark = QtGui.QTextEdit.ExtraSelection()
            mark.format.setBackground(QtGui.QColor(255, 215, 215))
            mark.format.setProperty(QtGui.QTextFormat.FullWidthSelection, True)
            mark.cursor = QtGui.QTextCursor(
                self.editor.document().findBlockByNumber(line - 1))
            marks.append(mark)
        self.editor.setExtraSelections(marks)

    def _record_save(self):
        """Save, as the recorded line ``save_mcs_parameters(doc, folder, text)``: the text
        checked and the folder chosen (asked for when the field is empty) first, so the line
        asks nothing when replayed."""
        if self.validate() is not None:
            return
        if not self.folder.text().strip() and not self._ask_folder("where to save "
                                                                    "parameters.txt"):
            self._show_check(False, "no MCS folder: choose one with Browse…")
            return
        try:
            record(f"save_mcs_parameters({doc_ref(self.doc)}, {str(self.folder_path())!r}, "
                   f"{self.editor.toPlainText()!r})")
        except InputError:
            pass  # the check line says why

    def _record_start(self):
        """Start watching, as the recorded line ``start_mcs_link(doc, folder)`` (the folder
        asked for first when the field is empty: the line asks nothing when replayed)."""
        if not self.folder.text().strip():
            if not self._ask_folder("the folder to watch"):
                self._show_state("no MCS folder: choose one with Browse…", error=True)
                return
            if self.editor.toPlainText() == self._text_put_in_editor:  # not edited
                self.load_parameters()
        store = ", store=True" if self.store.isChecked() else ""
        try:
            record(f"start_mcs_link({doc_ref(self.doc)}, {str(self.folder_path())!r}{store})")
        except InputError:
            pass  # the state line says why

    def _record_stop(self):
        record(f"stop_mcs_link({doc_ref(self.doc)})")

    def _record_store(self, checked):
        """Store in document clicked while watching: the recorded line ``store_mcs_scans``
        (not watching, the next Start watching's line carries it)."""
        if self.link is not None:
            record(f"store_mcs_scans({doc_ref(self.doc)}, {bool(checked)!r})")

    def reject(self):
        """Close: a link watching stops first, as the recorded line ``stop_mcs_link``."""
        if self.link is not None:
            self._record_stop()
        return super().reject()

    def save_parameters(self):
        if self.validate() is not None:
            return False
        if not self.folder.text().strip() and not self._ask_folder("where to save "
                                                                    "parameters.txt"):
            self._show_check(False, "no MCS folder: choose one with Browse…")
            return False
        folder = self.folder_path()
        if not folder.is_dir():
            self._show_check(False, f"{folder}: no such folder")
            return False
        shown = text = self.editor.toPlainText()
        if text and not text.endswith("\n"):
            text += "\n"  # the link takes a last line without its newline as still being written
        try:
            atomic_write_text(folder / PARAMETERS, text)
        except OSError as exc:
            self._show_check(False, f"{folder / PARAMETERS}: cannot write: {exc.strerror or exc}")
            return False
        self._text_put_in_editor, self._text_in_folder = shown, text
        App.Console.PrintMessage(f"WaferScan: wrote {folder / PARAMETERS}\n")
        self._show_check(True, f"saved to {folder / PARAMETERS}")
        return True

    # --- watching commands.txt ------------------------------------------------------------

    def start(self, events=True, poll_ms=None):
        """Watch commands.txt: on file-system events (``events``) and every ``poll_ms`` ms
        (0: no polling). Returns False with a message when the folder is not there."""
        if not self.folder.text().strip():
            if not self._ask_folder("the folder to watch"):
                self._show_state("no MCS folder: choose one with Browse…", error=True)
                return False
            if self.editor.toPlainText() == self._text_put_in_editor:  # not edited: show the folder's
                self.load_parameters()
        folder = self.folder_path()
        if not folder.is_dir():
            self._show_state(f"{folder}: no such folder", error=True)
            return False
        self.stop()
        poll_ms = preferences.POLL_MS if poll_ms is None else poll_ms
        try:
            self.link = LinkWatch(self.doc, folder, self.poll, events, poll_ms,
                                  before_scan=self._stop_pockets)
        except InputError as exc:  # another link (waferscan watch) holds the folder
            self.stop()
            self._show_state(str(exc), error=True)
            return False
        self._show_state(f"watching {folder / COMMANDS} "
                         f"({' and '.join(self.link.how) or 'by hand'})")
        App.Console.PrintMessage(f"WaferScan: watching {folder / COMMANDS}\n")
        self._buttons()
        self.poll()
        return True

    def stop(self):
        if self.link is not None:
            self.link.close()  # gives the folder's lock back
            App.Console.PrintMessage(f"WaferScan: stopped watching {self.link.folder}\n")
        self.link = None
        # FreeCAD deletes the widgets of a panel it closed (the form itself may look alive).
        if self.is_open():
            self._show_state("not watching")
            self._buttons()

    @property
    def watching(self):
        return self.link is not None

    def poll(self):
        """Carry out what commands.txt holds that results.txt has not answered."""
        if self.link is None or self._polling:
            return []
        if not self.is_open():  # the panel was closed without us: nobody sees the link
            self.stop()
            return []
        self._polling = True
        try:
            answers = self.link.poll()
        except LockLost as exc:  # another link answers this folder now: this one stops
            self._polling = False
            self.stop()
            App.Console.PrintError(f"WaferScan: MCS link: {exc}\n")
            if self.is_open():
                self._show_state(f"stopped: {exc}", error=True)
                self._buttons()
            return []
        except Exception as exc:  # the folder went away, a disk error: say so, keep watching
            self._show_state(f"watching, but the last poll failed: {exc}", error=True)
            App.Console.PrintError(f"WaferScan: MCS link: {exc}\n")
            return []
        finally:
            self._polling = False
        if self.link is not None:
            self.link.watch_commands_file()
            self._follow_parameters()
        shown = None
        for answer in answers:
            self._add_log_row(answer)
            result = self.link.scanned(answer) if self.link is not None else None
            if result is not None:
                shown = (answer, result)
        if shown is not None:  # the last scan answered (an earlier one would be replaced)
            self.show_scan(*shown)
        return answers

    # --- a scan answered, shown as Run scan shows one -------------------------------------

    def show_scan(self, answer, result):
        """The results table and the slot code of ``result`` (answered to ``answer``), the
        arm animated through it, and, with Store checked, the results kept in the document.
        A failure to show is said in the log's state line; the answer is written already."""
        try:
            if self.store.isChecked():
                self._store(result)
            if self.show_results is not None:
                self.show_results(self.doc, result=result)
            self._animate(result)
        except Exception as exc:  # noqa: BLE001 (the document changed under us): said, not raised
            self._show_state(f"watching; seq {answer.seq} could not be shown: {exc}", error=True)
            App.Console.PrintError(f"WaferScan: MCS seq {answer.seq}: not shown: {exc}\n")

    def _store(self, result):
        """What Run scan stores (cad/results_sheet.py), as its one undo step."""
        from ..cad.results_sheet import store_in_document
        from .session import session, transaction

        session.results[self.doc.Name] = result
        with transaction(self.doc, "WaferScan results"):
            store_in_document(self.doc, result)

    def _animate(self, result):
        """The scan played as Run scan plays it (``playback.play_scan``, without its panel and
        dialogs: this panel and the results shown are the link's): the arm through the Z steps
        in the 3D view only, over the preferences' playback time, then back at its start pose;
        a slow scan's jabs and sweeps after, pocket by pocket. A newer scan replaces it. A
        layout whose moving objects the view cannot move on their own (a link's) is not
        animated: it would move the document, which the next command reads. The jabs and
        sweeps do move the document (as Run scan's): the next command the link carries out
        ends them first (``LinkWatch``'s ``before_scan``), the arm back in its start pose."""
        from ..cad.reader import DocumentScene
        from ..cad.stepping import mover_for
        from .animation import ViewPose
        from .playback import play_scan

        self.stop_animation()
        scene = DocumentScene.of(self.doc)
        pose = ViewPose.of(mover_for(scene, result.layout), result.layout.scan.start_z)
        if pose is None:
            return
        pose.release()
        # FreeCAD quitting while it plays ends it in time (qt.GuiDocumentClosing), as Run
        # scan's.
        self.animation = play_scan(self.doc, result, show_results=False, panel=False,
                                   duration_s=preferences.playback_seconds(), scene=scene)

    def _stop_pockets(self):
        from .playback import stop_pockets

        stop_pockets(self.doc)

    def stop_animation(self):
        from .playback import stop_pockets

        if self.animation is not None and not self.animation.ended:
            self.animation.stop()
        stop_pockets(self.doc)

    def _follow_parameters(self):
        """parameters.txt changed on disk (the MCS wrote it): show it, unless the user is
        editing it, then say so."""
        try:
            text = (self.link.folder / PARAMETERS).read_bytes().decode("utf-8-sig")
        except (OSError, UnicodeDecodeError):
            return
        if text == self._text_in_folder:
            return
        self._text_in_folder = text
        if self.editor.toPlainText() == self._text_put_in_editor:
            self._show_text(text)
        else:
            self._show_check(False, "parameters.txt changed on disk: Reload shows it (your "
                                    "edits are not saved)")

    def _add_log_row(self, answer):
        row = self.log.rowCount()
        self.log.insertRow(row)
        cells = (_dt.datetime.now().strftime("%H:%M:%S"), str(answer.seq), answer.command,
                 answer.status, answer.code or answer.message)
        for column, text in enumerate(cells):
            item = QtGui.QTableWidgetItem(text)
            item.setToolTip(f"{cells[0]}: {text}" if column else text)
            if column == 3:
                item.setForeground(QtGui.QColor(29, 122, 46) if answer.status == "ok"
                                   else QtGui.QColor(192, 16, 16))
            self.log.setItem(row, column, item)
        self.log.fit_last_column()
        self.log.scrollToBottom()
        line = (f"WaferScan: MCS seq {answer.seq} {answer.command}: {answer.status}"
                f"{' ' + answer.code if answer.code else ''}"
                f"{' (' + answer.message + ')' if answer.message else ''}\n")
        (App.Console.PrintMessage if answer.status == "ok" else App.Console.PrintWarning)(line)

    def log_rows(self):
        """The log's text, row by row (what a user sees)."""
        return [[self.log.item(r, c).text() for c in range(self.log.columnCount())]
                for r in range(self.log.rowCount())]

    def _show_state(self, text, error=False):
        self.state.setText(text)
        self.state.setStyleSheet("color: #c01010;" if error else "")

    def _buttons(self):
        self.start_button.setEnabled(self.link is None)
        self.stop_button.setEnabled(self.link is not None)

    def shut_down(self):
        self.stop()
        self.stop_animation()


