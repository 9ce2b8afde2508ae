"""The Host link panel (SPEC §14) in a real FreeCAD GUI, under Xvfb, against secsgem's own GEM
host: a carrier loaded from the panel is scanned, its map reported and verified; the panel's
table and the slot-code dialog follow the host's verification, OK and FAILED."""

from pathlib import Path

from hsms_peers import free_port

from waferscan.host.ids import DEFAULTS

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("host_probe.py")
ARTIFACTS = REPO / "test-artifacts"
EVENTS = DEFAULTS["events"]
REASON = ("SlotMap slot 3: the host expects 3 (correctly occupied), the equipment read 1 "
          "(empty)")


def test_a_carrier_loaded_in_the_panel_is_verified_by_the_host(run_gui_probe):
    port = free_port()
    gui = run_gui_probe(PROBE, WAFERSCAN_GUI_PORT=str(port),
                        WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))
    assert gui["panel_class"] == "HostLinkPanel"
    assert gui["acks"] == [0, 0, 0]
    assert gui["state_started"] == f"listening on 127.0.0.1:{port}: no host connected"
    assert gui["state_connected"] == (f"listening on 127.0.0.1:{port}: a host is connected and "
                                      "communicating")
    # [CEID, CarrierID, SlotMapStatus] of each event the host received, in order
    assert gui["events"] == [
        [EVENTS["slot_map_not_read"], "FOUP0042", 0], [EVENTS["waiting_for_host"], "FOUP0042", 1],
        [EVENTS["verification_ok"], "FOUP0042", 2],
        [EVENTS["slot_map_not_read"], "FOUP0043", 0], [EVENTS["waiting_for_host"], "FOUP0043", 1],
        [EVENTS["verification_failed"], "FOUP0043", 3]]
    assert gui["replies"] == [{"CAACK": 0, "ERRORS": []},
                              {"CAACK": 3, "ERRORS": [{"ERRCODE": 9, "ERRTEXT": REASON}]}]
    assert gui["dialog_code"] == "1101221001220001010000010"
    assert gui["dialog_first"] == "Host verification of FOUP0042: VERIFICATION OK"
    assert gui["dialog_second"] == f"Host verification of FOUP0043: VERIFICATION FAILED\n{REASON}"
    assert gui["rows_first"] == [["1 (LP1)", "FOUP0042", "VERIFICATION OK",
                                  "1101221001220001010000010"]]
    assert gui["rows_second"] == [["1 (LP1)", "FOUP0043", "VERIFICATION FAILED",
                                   "1101221001220001010000010"]]
    assert gui["status_tip"] == f"VERIFICATION FAILED: {REASON}"
    # secsgem's warnings (both sides sending S1F13 at once) do not reach the Report view, which
    # holds FreeCAD's own lines (the layout built)
    assert gui["report_view_text"] > 0 and gui["report_view_warnings"] == []
    assert all(gui["log_has"].values()), gui["log_has"]
    assert gui["label_fits"] == [True, True]  # the verification's lines are not cut
    assert gui["port_free_after_close"] is True
    for name in ("gui-host-panel.png", "gui-host-dialog-ok.png", "gui-host-dialog-failed.png"):
        assert (ARTIFACTS / name).stat().st_size > 1000
