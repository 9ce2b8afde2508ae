"""IDS.toml, the tool's SECS/GEM identifiers (SPEC §14): defaults, ports and every error naming
the file and the line."""

import pytest

from waferscan.core.errors import InputError
from waferscan.host.ids import DEFAULTS, PortIds, default_ids, read_ids

CARRIERS = ["LP1", "LP2", "LP3"]


def test_the_defaults_number_ports_in_the_layouts_order():
    ids = default_ids()
    assert (ids.mdln, ids.softrev, ids.device_id) == ("WSCAN", "0.1.0", 0)
    assert ids.events == DEFAULTS["events"] and ids.data == DEFAULTS["data"]
    assert ids.assign_ports(CARRIERS) == (PortIds("LP1", 1, "LP1"), PortIds("LP2", 2, "LP2"),
                                          PortIds("LP3", 3, "LP3"))
    assert ids.status_id("slot_map_status", 3) == 9003


def test_a_file_sets_what_it_names_and_keeps_the_rest(tmp_path):
    path = tmp_path / "ids.toml"
    path.write_text('[equipment]\nmdln = "SORT01"\n\n[events]\nwaiting_for_host = 120\n\n'
                    '[[port]]\ncarrier = "LP2"\nnumber = 1\ncarrier_id = "FOUP0042"\n')
    ids = read_ids(path)
    assert ids.mdln == "SORT01" and ids.events["waiting_for_host"] == 120
    assert ids.events["verification_ok"] == DEFAULTS["events"]["verification_ok"]
    assert ids.assign_ports(CARRIERS) == (PortIds("LP1", 2, "LP1"),
                                          PortIds("LP2", 1, "FOUP0042"),
                                          PortIds("LP3", 3, "LP3"))


@pytest.mark.parametrize("text, where, message", [
    ('[events]\nwaiting_for_host = 1\nwaiting_for_hots = 2\n', 3,
     "[events] waiting_for_hots: unknown key (known: slot_map_not_read, waiting_for_host, "
     "verification_ok, verification_failed, carrier_cancelled)"),
    ('[vents]\n', 1, "unknown table 'vents' (known: equipment, events, data, status, port)"),
    ('[data]\nslot_map = -4\n', 2, "[data] slot_map: expected a whole number 1-4294967295 (U4), "
                                   "got -4"),
    ('[data]\nslot_map = 8703\n', 2, "ID 8703 is used twice: [events] verification_ok and "
                                     "[data] slot_map"),
    ('[status]\ncarrier_id = 8899\n', 2, "ID 8901 is used twice: [status] carrier_id of port 2 "
                                         "and [status] slot_map of port 1"),
    ('[equipment]\nmdln = "A VERY LONG MODEL NAME"\n', 2,
     "[equipment] mdln: expected ASCII text of 1 to 20 characters (SEMI E5), got "
     "'A VERY LONG MODEL NAME'"),
    ('[equipment]\ndevice_id = 40000\n', 2,
     "[equipment] device_id: expected an integer 0-32767 (HSMS session ID), got 40000"),
    ('[[port]]\ncarrier = "LP1"\nnumber = 1\n\n[[port]]\ncarrier = "LP2"\nnumber = 1\n', 7,
     "[[port]] #2 number: port 1 is already carrier 'LP1''s"),
    ('[status]\ncarrier_id = 1000\n', 2, "ID 1001 is used twice: secsgem's built-in SVID 1001 "
                                          "and [status] carrier_id of port 1"),
    ('[events]\nverification_ok = 3\n', 2, "ID 3 is used twice: secsgem's built-in CEID 3 and "
                                           "[events] verification_ok"),
    ('[[port]]\ncarrier = "LP9"\n', 2,
     "[[port]] carrier: no carrier named 'LP9' in the layout (carriers: LP1, LP2, LP3)"),
    ('[[port]]\ncarrier = "LP1"\nptn = 3\n', 3,
     "[[port]] #1 ptn: unknown key (known: carrier, number, carrier_id)"),
    ('[[port]]\nnumber = 3\n', 1,
     "[[port]] #1 missing key 'carrier' (the layout's carrier at this port)"),
    ('[[port]]\ncarrier = "LP1"\nnumber = 256\n', 3,
     "[[port]] #1 number: expected a port number 1-255 (PTN is U1), got 256"),
    ('[events\n', 1, "not valid TOML: Expected ']' at the end of a table declaration"),
])
def test_bad_input_names_the_file_the_line_and_the_value(tmp_path, text, where, message):
    path = tmp_path / "ids.toml"
    path.write_text(text)
    with pytest.raises(InputError) as caught:
        read_ids(path).assign_ports(CARRIERS)
    assert (caught.value.source, caught.value.line, caught.value.message) == (
        str(path), where, message)


def test_a_carrier_id_given_twice_is_refused(tmp_path):
    path = tmp_path / "ids.toml"
    path.write_text('[[port]]\ncarrier = "LP1"\ncarrier_id = "LP2"\n')
    with pytest.raises(InputError, match="carrier_id 'LP2' is given to two ports"):
        read_ids(path).assign_ports(CARRIERS)


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(InputError, match="ids.toml: cannot read the IDs file"):
        read_ids(tmp_path / "ids.toml")


def test_a_port_without_a_number_is_numbered_in_the_layouts_order(tmp_path):
    path = tmp_path / "ids.toml"
    path.write_text('[[port]]\ncarrier = "LP3"\ncarrier_id = "FOUP-C"\n\n'
                    '[[port]]\ncarrier = "LP1"\nnumber = 3\n')
    assert read_ids(path).assign_ports(CARRIERS) == (
        PortIds("LP1", 3, "LP1"), PortIds("LP2", 1, "LP2"), PortIds("LP3", 2, "FOUP-C"))
