"""Run scan on a document that is not ready says, in a message box, what to tag next."""

from pathlib import Path

import pytest

PROBE = Path(__file__).resolve().with_name("guidance_probe.py")


@pytest.fixture(scope="module")
def guidance(run_gui_probe):
    return run_gui_probe(PROBE)


def test_an_untagged_document_names_every_role_still_missing(guidance):
    (text,) = guidance["untagged"]
    assert "Nothing in it is tagged yet" in text
    assert "Tag as carrier" in text and "Tag as scanner" in text and "Tag as wafer" in text
    assert guidance["untagged_panel"] is False


def test_a_missing_scanner_is_named_alone(guidance):
    (text,) = guidance["no_scanner"]
    assert "Tag as scanner" in text and "Tag as carrier" not in text


def test_no_wafer_tagged_is_said_and_every_slot_reads_empty(guidance):
    assert any("No wafer in Untagged is tagged" in text for text in guidance["no_wafers"])
    assert set(guidance["no_wafers_code"]) == {"0"} and len(guidance["no_wafers_code"]) == 25
