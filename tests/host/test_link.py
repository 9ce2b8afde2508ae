"""The host link's load ports with their scans (``host.link``), with a stand-in scan: a carrier
cancelled by the host while it is being scanned, and the order of the reports."""

from types import SimpleNamespace

import pytest

from waferscan.core.errors import InputError
from waferscan.host.e87 import SLOT_MAP_NOT_READ, WAITING_FOR_HOST
from waferscan.host.ids import default_ids
from waferscan.host.link import HostLink

PAPER = SimpleNamespace(code="1101221001220001010000010", e87="3313553113551113131111131",
                        warnings=())


def test_a_carrier_cancelled_while_it_is_scanned_is_not_reported_and_nothing_fails():
    reported = []

    def scan(name):  # the host cancels FOUP1 on its SLOT MAP NOT READ event
        if link.ports.port(1).carrier_id == "FOUP1":
            assert link.carrier_action("CancelCarrier", "FOUP1", 1, []).caack == 0
        return PAPER

    link = HostLink(default_ids(), [("LP1", 25)], scan, report=reported.append)
    arrival = link.load(1, "FOUP1")
    assert [t.status for t in arrival.transitions] == [SLOT_MAP_NOT_READ]
    assert [(t.carrier_id, t.status) for t in reported] == [("FOUP1", SLOT_MAP_NOT_READ),
                                                            ("FOUP1", None)]
    assert link.ports.port(1).carrier_id is None
    assert link.load(1, "FOUP2").transitions[-1].status == WAITING_FOR_HOST


def test_ports_are_named_by_number_or_by_the_layouts_carrier():
    link = HostLink(default_ids(), [("LP1", 25), ("2", 13)], lambda name: PAPER)
    assert (link.port_of("1"), link.port_of("LP1"), link.port_of("2"), link.port_of("X")) == (
        1, 1, 2, None)  # a number first: the carrier named "2" is at port 2 anyway


def test_a_port_waiting_for_the_host_takes_no_other_carrier():
    link = HostLink(default_ids(), [("LP1", 25)], lambda name: PAPER)
    link.load(1, "FOUP1")
    with pytest.raises(InputError, match="port 1 holds carrier 'FOUP1' .WAITING FOR HOST."):
        link.load(1, "FOUP2")
