"""Layouts on disk: a scenario .toml is built into a document, a .FCStd is opened; documents are
saved atomically. Errors are ``InputError`` naming the file."""

from __future__ import annotations

import ctypes
import os
import re
import sys
import zipfile
from contextlib import contextmanager
from pathlib import Path

import FreeCAD as App

from ..core.errors import InputError
from ..core.files.scenario import key_line, read_scenario
from ..core.files.text_files import read_text, replacing
from .builder import build_document, document_preference_on


@contextmanager
def quiet_console():
    """FreeCAD quirk: in freecadcmd, loading a document and recomputing print a progress
    sequence ("Importing project files... (8 %)") on standard output, where it would mix with a
    command's results (--json). Standard output's file descriptor points at /dev/null
    meanwhile; C's buffers are flushed on both sides of the switch."""
    libc = ctypes.CDLL(None)
    try:
        sys.stdout.flush()
        libc.fflush(None)
        saved = os.dup(1)
    except (OSError, ValueError):
        yield  # no usable standard output: nothing to protect
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        yield
    finally:
        libc.fflush(None)
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def open_layout(path):
    """A document for a scenario (.toml, built in memory) or a layout (.FCStd, opened)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".toml":
        layout = read_scenario(path)
        before = set(App.listDocuments())
        try:
            with quiet_console():
                return build_document(layout, name=_document_name(path))
        except InputError as exc:
            robot = exc.source == "[robot]"  # a start pose the robot cannot be taught
            if not robot and (getattr(exc, "key", None) is None or exc.source != "[sensor]"):
                raise
            # A [robot] that contradicts [sensor] (cad.robot.SensorConflict), or one that
            # cannot reach the beam from its base: name the line.
            for name in set(App.listDocuments()) - before:  # the half-built document
                App.closeDocument(name)
            text = read_text(path, "the scenario")
            if robot:
                raise InputError(path, key_line(text, "robot", "base"),
                                 f"[robot] {exc.message}") from None
            raise InputError(path, key_line(text, "sensor", exc.key),
                             f"[sensor] {exc.message}") from None
    if suffix != ".fcstd":
        raise InputError(path, None, "expected a scenario .toml or a FreeCAD layout .FCStd")
    if not path.is_file():
        raise InputError(path, None, "no such file")
    check_whole_numbers(path)
    try:
        with quiet_console():
            return App.openDocument(str(path.resolve()))
    except Exception as exc:  # FreeCAD raises plain Exception/IOError for unreadable files
        raise InputError(path, None, f"FreeCAD cannot open it: {exc}") from None


_INTEGER_PROPERTY = re.compile(r'<Property name="([^"]{1,200})" type="App::PropertyInteger"'
                               r'[^>]{0,2000}>\s*<Integer value="([^"]{0,200})"')
_OBJECT = '<Object name="'
MAX_DOCUMENT_XML = 1 << 30  # bytes of Document.xml checked; a larger one is FreeCAD's to read


def check_whole_numbers(path):
    """InputError when an integer property of the .FCStd's Document.xml is not written as a
    whole number: FreeCAD reads ``SlotCount "1e3"`` as 1 (the digits before the first other
    character), silently. A file that is not a readable .FCStd is left to FreeCAD's own error."""
    try:
        with zipfile.ZipFile(path) as archive:
            info = archive.getinfo("Document.xml")
            if info.file_size > MAX_DOCUMENT_XML:
                return
            text = archive.read(info).decode("utf-8", errors="replace")
    except (OSError, KeyError, zipfile.BadZipFile, RuntimeError, ValueError):
        return
    for match in _INTEGER_PROPERTY.finditer(text):
        value = match.group(2)
        if re.fullmatch(r"-?[0-9]{1,18}", value):
            continue
        start = text.rfind(_OBJECT, 0, match.start())
        owner = text[start + len(_OBJECT):text.find('"', start + len(_OBJECT))][:60] \
            if start >= 0 else "?"
        line = text.count("\n", 0, match.start(2)) + 1
        raise InputError(path, None, f"Document.xml:{line}: {owner}.{match.group(1)} = "
                                     f"{value[:40]!r}: not a whole number")


def setting_error(message, source, parameters, table, key):
    """InputError for a problem with the scan setting ``key`` found while scanning: named by
    the parameters.txt line that set it, else by its line in a scenario ``source`` (.toml),
    else by the file (a layout .FCStd keeps it as a property)."""
    if parameters is not None and key in parameters.values:
        return InputError(parameters.source, parameters.lines.get(key), f"{key}: {message}")
    line = None
    if str(source).lower().endswith(".toml"):
        try:
            line = key_line(read_text(source), table, key)
        except InputError:
            pass
    return InputError(source, line, f"{key}: {message}")


def _document_name(path):
    name = "".join(c if c.isalnum() else "_" for c in path.stem) or "Layout"
    return name if name[0].isalpha() else "L" + name


def done_with(doc):
    """Close ``doc``, unless this process ends with its command (cad.CLOSE_AFTER_USE): then
    only its transient folder (FreeCAD's cache, which closing would remove and the process's
    end does not) is removed when the process ends."""
    from .. import cad

    if cad.CLOSE_AFTER_USE:
        App.closeDocument(doc.Name)
    else:
        import atexit
        import shutil

        atexit.register(shutil.rmtree, doc.TransientDir, ignore_errors=True)


@contextmanager
def opened_layout(path):
    """``open_layout`` as a context: the document is closed afterwards (``done_with``)."""
    doc = open_layout(path)
    try:
        yield doc
    finally:
        done_with(doc)


@contextmanager
def binary_shapes():
    """Shapes saved as OpenCASCADE's binary BRep (``.bin``, read by every FreeCAD since 0.17)
    instead of its text form: a layout of 10,000 wafers and 400 carriers is written in about
    half the time and opened a little faster. The preference Document/SaveBinaryBrep is put
    back as it was afterwards."""
    with document_preference_on("SaveBinaryBrep"):
        yield


def save_document(doc, path):
    """Save the document as ``path`` without ever leaving half a file there: save beside it
    under a temporary name, then rename over."""
    path = Path(path)
    if path.suffix.lower() != ".fcstd":
        raise InputError(path, None, "a FreeCAD layout is saved as .FCStd")
    if not path.parent.is_dir():
        raise InputError(path, None, f"no folder {path.parent}")
    try:
        # A save killed before its rename left its temporary file (the pid is in its name): the
        # next removes it. FreeCAD keeps a backup of a file it saves over: none there yet.
        with replacing(path, prefix=f".{path.stem}.", suffix=".tmp.FCStd", create=False) \
                as temporary:
            with binary_shapes(), _origins_hidden(doc):
                doc.saveAs(str(temporary))
            if not App.GuiUp:
                _add_view_data(doc, temporary)
    except Exception as exc:  # FreeCAD reports a failed save as a plain Exception
        raise InputError(path, None, f"cannot write: {getattr(exc, 'strerror', None) or exc}") \
            from None


def xml_attribute(text):
    """``text`` as a double-quoted XML attribute value. (xml.sax.saxutils.quoteattr does this
    too, but importing it pulls in urllib, http.client and email: ~20 ms of every headless
    start-up, for a save that may not even happen.)"""
    for plain, escaped in (("&", "&amp;"), ("<", "&lt;"), (">", "&gt;"), ('"', "&quot;"),
                           ("\n", "&#10;"), ("\r", "&#13;"), ("\t", "&#9;")):
        text = text.replace(plain, escaped)
    return f'"{text}"'


ORIGIN_TYPES = ("App::Origin", "App::Line", "App::Plane")  # an App::Part's origin features


@contextmanager
def _origins_hidden(doc):
    """Without the GUI, the Parts' origins saved hidden, as the GUI makes them: the GUI opening
    the file shows an object as its own Visibility (Document.xml) says, whatever the view data
    (GuiDocument.xml) says. Put back afterwards: saving changes nothing in the document."""
    shown = [] if App.GuiUp else [obj for obj in doc.Objects
                                   if obj.TypeId in ORIGIN_TYPES and obj.Visibility]
    for obj in shown:
        obj.Visibility = False
    try:
        yield
    finally:
        for obj in shown:
            obj.Visibility = True


def _add_view_data(doc, path):
    """FreeCAD quirk: a document saved without the GUI has no GuiDocument.xml, and the GUI then
    opens its C++ features (cylinders, parts, link solids) hidden. Write the view data FreeCAD
    would have written: each object shown as its own Visibility says, but an App::Part's origin
    (its axes and planes) hidden, as the GUI makes it. Left out, the GUI showed the origins:
    the robot's planes, axes and their 3D labels over the scene, resized at every frame of an
    animated scan (FreeCAD sizes an origin to its Part's bounding box, which the moving links
    change), their labels drawn in a pass of their own (annotations, after the scene)."""
    rows = []
    for obj in doc.Objects:
        if obj.TypeId in ORIGIN_TYPES:
            shown = "false"
        else:
            shown = "true" if getattr(obj, "Visibility", True) else "false"
        rows.append(f'        <ViewProvider name={xml_attribute(obj.Name)} expanded="0">\n'
                    f'            <Properties Count="1">\n'
                    f'                <Property name="Visibility" type="App::PropertyBool">\n'
                    f'                    <Bool value="{shown}"/>\n'
                    f'                </Property>\n'
                    f'            </Properties>\n'
                    f'        </ViewProvider>')
    # FreeCAD 0.20 reads a <Camera> element after the view providers and reports the file as
    # failed to read without one (the report view pops up); empty settings keep the 3D view's
    # own camera, as a new document has.
    xml = ('<?xml version=\'1.0\' encoding=\'utf-8\'?>\n<Document SchemaVersion="1">\n'
           f'    <ViewProviderData Count="{len(rows)}">\n' + "\n".join(rows) +
           '\n    </ViewProviderData>\n    <Camera settings=""/>\n</Document>\n')
    with zipfile.ZipFile(path, "a", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("GuiDocument.xml", xml)
