"""Run scan's playback: the layout scanned as headless runs do (``scanning``), then animated
(``ScanAnimation``) with its task panel, a slow scan's jabs and sweeps after (SPEC §13), and the
results dialogs once the animation reaches the end."""

from __future__ import annotations

from ..core.errors import WaferScanError
from . import preferences
from .dialogs import show_results_dialogs
from .scanning import changed_since, scan_and_store
from .session import (check_no_other_task_panel, doc_ref, last_result, record, report, session,
                      show_task_panel)

__all__ = ["run_scan", "replay_scan", "play_scan", "stop_pockets"]


def run_scan(doc, steps_per_frame=None, show_results=True, panel=True, duration_s=None):
    """Scan the document (as headless runs do) and animate the scan, with its task panel; the
    results table and the slot code open when the animation reaches the end. The animation
    lasts the preferences' playback time, unless ``duration_s`` or ``steps_per_frame`` (frames
    as fast as the machine draws them) is given."""
    if panel:
        check_no_other_task_panel()
    scene, result = scan_and_store(doc)
    if not result.layout.wafers:
        report(f"No wafer in {doc.Label} is tagged, so every slot reads empty. Select the "
               "wafers and use Tag as wafer, then Run scan again.")
    from ..core.scan.scan_result import BEAM_MISSES

    missed = [w for w in result.warnings if w.startswith(BEAM_MISSES)]
    if missed:  # said at once, not only when the animation ends: the map it gives is empty
        report(f"{doc.Label}: {missed[0][0].upper()}{missed[0][1:]}.", error=True)
    return play_scan(doc, result, steps_per_frame, show_results, panel, duration_s, scene)


def play_scan(doc, result, steps_per_frame=None, show_results=True, panel=True,
              duration_s=None, scene=None):
    """Animate ``result`` (a scan of ``doc``), with its task panel unless ``panel`` is False.
    ``scene``: the DocumentScene the scan read, unchanged since (None: read the document)."""
    from .animation import ScanAnimation
    from .scan_panel import ScanTaskPanel

    previous = session.animation
    if previous is not None:
        previous.stop()
    stop_pockets()  # a slow scan's jabs and sweeps still playing: this scan replaces them
    if steps_per_frame is None and duration_s is None:
        duration_s = preferences.playback_seconds()
    animation = ScanAnimation(doc, result, steps_per_frame or 10, duration_s, scene)
    session.animation = animation
    # The animation showed this result: its dialogs show it too.
    on_completed = (lambda: show_results_dialogs(doc, result=result)) if show_results else None
    if result.pockets:  # SPEC §13: then the jabs and sweeps, pocket by pocket
        from .pocket_animation import then_pockets

        on_completed = then_pockets(doc, result, on_completed, show_task_panel if panel
                                    else None, session)
    if panel:
        def replay(seconds):  # the panel's Replay, as the line a macro replays
            results = "" if show_results else ", show_results=False"
            record(f"replay_scan({doc_ref(doc)}, duration_s={seconds!r}{results})")
        scan_panel = ScanTaskPanel(animation, on_completed, replay)
        show_task_panel(scan_panel)
    elif on_completed is not None:
        animation.finished.connect(lambda: animation.completed and on_completed())
    animation.play()
    return animation


def stop_pockets(doc=None):
    """End the jabs and sweeps playing (of ``doc`` only, when given): the arm back in its
    start pose. They move the document (``pocket_animation``), which the next scan reads."""
    pockets = session.pocket_animation
    if pockets is not None and not pockets.ended and (doc is None or pockets.doc is doc):
        pockets.stop()


def replay_scan(doc, duration_s=None, show_results=True):
    """Play the document's last scan again from the start, in a fresh panel (what the scan
    panel's Replay does and records). When the document changed since that scan (settings
    applied in the panel, the carrier or the scanner edited, an Undo), it is scanned as it is
    now, and the panel says so; a document never scanned is scanned. Returns the animation, or
    None when the document cannot be scanned as it is (said to the user)."""
    result = last_result(doc)
    if result is not None and not changed_since(doc, result):
        return play_scan(doc, result, show_results=show_results, duration_s=duration_s)
    try:
        animation = run_scan(doc, show_results=show_results, duration_s=duration_s)
    except WaferScanError as exc:
        report(f"Replay: {doc.Label} cannot be scanned as it is now: {exc}", error=True)
        return None
    if result is not None:
        session.task_panel.say_rescanned()
    return animation
